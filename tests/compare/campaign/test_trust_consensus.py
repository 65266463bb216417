"""``trilith trust`` with two engines or more: where the model is invalid, the
engines against each other at a few frequencies per curve, never where the bob
meets a column, and a page section that says it is not the model's comparison."""
from __future__ import annotations

import pytest

from trilith_xval.compare.campaign import trust_check
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.scenes import load_scene


def _row(omega, a, valid, reason=""):
    return {"omega": omega, "a_model": a, "mode": None, "valid": valid, "reason": reason}


def test_invalid_rows_are_spread_and_the_bob_rows_left_out():
    rows = ([_row(w, 10.0 + w, True) for w in range(4)]
            + [_row(10 + w, 30.0, False, "lintel normal force -0.2") for w in range(9)]
            + [_row(30.0, 40.0, False, "the bob meets an inner column face at t = 1 s")])
    picked = trust_check._invalid(rows, 3)
    assert [r["omega"] for r in picked] == [10, 14, 18]
    assert all("bob meets" not in r["reason"] for r in picked)


@pytest.mark.slow
def test_consensus_where_the_lintel_would_be_thrown_off(capsys):
    """Fig. 5 without the pendulum at Omega 24 (the model's lintel would be thrown
    off its columns): Pymunk and MuJoCo answer each other within 2 %."""
    scene = load_scene("fig5")
    band = {"curves": {"no_pendulum": [
        _row(24.0, 63.137, False, "lintel normal force -0.25 of its weight")]}}
    runs = {e: RunSpec.resolve(e, scene, calibrated=True) for e in ("pymunk", "mujoco")}
    (c,) = trust_check._consensus(runs, scene, band, trust_check.StageProgress(1, True))
    assert c["case"] == "no_pendulum" and c["status"] == "consensus"
    assert all(abs(v["deviation"]) <= 0.02 for v in c["engines"].values())
    from trilith_xval.compare.report.trust_page import _consensus_section
    html = _consensus_section({"consensus": [c]})
    assert "engine against engine" in html and "never agreement with the model" in html
    assert _consensus_section({}) == ""  # one engine: no section
