"""A campaign's scenes of another kind: the engines against each other, through the store."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.campaign.study import load_study
from trilith_xval.compare.cli.main import main


def write(tmp_path, body: str):
    path = tmp_path / "c.toml"
    path.write_text('[campaign]\nname = "k"\n' + body)
    return path


def test_a_kind_needs_two_engines_that_build_it(tmp_path):
    with pytest.raises(ValueError, match="give two or more, got pymunk"):
        load_study(write(tmp_path, 'scenes = ["drums"]\nengines = ["pymunk"]\nomega = [8.0]\n'))
    study = load_study(write(tmp_path, 'scenes = ["drums", "fig5"]\nengines = ["pymunk", '
                                       '"mujoco"]\nomega = [8.0]\n'))
    assert study.scenes == ("fig5",) and study.kind_scenes == ("drums",)


def test_a_kind_has_no_record_axis(tmp_path):
    with pytest.raises(ValueError, match="records: the record axis needs the model's IDA"):
        load_study(write(tmp_path, 'scenes = ["unequal"]\nengines = ["pymunk", "mujoco"]\n'
                                   'omega = [8.0]\n[campaign.records]\nsuite = "sample"\n'))


def test_a_kind_is_answered_engine_against_engine_and_resumes(tmp_path, capsys):
    """block_on_block has no pendulum: the two cases are one structure, listed once.
    Pymunk and MuJoCo converge in the step and agree with each other (a rigid block on
    a block with the same contacts: a stated 2 % is the engines' tolerance against the
    model, and against each other); the rerun takes every job from the store."""
    path = write(tmp_path, 'scenes = ["block_on_block"]\nengines = ["pymunk", "mujoco"]\n'
                           'omega = [8.0]\n')
    args = ["campaign", str(path), "--out", str(tmp_path / "out"), "--workers", "1",
            "--cache", str(tmp_path / "store")]
    assert main(args) == 0
    doc = json.loads((tmp_path / "out" / "campaign.json").read_text())
    assert doc["rows"] == [] and len(doc["consensus"]) == 1
    row = doc["consensus"][0]
    assert row["case"] == "no_pendulum" and row["what"].startswith("engine against engine")
    assert row["status"] == "consensus" and row["failure"] in ("overturned", "collapsed")
    assert all(row["own"][e]["converged"] for e in ("pymunk", "mujoco"))
    assert max(abs(v["deviation"]) for v in row["engines"].values()) <= 0.02
    assert row["a_guess"] is not None and row["scan_runs"] >= 2
    page = (tmp_path / "out" / "index.html").read_text()
    assert "engine against engine" in page and "never agreement with the model" in page
    capsys.readouterr()
    assert main(args) == 0
    assert " 0 computed" in capsys.readouterr().err
    assert json.loads((tmp_path / "out" / "campaign.json").read_text())["consensus"] == \
        doc["consensus"]
