"""``--restitution-factor``: the model's impacts scaled, and what the engines are
compared with (docs/model.md, "A measured restitution")."""
from __future__ import annotations

import json
import math

import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.compare.cli.main import main
from trilith_xval.compare.measure.restitution import measure_restitution
from trilith_xval.scenes import load_scene


def _json(argv, capsys) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def _housner(scene) -> float:
    return 1.0 - 1.5 * math.sin(scene.alpha) ** 2


def test_restitution_command_targets_r_times_eq20(capsys):
    doc = _json(["restitution", "--scene", "single_block", "--engine", "analytic",
                 "--restitution-factor", "0.7", "--n-impacts", "2", "--no-cache", "--json"],
                capsys)
    target = 0.7 * _housner(load_scene("single_block"))
    assert doc["inputs"]["restitution_factor"] == 0.7
    assert doc["equation"] == "0.7 x Eq. 20"
    for imp in doc["impacts"]:
        assert imp["predicted"] == pytest.approx(target, rel=1e-12)
        assert imp["measured"] == pytest.approx(target, rel=1e-6)  # the scaled model itself


def test_an_engine_is_measured_against_the_scaled_target():
    """Pymunk's impact follows Eq. 20 (its own test: 0.5 %); against 0.8 x Eq. 20
    it is off by 1/0.8 - 1 = 25 %: the target moved, the engine did not."""
    scene = load_scene("single_block")
    exact = measure_restitution("pymunk", scene, n_impacts=2)
    scaled = measure_restitution("pymunk", scene, n_impacts=2, restitution_factor=0.8)
    assert [i.predicted for i in scaled.impacts] == pytest.approx(
        [0.8 * i.predicted for i in exact.impacts], rel=1e-12)
    assert scaled.max_rel_error == pytest.approx(0.25, abs=0.01)
    assert "restitution_factor" not in exact.to_dict()  # documents at r = 1 unchanged


def test_simulate_scales_the_model_and_echoes_the_factor(capsys):
    base = ["simulate", "--scene", "single_block", "-A", "3", "-w", "10", "--json"]
    housner = _housner(load_scene("single_block"))
    for engine in ("analytic", "analytic-fast"):
        exact = _json(base + ["--engine", engine], capsys)
        scaled = _json(base + ["--engine", engine, "--restitution-factor", "0.5"], capsys)
        assert "restitution_factor" not in exact["inputs"]
        assert scaled["inputs"]["restitution_factor"] == 0.5
        for doc, r in ((exact, 1.0), (scaled, 0.5)):
            imp = next(e for e in doc["events"] if e["kind"] == "impact")
            ratio = imp["theta_dot_after"] / imp["theta_dot_before"]
            assert ratio == pytest.approx(r * housner, abs=1e-6), (engine, r)


def test_spectrum_threshold_moves_with_the_factor(capsys):
    """A lossier impact leaves less energy to the rebound: at Omega = 10 rad/s the
    single block's exact threshold is an after-impact overturn (the pulse's second
    half throws it over the corner after the first impact); with r = 0.8 that
    path closes and the block needs a pulse strong enough to topple it before
    any impact: the threshold rises and the mode changes."""
    base = ["spectrum", "--scene", "single_block", "--omega", "10", "--workers", "1",
            "--no-cache", "--json"]
    exact = _json(base, capsys)
    scaled = _json(base + ["--restitution-factor", "0.8"], capsys)
    a1, a08 = exact["a_no_pendulum"][0], scaled["a_no_pendulum"][0]
    assert exact["mode_no_pendulum"][0] == "after-impact"
    assert scaled["mode_no_pendulum"][0] == "no-impact"
    assert a08 > 1.5 * a1
    assert scaled["inputs"]["restitution_factor"] == 0.8
    assert "restitution_factor" not in exact["inputs"]


def test_eq20_of_the_model_is_unscaled():
    """restitution_ratio stays the exact Eq. 19/20: the factor lives in the run settings."""
    b, h, mu, gamma, j, _l, _g = load_scene("single_block").model_args()
    assert eq.restitution_ratio(0.0, 1.0, b, h, mu, gamma, j) == pytest.approx(
        _housner(load_scene("single_block")), rel=1e-12)


def test_map_first_overturning_moves_with_the_factor(capsys):
    base = ["map", "--scene", "single_block", "--omega", "10", "--amplitude", "2:14:2",
            "--workers", "1", "--json"]
    exact = _json(base, capsys)
    scaled = _json(base + ["--restitution-factor", "0.8"], capsys)
    assert "restitution_factor" not in exact and scaled["restitution_factor"] == 0.8
    a1 = exact["maps"][0]["first_overturn"][0]
    a08 = scaled["maps"][0]["first_overturn"][0]
    # The spectrum's numbers (test above): after-impact ~4.1, no-impact ~12.5 m/s^2.
    assert a1 == pytest.approx(4.105, rel=0.01) and a08 == pytest.approx(12.48, rel=0.01)
