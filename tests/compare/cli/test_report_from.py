"""``trilith report --from FILE``: a stored run rendered, nothing recomputed, and
labelled as such; bad input refused at the door."""
from __future__ import annotations

import hashlib
import json

import pytest

from tests.support.paths import ROOT
from trilith_xval.compare.cli.main import main

STORED = ROOT / "docs" / "validation" / "summary.json"


def test_the_stored_run_is_rendered_with_its_own_numbers(tmp_path, no_work, capsys):
    """Nothing runs (``no_work`` fails the test when any simulation, campaign or
    spectrum starts) and every number is the stored run's."""
    rendered = tmp_path / "report"
    assert main(["report", "--from", str(STORED), "--out", str(rendered)]) == 0
    assert "verdicts pass" in capsys.readouterr().out
    stored = json.loads(STORED.read_text())
    doc = json.loads((rendered / "summary.json").read_text())
    assert doc.pop("rendered_from") == {
        "file": str(STORED), "sha256": hashlib.sha256(STORED.read_bytes()).hexdigest()}
    assert doc == stored
    page = (rendered / "index.html").read_text()
    commit = stored["provenance"]["commit"][:12]
    assert "Rendered from the stored run" in page and commit in page
    assert "nothing was recomputed" in (rendered / "summary.md").read_text()


@pytest.mark.parametrize("argv, message", [
    (["--from", "{missing}"], "does not exist"),
    (["--from", "{not_json}"], "not valid JSON"),
    (["--from", "{not_summary}"], "summary"),
    (["--from", str(STORED), "--quick"], "--quick cannot apply"),
    (["--from", str(STORED), "--dt", "1e-4"], "--dt cannot apply"),
    (["--from", str(STORED), "--full"], "--full cannot apply"),
])
def test_bad_input_is_refused_at_the_door(tmp_path, capsys, no_work, argv, message):
    (tmp_path / "bad.json").write_text("{not json")
    (tmp_path / "other.json").write_text(json.dumps({"schema_version": 2, "spectra": 3}))
    paths = {"missing": tmp_path / "none.json", "not_json": tmp_path / "bad.json",
             "not_summary": tmp_path / "other.json"}
    argv = [a.format(**paths) for a in argv]
    out = tmp_path / "out"
    assert main(["report", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert not out.exists()  # refused before the output directory was made
