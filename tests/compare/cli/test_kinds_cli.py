"""The commands on scenes the model does not cover (analytic.kinds): simulate runs
the engines and says there is no model; spectrum --consensus gives each engine's
own first failure and their consensus; every other command refuses in one line
naming itself and the kind, before any work."""
from __future__ import annotations

import json

import pytest

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.compare.cli.main import main
from trilith_xval.engines import get_backend
from trilith_xval.scenes import load_scene


def test_simulate_runs_an_engine_and_says_there_is_no_model(capsys):
    assert main(["simulate", "--scene", "drums", "--engine", "pymunk", "-A", "5", "-w", "8"]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].startswith("pymunk: scene drums (drums, 7 bodies)")
    assert lines[1].startswith("verdict: ")
    assert "no model" in captured.out
    assert main(["simulate", "--scene", "unequal", "--engine", "mujoco", "-A", "1", "-w", "8",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["inputs"]["scene"]["kind"] == "unequal"
    assert doc["kind"] == "unequal" and doc["model"] is None
    assert doc["status"] == "survived"  # 1 m/s^2: below the frame uplift g b/h = 1.96


def test_simulate_with_the_model_says_there_is_none(capsys, no_work):
    assert main(["simulate", "--scene", "drums", "-A", "5", "-w", "8"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "no model of the drums kind" in err


def test_every_command_that_takes_a_scene_answers_another_kind():
    """Every subcommand with --scene runs the other kinds (with the engines, their
    consensus, or against its own reference step); check_kind refuses a kind only in
    a command outside that list, naming the command and the kind in one line."""
    import argparse

    from trilith_xval.compare.cli import options
    from trilith_xval.compare.cli.main import build_parser
    sub = next(a for a in build_parser()[0]._actions if isinstance(a, argparse._SubParsersAction))
    with_scene = {name for name, p in sub.choices.items()
                  if any("--scene" in a.option_strings for a in p._actions)}
    assert with_scene and with_scene <= set(options.KIND_COMMANDS) | {"report"}
    from trilith_xval.scenes import load_scene
    with pytest.raises(ValueError, match="^trilith figures: scene 'block_on_block' is of the "
                                         "block_on_block kind"):
        options.check_kind(load_scene("block_on_block"), "figures")


def test_spectrum_without_consensus_or_with_a_trilith_engine_refuses(capsys, no_work,
                                                                     monkeypatch):
    assert main(["spectrum", "--scene", "drums", "--omega", "8"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "give --consensus E1,E2" in err
    # Every shipped engine builds the body list: one taken off the list stands for an
    # engine that does not.
    from trilith_xval.engines import geometry
    monkeypatch.setattr(geometry, "STRUCTURE_ENGINES", ("pymunk", "mujoco"))
    assert main(["spectrum", "--scene", "drums", "--omega", "8",
                 "--consensus", "drake,pymunk"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "drake runs the parametric trilith only" in err


def test_spectrum_consensus_brackets_each_engines_own_failure(capsys):
    # dt 1e-3 s keeps the test to seconds: the consensus converges the step itself
    # (it compares 2 dt with dt) and the verdicts are checked below at the answer's step.
    scene = load_scene("block_on_block")
    assert main(["spectrum", "--scene", "block_on_block", "--consensus", "pymunk,mujoco",
                 "--omega", "12", "--dt", "1e-3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["model"] is None and doc["kind"] == "block_on_block"
    (point,) = doc["points"]
    assert point["status"] in ("consensus", "disagree")
    fails = [own["a_fails"] for own in point["own"].values()]
    assert min(fails) <= point["median"] <= max(fails)
    for engine, own in point["own"].items():
        assert own["converged"] and own["a_survives"] < own["a_fails"]
        # The bracket is what the engine does: it fails at a_fails and stands at
        # a_survives, at the step of the answer.
        backend = get_backend(engine)
        s = backend.Settings(dt=own["dt"], verdict_only=True)
        at_fail = backend.simulate(scene, Pulse(own["a_fails"], 12.0), s)
        at_survive = backend.simulate(scene, Pulse(own["a_survives"], 12.0), s)
        assert at_fail.verdict.status == own["failure"]
        assert at_survive.verdict.status == "survived"


def test_consensus_names_the_engines_as_engine_does():
    from trilith_xval.compare.cli import spectrum
    from trilith_xval.compare.cli.main import build_parser
    parser, _ = build_parser()
    given = parser.parse_args(["spectrum", "--consensus", "pymunk,mujoco"])
    flag = parser.parse_args(["spectrum", "--engine", "pymunk,mujoco", "--consensus"])
    assert spectrum._engines(given) == spectrum._engines(flag) == ("pymunk", "mujoco")
    assert flag.consensus is True and not parser.parse_args(["spectrum"]).consensus


def test_atlas_refuses_a_glob_that_reaches_another_kind(tmp_path):
    from trilith_xval.compare.campaign.atlas import AtlasConfig, atlas_scenes
    from trilith_xval.compare.campaign.study import load_study
    # 'block*' reaches the block family and block_on_block (the kind is named).
    with pytest.raises(ValueError, match="'block_on_block' is of the block_on_block kind"):
        atlas_scenes(AtlasConfig(engines=("pymunk",), scenes=(("block*", "sine"),)))
    assert atlas_scenes(AtlasConfig(engines=("pymunk",), scenes=(("block_lam*", "sine"),)))
    path = tmp_path / "c.toml"
    path.write_text('[campaign]\nscenes = ["drums"]\nengines = ["pymunk"]\nomega = [8.0]\n')
    # A campaign answers a kind with the engines against each other: one is not enough.
    with pytest.raises(ValueError, match="drums have no model .* give two or more"):
        load_study(path)


def test_set_names_the_kinds_own_values(capsys, no_work):
    assert main(["simulate", "--scene", "unequal", "--engine", "pymunk", "-A", "1", "-w", "8",
                 "--set", "lam=3"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1
    assert "--set lam: not a value of the unequal kind; allowed:" in err and "gap" in err
