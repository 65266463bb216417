"""`trilith campaign FILE --estimate` prints its estimate on stdout (the result
asked for) and writes nothing."""
from __future__ import annotations

import re

from trilith_xval.compare.cli.main import main


def test_estimate_is_printed_on_stdout(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c.toml").write_text('[campaign]\nname = "tiny"\nscenes = ["fig5"]\n'
                                     'engines = ["pymunk"]\nomega = "10"\n')
    assert main(["campaign", "c.toml", "--estimate", "--no-cache"]) == 0
    out, err = capsys.readouterr()
    assert re.match(r"campaign tiny: 1 scenes, \d+ reference points, \d+ engine threshold "
                    r"jobs .* of CPU", out), out
    assert "campaign tiny" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.toml"]  # nothing written
