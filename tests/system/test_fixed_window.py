"""--t-max gives every backend the same fixed window, with no early stop."""
from __future__ import annotations

import json

import pytest

from trilith_xval import engines
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.compare.cli.main import main
from trilith_xval.compare.cli.options import run_spec
from trilith_xval.compare.cli.simulate import _overrides
from trilith_xval.scenes import load_scene


@pytest.mark.slow
@pytest.mark.parametrize("name", ["analytic", "pymunk", "pybullet", "mujoco"])
def test_simulate_t_max_runs_every_backend_to_the_end(name):
    """The README's Fig. 8 record after its pulse: every backend, model included, runs
    the whole 1.5 s (they used to stop at 0.656 s, 'survived', where PyBullet's pivots
    go on sliding)."""
    scene, pulse = load_scene("fig8_lam3_gamma0.1"), Pulse(19.0, 15.0)
    settings = run_spec(name, scene, pulse, overrides=_overrides(name, None, 1.5)).settings
    assert settings.early_stop is False and settings.t_max == 1.5
    tr = engines.simulate(name, scene, pulse, settings)
    assert tr.t[-1] == pytest.approx(1.5, abs=0.01) or tr.verdict.status != "survived"


@pytest.mark.slow
def test_spectrum_t_max_reaches_the_engines(capsys):
    """``spectrum --engine pymunk --t-max 0.7 --omega 10``: the engine runs get the
    model's window (they had none).  Overturning within 0.7 s takes 46 m/s^2, where
    the model's lintel would be thrown off: the point is the model's, and says so."""
    assert main(["spectrum", "--engine", "pymunk", "--t-max", "0.7", "--omega", "10",
                 "--json", "--no-cache", "--workers", "1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    spec = doc["engines"]["pymunk"]
    point = spec["curves"]["no_pendulum"][0]
    assert point["provenance"]["settings"]["t_max"] == 0.7
    assert point["provenance"]["settings"]["early_stop"] is False
    assert point["valid"] is False and point["cause"] == "model"
    assert "lintel" in point["cause_detail"]
