"""``trilith atlas --from STORED --consensus E1,E2``: the engines' answer where the
model is invalid, added to a stored atlas, drawn in its own colour, and refused
at the door when it cannot compare anything."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.cli.main import main

from tests.support.paths import ROOT


@pytest.fixture(scope="module")
def small_atlas(tmp_path_factory):
    """The stored atlas cut to one invalid point the engines can answer, one where
    the bob meets a column, and one valid point."""
    doc = json.loads((ROOT / "docs" / "validation" / "atlas.json").read_text())
    pts = doc["points"]
    hop = next(p for p in pts if p["valid"] is False and "bob meets" not in p["model_reason"]
               and p["scene"] == "fig8_lam3_gamma0.1" and p["omega"] == 20.0
               and p["case"] == "pendulum")
    bob = next(p for p in pts if p["valid"] is False and "bob meets" in p["model_reason"])
    ok = next(p for p in pts if p["valid"] is True)
    doc["points"] = [hop, bob, ok]
    path = tmp_path_factory.mktemp("atlas") / "small.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.slow
def test_consensus_is_added_where_the_model_is_invalid(small_atlas, tmp_path, capsys):
    out, page = tmp_path / "out.json", tmp_path / "out.html"
    assert main(["atlas", "--from", str(small_atlas), "--consensus", "pymunk,mujoco",
                 "--json", str(out), "--html", str(page), "--cache",
                 str(tmp_path / "store")]) == 0
    printed = capsys.readouterr().out
    assert "1 gained an answer of 1 the engines can answer" in printed
    doc = json.loads(out.read_text())
    hop, bob, ok = doc["points"]
    assert hop["consensus"]["status"] == "consensus"
    assert set(hop["own"]) == {"pymunk", "mujoco"}
    assert bob["consensus"]["status"] == "not run" and "collides with nothing" in \
        bob["consensus"]["why"]
    assert "consensus" not in ok  # where the model is valid the engines face the model
    assert doc["consensus"]["engines"] == ["pymunk", "mujoco"]
    assert doc["consensus"]["cpu_s"] > 0.0 and "--consensus" in doc["consensus"]["command"]
    html = page.read_text()
    assert "engine against engine" in html and "1 points gained an answer" in html


@pytest.mark.parametrize("value, message", [("pymunk", "at least two engines"),
                                            ("pymunk,bullet", "unknown engine 'bullet'")])
def test_a_consensus_of_fewer_than_two_engines_is_refused(value, message, small_atlas,
                                                          tmp_path, no_work, capsys):
    assert main(["atlas", "--from", str(small_atlas), "--consensus", value, "--json",
                 str(tmp_path / "o.json")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and message in err[0] and "--consensus" in err[0]
    assert not (tmp_path / "o.json").exists()


def test_spectrum_consensus_needs_two_engines(no_work, capsys):
    assert main(["spectrum", "--engine", "pymunk", "--omega", "24", "--consensus"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "--consensus" in err[0] and "two or more" in err[0]


@pytest.mark.slow
def test_spectrum_consensus_where_the_model_cannot_judge(capsys):
    """Fig. 5 at Omega 24: the model's lintel would be thrown off (cause 'model' for
    both engines); the engines' own failures agree with each other, apart from
    the model's comparison in the document."""
    assert main(["spectrum", "--engine", "pymunk,mujoco", "--omega", "24", "--consensus",
                 "--json", "--workers", "1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    found = doc["consensus"]
    assert {c["curve"] for c in found} == {"pendulum", "no_pendulum"}
    for c in found:
        assert c["status"] == "consensus" and set(c["own"]) == {"pymunk", "mujoco"}
        assert all(abs(v["deviation"]) <= 0.02 for v in c["engines"].values())
    for name in ("pymunk", "mujoco"):  # the model's comparison is unchanged beside it
        assert {p["cause"] for p in doc["engines"][name]["curves"]["pendulum"]} == {"model"}


@pytest.mark.parametrize("argv", [["--engine", "pymunk"], []])
def test_map_consensus_needs_two_engines(argv, no_work, capsys):
    assert main(["map", "--omega", "20:26:2", "--amplitude", "40:90:10", "--consensus",
                 *argv]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "--consensus" in err[0] and "two or more" in err[0]
