"""``trilith trust``: the user's own scene, with and without a pendulum and with a
ground motion; bad input refused at the door; a scene outside the calibration's
domain runs the reference step and says so."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.engines import configure
from trilith_xval.engines.calibration import threshold_choice
from trilith_xval.scenes import load_scene


def _run(capsys, argv):
    code = main(["trust", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_a_scene_with_a_pendulum(tmp_path, capsys):
    out = tmp_path / "t"
    code, stdout, err = _run(capsys, ["--scene", "fig5", "--engine", "pymunk",
                                      "--out", str(out)])
    assert code == 0
    doc = json.loads((out / "trust.json").read_text())
    entry = doc["engines"]["pymunk"]
    assert set(doc["band"]["curves"]) == {"pendulum", "no_pendulum"}
    cases = [p["case"] for p in entry["thresholds"]]
    assert cases.count("pendulum") == cases.count("no_pendulum") == 6
    # Inside the calibration's domain: the calibrated step, the same in the page.
    assert entry["threshold_dt"] == threshold_choice("pymunk", load_scene("fig5")).options["dt"]
    assert {r["equation"] for r in entry["restitution"]} == {"Eq. 20", "Eq. 19"}
    assert len(entry["histories"]) == 4 and {h["factor"] for h in entry["histories"]} == {
        0.9, 1.1}
    assert entry["threshold_verdict"]["trusted"] is not None
    assert entry["cost"]["threshold_point_cpu_s"] > 0
    page = (out / "index.html").read_text()
    assert "Which engine to trust" in page and "data:image/png;base64," in page
    assert (out / "trust.csv").read_text().count("\n") == 13  # header + 12 points
    # One progress line per stage on stderr, and the answer on stdout.
    assert "trust: 1/4 model" in err and "trust: 4/4 pymunk time histories" in err
    assert stdout.startswith("Pymunk: thresholds ")


def test_a_scene_without_a_pendulum_and_a_record(tmp_path, capsys):
    out = tmp_path / "t"
    code, stdout, err = _run(capsys, ["--scene", "no_pendulum", "--engine", "pymunk",
                                      "--record", "scenes/records/sample.csv",
                                      "--out", str(out), "-q"])
    assert code == 0 and err == ""  # -q: no progress, no note
    doc = json.loads((out / "trust.json").read_text())
    entry = doc["engines"]["pymunk"]
    assert set(doc["band"]["curves"]) == {"no_pendulum"}
    assert {p["case"] for p in entry["thresholds"]} == {"no_pendulum"}
    assert [r["equation"] for r in entry["restitution"]] == ["Eq. 20"]
    (rec,) = entry["records"]
    assert rec["record"] == "sample.csv" and rec["im_model"] > 0
    # The engine's intensity is measured, and compared with the model's within 2 %.
    assert rec["passed"] == (rec["rel_error"] is not None and abs(rec["rel_error"]) <= 0.02)


def test_outside_the_domain_the_reference_step_runs_and_a_note_says_so(tmp_path, capsys):
    scene = tmp_path / "stocky.toml"
    scene.write_text("[scene]\nb = 0.6\nlam = 2.5\nmu = 1.0\ngamma = 0.0\n")  # lam < 3
    out = tmp_path / "t"
    code, stdout, err = _run(capsys, ["--scene", str(scene), "--engine", "pymunk",
                                      "--out", str(out)])
    assert code == 0
    assert err.splitlines()[0].startswith("note: pymunk: stocky is outside the domain")
    doc = json.loads((out / "trust.json").read_text())
    assert doc["engines"]["pymunk"]["threshold_dt"] == configure("pymunk").dt
    assert doc["engines"]["pymunk"]["calibrated_inside"] is False


@pytest.mark.parametrize("argv, word", [
    (["--scene", "nosuch"], "scene"),
    (["--engine", "nosuch"], "--engine"),
    (["--record", "/nonexistent.csv"], "--record"),
])
def test_bad_input_is_refused_before_any_work(tmp_path, capsys, argv, word):
    out = tmp_path / "t"
    code, stdout, err = _run(capsys, [*argv, "--out", str(out)])
    assert code == 2 and err.count("\n") == 1 and word in err
    assert not out.exists()
