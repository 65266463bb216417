"""`trilith scenes` and the scene words: every value is defined where it is
first met (the README's "Using it", each command's --help, `trilith scenes`),
and `scenes --scene NAME|FILE` shows one scene's values."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from trilith_xval.analytic.parameters import GLOSSARY
from trilith_xval.compare.cli import COMMANDS
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_scene, scene_names

ROOT = Path(__file__).resolve().parents[3]
# The words a newcomer must not guess (mu read as friction, b as half-width).
WORDS = ("lam", "b", "h", "mu", "gamma", "l", "gap", "lintel_height")


def _help(command: str, capsys) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return capsys.readouterr().out


def test_every_help_with_scene_options_defines_the_words(capsys):
    with_scene = 0
    for command in COMMANDS:
        text = _help(command, capsys)
        if "--scene" not in text:
            continue
        with_scene += 1
        for word in WORDS:
            # The glossary's line for the word: name, spaces, its meaning.
            assert re.search(rf"^\s+{word}\s+{re.escape(GLOSSARY[word][:25])}", text,
                             re.M), (command, word)
        assert "not friction" in text, command
    assert with_scene >= 8  # simulate, spectrum, map, record, restitution, ...


def test_listing_shows_the_words_and_no_pendulum_length_without_pendulum(capsys):
    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    table, _, words = out.partition("\n\n")
    rows = {line.split()[0]: line.split() for line in table.splitlines()[1:]}
    assert set(rows) == set(scene_names())
    assert rows["no_pendulum"][5] == "-"  # l: there is no pendulum
    assert float(rows["fig5"][5]) == pytest.approx(load_scene("fig5").pendulum_length, rel=1e-2)
    for word in WORDS:
        assert re.search(rf"^\s+{word}\s+{re.escape(GLOSSARY[word])}$", words, re.M), word


def test_scene_file_shows_its_values(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text("# My own trilith: a drawing's sizes\n[scene]\nb = 0.5\nh = 2.25\nmu = 2\n")
    assert main(["scenes", "--scene", str(path), "--json"]) == 0
    (shown,) = json.loads(capsys.readouterr().out)["scenes"]
    scene = load_scene(path)
    assert shown["file"] == str(path) and shown["source"] == "My own trilith"
    assert shown["lam"] == scene.lam == pytest.approx(4.5, rel=1e-15)  # rounding of h/b
    assert (shown["h"], shown["mu"], shown["gap"]) == (scene.h, 2.0, scene.d)
    assert shown["l"] == scene.pendulum_length and shown["alpha"] == scene.alpha
    assert main(["scenes", "--scene", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].startswith(f"mine: {path}")
    assert re.search(r"^\s+mu\s+2\s+lintel mass .*not friction", out, re.M)
    assert re.search(r"^\s+h\s+2\.25 m\s", out, re.M)


def test_named_scenes_with_overrides_and_globs(capsys):
    assert main(["scenes", "--scene", "fig8_lam3_*", "--set", "b=0.4", "--json"]) == 0
    shown = json.loads(capsys.readouterr().out)["scenes"]
    assert [s["name"] for s in shown] == [n for n in scene_names() if n.startswith("fig8_lam3_")]
    assert all(s["b"] == 0.4 and s["file"].startswith("scenes/data/") for s in shown)
    assert main(["scenes", "--scene", "fig5", "--no-pendulum"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^\s+gamma\s+0\s", out, re.M)
    assert re.search(r"^\s+l\s+-  \(no pendulum\)", out, re.M)


def test_unknown_scene_is_one_error_line(capsys):
    assert main(["scenes", "--scene", "atlantis"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: unknown scene 'atlantis'") and len(err.splitlines()) == 1


def test_readme_defines_the_words_where_scenes_are_first_named():
    text = (ROOT / "README.md").read_text()
    using = text[text.index("## Using it"):]
    using = using[:using.index("```")]  # before the first example
    assert "not friction" in using and "m3/m1" in using and "m4/m1" in using
    assert "h/b" in using and "*full* width" in using and "2h/3" in using
    for word in WORDS:
        assert f"`{word}`" in using or f"`{word} =" in using, word
