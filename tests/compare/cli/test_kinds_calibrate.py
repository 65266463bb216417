"""``trilith calibrate`` on a scene the model does not cover: the engine's step
against its own reference step (self-convergence), a settings file marked with
the kind, refused on any other kind."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.engines.calibration import Domain


def test_calibrate_on_a_kind_is_self_convergence_and_its_file_keeps_to_the_kind(
        tmp_path, capsys):
    out, doc_path = tmp_path / "s.toml", tmp_path / "c.json"
    # Steps of 1-2 ms keep the test to seconds; the reference is the finest asked.
    assert main(["calibrate", "--engine", "mujoco", "--scene", "block_on_block", "--dt",
                 "1e-3,2e-3", "--step-only", "--omega", "12", "--no-cache",
                 "--settings-out", str(out), "--json", str(doc_path)]) == 0
    text = capsys.readouterr().out
    assert "block_on_block kind: no model" in text and "(self-convergence)" in text
    body = json.loads(doc_path.read_text())
    body = body.get("result", body)
    assert body["kind"] == "block_on_block" and body["model"] is None
    assert body["self_reference"]["dt_ref"] == 1e-3
    (ref,) = body["self_reference"]["thresholds"]["block_on_block"].values()
    assert ref["failure"] == "overturned" and ref["a_survives"] < ref["a_fails"]
    at_ref = next(e for e in body["evaluations"] if e["options"]["dt"] == 1e-3)
    # The reference step against itself: two searches of the same runs, centred
    # apart, bracket the same threshold within their resolution (0.5 % each).
    assert at_ref["worst_error"] <= 0.01
    settings = out.read_text()
    assert '[domain]\nkind = "block_on_block"' in settings
    assert 'target = "self-convergence"' in settings
    # The file refuses a trilith (and any other kind) in one line, before work ...
    assert main(["simulate", "--scene", "fig5", "--engine", "mujoco", "--settings", str(out),
                 "-A", "5", "-w", "8"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1
    assert "calibrated on the block_on_block kind" in err and "'fig5'" in err
    # ... and runs its own kind.
    assert main(["simulate", "--scene", "block_on_block", "--engine", "mujoco", "--settings",
                 str(out), "-A", "1", "-w", "8"]) == 0


@pytest.mark.parametrize("extra, text", [
    (["--metric", "restitution"], "--metric restitution: there is no model of the drums kind"),
    (["--metric", "histories"], "--metric histories: there is no model of the drums kind"),
    (["--restitution-factor", "0.9"], "--restitution-factor: there is no model"),
    (["--scene", "fig5"], "one calibration holds over one kind"),
])
def test_calibrate_on_a_kind_refuses_what_has_no_target(extra, text, capsys, no_work):
    assert main(["calibrate", "--engine", "pymunk", "--scene", "drums", *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and text in err


def test_a_trilith_calibration_file_is_refused_on_a_kind(capsys, no_work):
    import trilith_xval.engines.pymunk_ as package
    shipped = Path(package.__file__).parent / "thresholds.toml"  # a design's [domain]
    assert main(["simulate", "--scene", "drums", "--engine", "pymunk", "--settings",
                 str(shipped), "-A", "5", "-w", "8"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "calibrated on the trilith kind" in err


def test_a_domain_of_a_kind_holds_over_that_kind_only():
    from trilith_xval.scenes import load_scene
    domain = Domain.from_table({"kind": "drums"}, "f")
    assert domain.outside(load_scene("drums")) is None
    assert "of the trilith kind" in domain.outside(load_scene("fig5"))
    with pytest.raises(ValueError, match=r"\[domain\] kind must be one of"):
        Domain.from_table({"kind": "arch"}, "f")
    with pytest.raises(ValueError, match="takes no trilith coordinate"):
        Domain.from_table({"kind": "drums", "lam": [3, 5]}, "f")
