"""The step is ruled out before anything else is blamed (compare/measure/step_rule.py),
on a trilith outside the paper's set: small slender columns (b = 0.15 m, lam 7), a
light lintel (mu 0.5) and a heavy short pendulum (gamma 0.45, l = 0.3 m)."""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.spectrum import overturning_spectrum
from trilith_xval.compare.measure.engine_spectrum import measure_point, threshold_spec
from trilith_xval.compare.measure.step_rule import finer_steps, passes, rule_out_step
from trilith_xval.compare.measure.thresholds import SEARCH, engine_threshold
from trilith_xval.engines import configure

SMALL_SLENDER = Scene(b=0.15, lam=7.0, mu=0.5, gamma=0.45, l=0.3, name="small_slender")
OMEGA = 16.0  # rad/s; at Pymunk's Fig. 5 step (5e-4 s) the threshold is ~10 % high here


@pytest.fixture(scope="module")
def reference():
    spec = overturning_spectrum(SMALL_SLENDER, [OMEGA])
    return float(spec.a_pendulum[0]), spec.mode_pendulum[0]


def test_the_ladder_goes_down_to_the_reference_step():
    assert finer_steps(1e-3, 1e-4) == [5e-4, 2e-4, 1e-4]
    assert finer_steps(5e-4, 1e-4) == [2e-4, 1e-4]
    assert finer_steps(2.5e-3, 1e-4) == [2e-3, 1e-3, 5e-4, 2e-4, 1e-4]
    assert finer_steps(1e-4, 1e-4) == [] and finer_steps(5e-5, 1e-4) == []


def test_a_coarse_step_is_named_discretisation_with_the_finer_steps_bracket(reference):
    a_ref, mode = reference
    spec = threshold_spec("pymunk", SMALL_SLENDER, OMEGA, a_ref, options={"dt": 5e-4})
    point = measure_point(spec, OMEGA, a_ref, mode, case="pendulum")
    # The coarse step alone misses by more than the 2 % tolerance...
    assert not passes(point.point, 0.02)
    # ...and the cause is the step, never the model or a collapse.
    assert point.cause == "discretisation"
    assert point.agreeing_dt == pytest.approx(2e-4)
    rows = {round(r["dt"], 12): r for r in point.steps}
    assert set(rows) == {5e-4, 2e-4}  # the reference step was not needed
    ok = rows[2e-4]
    assert ok["passes"] and abs(ok["rel_error"]) <= 0.02
    assert ok["a_survives"] < a_ref * 1.02 and ok["a_engine"] > a_ref * 0.98
    assert "2e-4" in point.cause_detail.replace("0.0002", "2e-4")
    # The reruns' cost is counted with the point's.
    assert point.cpu_s >= point.point.cpu_s + ok["cpu_s"] - 1e-9


def test_a_passing_point_reruns_nothing(reference):
    a_ref, mode = reference
    settings = configure("pymunk", dt=2e-4)
    p = engine_threshold("pymunk", SMALL_SLENDER, OMEGA, a_ref, settings, search=SEARCH)
    check = rule_out_step("pymunk", SMALL_SLENDER, OMEGA, p, settings, tol=0.02)
    assert passes(p, 0.02) and len(check.rows) == 1 and check.agreeing_dt is None


def test_at_the_reference_step_the_other_causes_are_searched(reference):
    """With a tolerance no step can meet, the rule reaches the reference step and
    hands its point (not the coarse one) to the cause search."""
    a_ref, mode = reference
    settings = configure("pymunk", dt=5e-4)
    p = engine_threshold("pymunk", SMALL_SLENDER, OMEGA, a_ref, settings, search=SEARCH)
    check = rule_out_step("pymunk", SMALL_SLENDER, OMEGA, p, settings, tol=1e-6)
    assert check.agreeing_dt is None
    assert [r["dt"] for r in check.rows] == pytest.approx([5e-4, 2e-4, 1e-4])
    assert check.settings.dt == pytest.approx(1e-4)
    # The point handed on is the reference step's search, not the coarse one.
    assert check.point is not p and check.point.provenance.dt == pytest.approx(1e-4)
    ref = check.rows[-1]
    assert (check.point.a_engine == ref["a_engine"]
            or (math.isnan(check.point.a_engine) and math.isnan(ref["a_engine"])))
    assert "no step down to the reference" in check.detail(1e-6)
