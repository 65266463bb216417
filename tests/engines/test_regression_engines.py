"""Regression: every engine tied to the paper's equations with its calibrated defaults.

* free rocking restitution against Eq. 20 within 0.5 % (the acceptance tolerance)
  on a small lam x mu grid (the grid's corners and centre);
* with the pendulum, against Eq. 19 at the measured psi, within the campaign's
  stated tolerance (``Tolerances.restitution_pendulum``);
* one overturning threshold per engine within 2 % of the analytic one at a
  frequency away from mode jumps.

The expected values are the corrected equations (Eq. 19/20, checked against an
independent sympy derivation in tests/analytic/test_derivation.py) and the analytic
model's threshold computed here, never numbers recorded from an engine run.
"""
from __future__ import annotations

import pytest

from trilith_xval.compare.campaign.validation import CampaignConfig, Tolerances, campaign_run
from trilith_xval.compare.measure.reference_spectra import first_overturning_amplitude, monotone_above
from trilith_xval.compare.measure.thresholds import engine_threshold
from trilith_xval.engines import engine_names, get_backend
from trilith_xval.scenes import load_scene

TOL = Tolerances()
CONFIG = CampaignConfig()  # calibrated engine settings, theta0 = alpha/2, 4 impacts


# One point per engine (its class's ``regression_point``), on both branches of the
# Fig. 5 spectrum: with the pendulum at 12.5-13 rad/s (no-impact branch, above its
# mode jump at 10-10.5) and without it at 12.5 rad/s (after-impact branch, 5 rad/s
# below its jump at 17.5-18).  Below ~10 rad/s the pendulum curve has narrow
# overturning windows (see analytic/spectrum.py), where "the" threshold is
# ill-posed for a bisection; the test checks the point is well posed.


@pytest.mark.slow
@pytest.mark.parametrize("engine", engine_names())
def test_overturning_threshold_within_2_percent(engine):
    scene_name, omega = get_backend(engine).regression_point
    scene = load_scene(scene_name)
    a_ref, mode_ref = first_overturning_amplitude(scene, omega)
    # The point is well posed: the model overturns throughout the bracket above it,
    # and no mode jump lies within CONFIG.jump_margin of it.
    assert monotone_above(scene, omega, a_ref, 2 * CONFIG.rel_bracket)
    for w in (omega - CONFIG.jump_margin, omega + CONFIG.jump_margin):
        assert first_overturning_amplitude(scene, w)[1] == mode_ref
    p = engine_threshold(engine, scene, omega, a_ref, campaign_run(engine, CONFIG, scene).settings,
                         mode_reference=mode_ref, rel_tol=4e-3)
    # Every probe must end 'overturned' or 'survived' (an 'unstable' run would
    # count as survived and bias the bisection).
    assert p.irregular_runs == 0
    assert p.bracketed
    # Issue acceptance: 2 % away from jumps; the bisection resolves 0.4 %.
    assert abs(p.rel_error) <= TOL.threshold, (p.a_engine, a_ref)
    assert p.mode_engine == mode_ref
