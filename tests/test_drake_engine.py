"""Acceptance of the Drake backend against the corrected analytic model.

Restitution (Housner, Eq. 20 through Makris-Vassiliou, Eq. 19), the paper's
Fig. 5 verdicts at A-D, the pendulum at rest (Eq. 1), sign conventions,
validation before any plant is built, and the hydroelastic contact measured as
the artefact it is.  Drake costs ~2 CPU s per simulated second (SAP, point
contact), so the restitution grid is cut to its corners and the long checks are
``slow``; budget ~150 CPU s on 2 cores.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from analytic.excitation import Pulse
from analytic.parameters import Scene
from compare.restitution import measure_restitution
from engines.drake_ import DrakeEngine, Settings
from scenes import PAPER_OUTCOMES, load_scene, point_pulse
from test_closed_forms import makris_vassiliou

# The engine contract's acceptance bound for restitution (Eq. 19/20 within
# 0.5 %); the measured worst at the defaults is in docs/drake.md.
RESTITUTION_TOL = 5e-3


def test_single_columns_mu0_match_housner():
    # mu = 0: no lintel body, the columns rock as single blocks; Eq. 20 is then
    # Housner's 1 - 1.5 sin^2(alpha) for a uniform column (independent formula).
    scene = Scene(lam=4.0, mu=0.0, gamma=0.0)
    res = measure_restitution("drake", scene, 0.5 * scene.alpha, n_impacts=2)
    housner = 1.0 - 1.5 * math.sin(scene.alpha) ** 2
    assert [i.measured for i in res.impacts] == pytest.approx([housner] * 2, rel=RESTITUTION_TOL)


@pytest.mark.slow
@pytest.mark.parametrize("lam, mu", [(3.0, 0.5), (5.0, 1.0), (7.0, 2.0)])
def test_restitution_matches_makris_vassiliou(lam, mu):
    # The grid's corners and centre (the whole lam 3/5/7 x mu 0.5/1/2 grid is in
    # docs/drake.md): the light lintel on squat columns is the hardest case.
    scene = load_scene("fig5", lam=lam, mu=mu, gamma=0.0)
    res = measure_restitution("drake", scene, n_impacts=4)
    assert res.complete, res.status
    closed_form = makris_vassiliou(scene.alpha, mu / 2.0)  # two columns carry the lintel
    errors = [i.measured / closed_form - 1.0 for i in res.impacts]
    assert max(map(abs, errors)) <= RESTITUTION_TOL, errors


@pytest.mark.slow
def test_restitution_with_pendulum_matches_eq19(fig5):
    res = measure_restitution("drake", fig5, n_impacts=4)
    assert res.complete, res.status
    assert max(abs(i.psi) for i in res.impacts) > 0.05  # the pendulum swings: psi matters
    assert res.max_rel_error <= RESTITUTION_TOL, [i.rel_error for i in res.impacts]


@pytest.mark.slow
@pytest.mark.parametrize("pendulum", [True, False], ids=["pendulum", "bare"])
@pytest.mark.parametrize("point", "ABCD")
def test_paper_points_give_the_papers_verdict_and_mode(point, pendulum, fig5):
    scene = fig5 if pendulum else fig5.without_pendulum()
    tr = DrakeEngine.simulate(scene, point_pulse(point))
    assert (tr.verdict.status, tr.verdict.mode) == PAPER_OUTCOMES[(point, pendulum)], tr.verdict


@pytest.mark.slow
def test_hydroelastic_contact_is_too_elastic_and_the_measurement_says_so():
    """A pressure patch instead of a corner: the impact is spread over the patch
    and keeps too much energy.  Measured +2.5 to +3.6 % on a single block (shared
    notes) and on the frame (docs/drake.md): the restitution check, which the
    point contact passes within 0.5 %, names it beyond 1 %."""
    scene = load_scene("fig5", gamma=0.0)
    res = measure_restitution("drake", scene, n_impacts=1, contact_model="hydroelastic")
    assert res.complete, res.status
    assert res.impacts[0].rel_error > 0.01, res.impacts[0]


def test_positive_pulse_rocks_on_left_corners_like_analytic(fig5, run_analytic):
    # Sign convention: xg_ddot > 0 pushes the trilith onto its left corners
    # (theta > 0, Eq. 9 with side = +1); the applied forces stand in for the
    # horizontal gravity, so the onset must be the model's: first passage of
    # |theta| = 1e-2 rad within 0.5 ms (half a sample period).
    tr = DrakeEngine.simulate(fig5, Pulse(10.0, 9.0), Settings(t_max=0.3))
    ref = run_analytic(fig5, 10.0, 9.0)

    def first_passage(traj):
        k = int(np.argmax(np.abs(traj.theta) > 1e-2))
        assert traj.theta[k] > 0
        return np.interp(1e-2, np.abs(traj.theta[k - 1:k + 1]), traj.t[k - 1:k + 1])

    assert first_passage(tr) == pytest.approx(first_passage(ref), abs=5e-4)


def test_pendulum_on_a_resting_trilith_follows_eq1(fig5):
    """psi0 = 0.1 rad on the trilith at rest swings as Eq. 1 (psi CCW from the
    downward vertical): joint axis and sign.  1e-4 rad / 5e-4 rad/s over 1 s,
    the bound the other engines meet (step error of a 1e-4 s integrator)."""
    from scipy.integrate import solve_ivp

    from analytic import equations as eq
    from analytic.excitation import Still

    tr = DrakeEngine.simulate(fig5, Still(), Settings(psi0=0.1, t_max=1.0, early_stop=False))
    assert tr.max_abs_theta < 1e-5  # the trilith stayed down (compliant contact: ~1e-6 rad)
    l, g = fig5.pendulum_length, fig5.g
    sol = solve_ivp(lambda t, y: (y[1], eq.rest_pendulum_acceleration(y[0], 0.0, l, g)),
                    (0.0, tr.t[-1]), (0.1, 0.0), t_eval=tr.t, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(tr.psi - sol.y[0])) < 1e-4
    assert np.max(np.abs(tr.psi_dot - sol.y[1])) < 5e-4


def test_static_sink_is_the_calibrated_one(fig5):
    """The stiffness rule: at rest, each column's share of the weight sinks its
    four base spheres by ``sink_fraction b`` (the penetration read from the
    poses, the same for every engine), within 10 % (the lintel's share is split
    between the columns only on average)."""
    from analytic.excitation import Still

    s = Settings(t_max=0.3, early_stop=False)
    tr = DrakeEngine.simulate(fig5, Still(), s)
    assert tr.diagnostics["penetration_max"] == pytest.approx(s.sink_fraction * fig5.b, rel=0.1)


@pytest.mark.parametrize("changes, field", [
    ({"contact_model": "mesh"}, "contact_model"), ({"solver": "tamsi"}, "solver"),
    ({"base_motion": "ground"}, "base_motion"), ({"sink_fraction": 0.0}, "sink_fraction"),
    ({"damping_ratio": -1.0}, "damping_ratio"), ({"relaxation_time": math.inf},
                                                 "relaxation_time"),
    ({"sphere_fraction": 0.5}, "sphere_fraction"), ({"dt": 0.0}, "dt"),
    ({"friction": 1.0}, "friction"),  # point D peaks at 2.55 g
])
def test_bad_settings_raise_before_building(fig5, monkeypatch, changes, field):
    monkeypatch.setattr(DrakeEngine, "build", lambda self: pytest.fail("built before checks"))
    with pytest.raises((ValueError, TypeError), match=field):
        DrakeEngine.simulate(fig5, Pulse(25.0, 11.0), dataclasses.replace(Settings(), **changes))
