"""Property-based tests (hypothesis) of the analytic model: mirror symmetry and energy.

Two layers:

* the scalar equations (``analytic/equations.py``, Eq. 1, 8/A.1, 9, 19, 21) over
  random parameters and states -- cheap, many examples;
* whole runs of the event-driven simulator (``analytic/simulate.py``) -- fewer
  examples, each a full simulation.

Every test is derandomised (``derandomize=True``) so CI sees the same examples on
every run, and has ``deadline=None`` (a simulation's wall time is not a property).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.parameters import LENGTH_RANGE, Scene

# Common hypothesis profile: deterministic, no deadline; example counts per test.
CHEAP = settings(max_examples=300, deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.too_slow])
RUNS = settings(max_examples=15, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])

# --- strategies: the stress-grid ranges of the brief ---------------------------------
lams = st.floats(1.5, 30.0)
mus = st.floats(0.0, 10.0)
gammas = st.floats(0.0, 1.0)
l_fracs = st.floats(0.1, 2.0)          # l / h
widths = st.floats(0.05, 3.0)          # b [m]
angles = st.floats(-math.pi, math.pi)
rates = st.floats(-20.0, 20.0)         # rad/s: well past any overturning speed
accels = st.floats(-50 * 9.81, 50 * 9.81)  # up to 50 g, as in the stress grid
sides = st.sampled_from([1.0, -1.0])


@st.composite
def scenes(draw, with_pendulum: bool | None = None) -> Scene:
    lam = draw(lams)
    b = draw(widths)
    gamma = draw(gammas) if with_pendulum is None else (draw(st.floats(0.01, 1.0))
                                                         if with_pendulum else 0.0)
    l = draw(l_fracs) * lam * b
    assume(l <= LENGTH_RANGE[1])  # Scene's documented range (a pendulum <= 100 m)
    return Scene(b=b, lam=lam, mu=draw(mus), gamma=gamma, l=l)


def _scale(scene: Scene) -> float:
    """A natural size of accelerations [1/s^2] for relative comparisons: g / R."""
    return scene.g / scene.R


# --- equations: mirror symmetry -------------------------------------------------------
@CHEAP
@given(scenes(), angles, rates, angles, rates, accels, sides)
def test_rocking_equations_mirror(scene, theta, theta_dot, psi, psi_dot, xg, side):
    """Eq. 8 and A.1 are mirror images: (theta, psi, xg, side) -> their negatives
    negates both accelerations."""
    args = scene.model_args()
    a = eq.rocking_accelerations(theta, theta_dot, psi, psi_dot, xg, side, *args)
    m = eq.rocking_accelerations(-theta, -theta_dot, -psi, -psi_dot, -xg, -side, *args)
    scale = _scale(scene) * (1.0 + abs(xg) / scene.g) + theta_dot ** 2 + psi_dot ** 2
    # Same floating-point operations up to sign: agreement to rounding (1e-12 relative).
    assert m[0] == pytest.approx(-a[0], abs=1e-12 * scale)
    assert m[1] == pytest.approx(-a[1], abs=1e-12 * scale * (1 + scene.h / scene.pendulum_length))


@CHEAP
@given(scenes(), angles, rates, accels, sides)
def test_uplift_mirror(scene, psi, psi_dot, xg, side):
    """Eq. 9: the uplift threshold and the contact margin mirror exactly."""
    b, h, mu, gamma, j, l, g = scene.model_args()
    up = eq.uplift_acceleration(psi, psi_dot, side, b, h, mu, gamma, l, g)
    up_m = eq.uplift_acceleration(-psi, -psi_dot, -side, b, h, mu, gamma, l, g)
    assert up_m == pytest.approx(-up, rel=1e-12, abs=1e-12 * g)  # rounding only
    mg = eq.uplift_margin(psi, psi_dot, xg, side, b, h, mu, gamma, l, g)
    mg_m = eq.uplift_margin(-psi, -psi_dot, -xg, -side, b, h, mu, gamma, l, g)
    scale = g * (1 + mu + gamma) * (b + h) * (1.0 + abs(xg) / g) + gamma * l * l * psi_dot ** 2
    assert mg_m == pytest.approx(mg, abs=1e-12 * scale)  # rounding only


@CHEAP
@given(scenes(), angles, rates, rates, sides)
def test_impact_map_mirror(scene, psi, theta_dot, psi_dot, new_side):
    """Eq. 19/21: mirrored pre-impact state gives mirrored post-impact velocities."""
    b, h, mu, gamma, j, l, g = scene.model_args()
    td = abs(theta_dot) * new_side  # the impact hands rocking over to new_side
    a = eq.impact_velocities(td, psi, psi_dot, new_side, b, h, mu, gamma, j, l)
    m = eq.impact_velocities(-td, -psi, -psi_dot, -new_side, b, h, mu, gamma, j, l)
    scale = abs(td) * (1 + h / l) + abs(psi_dot)
    assert m[0] == pytest.approx(-a[0], abs=1e-12 * scale)  # rounding only
    assert m[1] == pytest.approx(-a[1], abs=1e-12 * scale)


# --- equations: energy ----------------------------------------------------------------
@CHEAP
@given(scenes(), angles, rates, rates, sides)
def test_impact_never_adds_energy(scene, psi, speed, psi_dot, new_side):
    """Eq. 13-21 model a perfectly plastic impact: the mechanical energy just after
    is never larger than just before (energy per m1, Eq. 6-7 in the base frame)."""
    b, h, mu, gamma, j, l, g = scene.model_args()
    td_minus = new_side * abs(speed)  # rocking on the old side (-new_side) towards theta=0
    td_plus, pd_plus = eq.impact_velocities(td_minus, psi, psi_dot, new_side, b, h, mu, gamma,
                                            j, l)
    before = eq.energy(0.0, td_minus, psi, psi_dot, -new_side, *scene.model_args())
    after = eq.energy(0.0, td_plus, psi, pd_plus, new_side, *scene.model_args())
    kin = (0.5 * eq.rocking_inertia(b, h, mu, gamma, j) * td_minus ** 2
           + 0.5 * gamma * l * l * psi_dot ** 2 + 2 * gamma * l * (b + h) * abs(td_minus * psi_dot))
    # Rounding of O(1e-15) on energies of size `kin`; 1e-12 leaves margin.
    assert after <= before + 1e-12 * max(kin, 1e-30)
    # The rocking rate keeps its sign (or stops).  With a pendulum swung far out the
    # ratio of Eq. 19 may exceed 1 (the pendulum's momentum is shared with the
    # columns) while the energy still drops, so <= 1 only holds without one.
    ratio = eq.restitution_ratio(psi, new_side, b, h, mu, gamma, j)
    assert ratio >= 0.0
    if gamma == 0.0:
        assert ratio <= 1.0
    assert td_plus * td_minus >= 0.0


@CHEAP
@given(lams, mus, st.floats(0.05, 3.0))
def test_restitution_eq20_bounds(lam, mu, b):
    """Eq. 20 (no pendulum, uniform columns): Housner's single-block value
    ``1 - 1.5 sin^2(alpha)`` when the lintel is massless (two free blocks), and
    between ``cos(2 alpha)`` (a lintel infinitely heavier than the columns: the
    lintel's horizontal momentum about the new corner) and Housner otherwise,
    decreasing with mu: a heavier lintel loses more at each impact."""
    scene = Scene(b=b, lam=lam, mu=mu, gamma=0.0)
    b_, h, mu_, gamma, j, l, g = scene.model_args()
    r = eq.restitution_ratio(0.0, 1.0, b_, h, mu_, gamma, j)
    housner = 1.0 - 1.5 * math.sin(scene.alpha) ** 2
    heavy = math.cos(2.0 * scene.alpha)
    assert heavy - 1e-12 <= r <= housner + 1e-12  # rounding only
    r0 = eq.restitution_ratio(0.0, 1.0, b_, h, 0.0, gamma, j)
    assert r0 == pytest.approx(housner, rel=1e-12)  # closed form vs formula: rounding
    r_heavier = eq.restitution_ratio(0.0, 1.0, b_, h, mu_ + 1.0, gamma, j)
    assert r_heavier <= r + 1e-15  # rounding only


@CHEAP
@given(scenes(with_pendulum=True), st.floats(-1.0, 1.0), st.floats(-3.0, 3.0),
       st.floats(-0.5, 0.5), st.floats(-3.0, 3.0), sides)
def test_energy_conserved_between_impacts(scene, theta_frac, theta_dot, psi, psi_dot, side):
    """With the base still, Eq. 8 / A.1 conserve the energy of ``equations.energy``
    (checks that the equations of motion and the energy are the same Lagrangian)."""
    args = scene.model_args()
    theta = side * abs(theta_frac) * scene.alpha  # on the rocking side
    y0 = [theta, theta_dot, psi, psi_dot]

    def rhs(t, y):
        a, p = eq.rocking_accelerations(y[0], y[1], y[2], y[3], 0.0, side, *args)
        return (y[1], a, y[3], p)

    t_end = 2.0 * math.sqrt(scene.R / scene.g)  # a couple of natural time units
    sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-11, atol=1e-12,
                    dense_output=False)
    e = [eq.energy(*sol.y[:, k], side, *args) for k in range(sol.y.shape[1])]
    e_scale = scene.g * scene.R * (1 + scene.mu + scene.gamma) + abs(e[0])
    # DOP853 at rtol 1e-11 over a few units: drift well under 1e-7 of the energy scale.
    assert max(abs(v - e[0]) for v in e) <= 1e-7 * e_scale


@CHEAP
@given(scenes(), angles, rates, sides)
def test_energy_mirror(scene, theta, theta_dot, side):
    """The energy is mirror-invariant."""
    args = scene.model_args()
    psi, psi_dot = 0.3 * theta, -0.7 * theta_dot
    e = eq.energy(theta, theta_dot, psi, psi_dot, side, *args)
    e_m = eq.energy(-theta, -theta_dot, -psi, -psi_dot, -side, *args)
    scale = scene.g * scene.R * (1 + scene.mu + scene.gamma) + abs(e)
    assert e_m == pytest.approx(e, abs=1e-12 * scale)  # rounding only


# --- whole runs of the event-driven simulator -------------------------------------------
@st.composite
def pulses(draw, scene: Scene) -> Pulse:
    """A one-sine or one-cosine pulse from half to four times the uplift
    acceleration of Eq. 9 with the pendulum hanging (mostly rocking, sometimes
    overturning), Omega 1..30 rad/s."""
    factor = draw(st.floats(0.5, 4.0))
    omega = draw(st.floats(1.0, 30.0))
    kind = draw(st.sampled_from(["sine", "cosine"]))
    b, h, mu, gamma, j, l, g = scene.model_args()
    a_up = eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu, gamma, l, g)
    return Pulse(factor * a_up, omega, kind)


@st.composite
def scene_and_pulse(draw):
    scene = draw(scenes())
    return scene, draw(pulses(scene))


def _simulate(scene, pulse, **kw):
    from trilith_xval.analytic.simulate import Settings, simulate
    # A 3 s window after the pulse keeps every example bounded in cost.
    return simulate(scene, pulse, Settings(t_max=pulse.end_time + 3.0, **kw))


@RUNS
@given(scene_and_pulse())
def test_simulation_mirror_symmetry(sp):
    """Mirroring the ground motion mirrors the whole response: theta, psi and their
    rates change sign, the verdict and every event time are the same."""
    scene, pulse = sp
    a = _simulate(scene, pulse)
    m = _simulate(scene, pulse.mirrored())
    assert a.verdict.status == m.verdict.status
    assert a.verdict.mode == m.verdict.mode
    assert a.n_impacts == m.n_impacts
    assert [e.kind for e in a.events] == [e.kind for e in m.events]
    # Negation is exact in floating point and the integrator's error norm is
    # sign-blind, so the mirrored run takes the same steps: agreement to rounding.
    for ea, em in zip(a.events, m.events):
        assert em.t == pytest.approx(ea.t, abs=1e-9)
        assert em.side == -ea.side
    assert a.t.shape == m.t.shape
    scale = scene.alpha
    assert np.allclose(m.theta, -a.theta, rtol=0, atol=1e-9 * scale)
    assert np.allclose(m.psi, -a.psi, rtol=0, atol=1e-9 * (1 + np.max(np.abs(a.psi))))


@RUNS
@given(scene_and_pulse())
def test_simulation_energy_budget(sp):
    """After the pulse, the energy (Eq. 6-7 per m1, base frame) never increases --
    it only drops at impacts; and at every impact of the run it drops."""
    scene, pulse = sp
    tr = _simulate(scene, pulse)
    args = scene.model_args()
    scale = scene.g * (1 + scene.mu + scene.gamma) * 2.0 * scene.R
    for e in tr.impacts:
        before = eq.energy(0.0, e.theta_dot_before, e.psi, e.psi_dot_before, -e.side, *args)
        after = eq.energy(0.0, e.theta_dot_after, e.psi, e.psi_dot_after, e.side, *args)
        assert after <= before + 1e-12 * scale  # rounding only
    energies = []
    for t, th, td, ps, pd in zip(tr.t, tr.theta, tr.theta_dot, tr.psi, tr.psi_dot):
        if t < pulse.end_time or (th == 0.0 and td != 0.0):
            continue  # during the pulse work is done; at theta = 0 the side is ambiguous
        if th == 0.0:
            energies.append(eq.rest_energy(ps, pd, scene.gamma, scene.pendulum_length, scene.g))
        else:
            energies.append(eq.energy(th, td, ps, pd, 1.0 if th > 0 else -1.0, *args))
    if len(energies) > 1:
        # DOP853 at the default rtol 1e-10 over <= 1e4 steps: drift < 1e-7 of the scale.
        assert np.max(np.diff(energies)) <= 1e-7 * scale
