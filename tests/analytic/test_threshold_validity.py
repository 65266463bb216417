"""The model's validity along a threshold curve (analytic/threshold_validity.py)
and its shading: the Fig. 5 trilith at the pulse (A = 74.9 m/s^2 = 7.6 g,
Omega = 26 rad/s = 4.1 Hz) throws the lintel off; a low pulse keeps every contact."""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic import _workers
from trilith_xval.analytic.threshold_validity import (VALIDITY_FIELDS, curve_validity, invalid_spans,
                                         point_validity)
from trilith_xval.scenes import load_scene


@pytest.fixture(scope="module")
def fig5():
    return load_scene("fig5")


def test_lintel_thrown_off_at_the_issue_pulse(fig5):
    v = point_validity(fig5, 74.9, 26.0)
    assert set(v) == set(VALIDITY_FIELDS)
    assert v["model_valid"] is False
    assert v["lintel_min_normal"] < 0.0  # the column tops would have to pull the lintel
    assert "lintel would be thrown off" in v["model_reason"]


def test_low_pulse_keeps_every_contact(fig5):
    v = point_validity(fig5, 3.0, 5.0)
    assert v["model_valid"] is True and v["model_reason"] == ""
    # At rest the normal forces are the weights (1); a gentle pulse stays well above 0.
    assert 0.5 < v["ground_min_normal"] <= 1.5 and 0.5 < v["lintel_min_normal"] <= 1.5
    assert v["bob_min_clearance"] > 0.0  # the bob swings clear of the columns


def test_no_pendulum_has_no_clearance(fig5):
    v = point_validity(fig5.without_pendulum(), 3.0, 5.0)
    assert v["bob_min_clearance"] is None and v["model_valid"] is True


def test_curve_keeps_order_skips_missing_and_is_the_same_on_two_workers(fig5, monkeypatch):
    omegas, amps = [5.0, 26.0, 12.0, 8.0], [3.0, 74.9, math.nan, 3.5]
    one = curve_validity(fig5, omegas, amps, workers=1)
    assert [v["model_valid"] for v in one] == [True, False, None, True]
    monkeypatch.setattr(_workers, "POOL_START_CPU_S", 0.0)  # a pool, however cheap the work
    assert curve_validity(fig5, omegas, amps, workers=2) == one


def test_curve_rejects_unequal_lengths(fig5):
    with pytest.raises(ValueError, match="equal lengths"):
        curve_validity(fig5, [1.0, 2.0], [3.0])


def test_invalid_spans_widen_by_half_a_step():
    assert invalid_spans([1, 2, 3, 4, 5], [True, False, False, True, False]) == [
        (1.5, 3.5), (4.5, 5.5)]
    assert invalid_spans([1, 2, 3], [True, None, True]) == []  # unchecked is not invalid
