"""The accurate simulator against closed forms derived independently here.

* Eq. 11: uplift at ``g/lam`` without pendulum (any ``mu``), and the simulated
  uplift time of a one-sine pulse ``asin(g/(lam A))/Omega``.
* Uplift with the pendulum hanging still: ``g (1+mu+gamma) / (lam (1+mu))``, and
  the simulated uplift with a pendulum that swings before uplift.
* Eq. 20 against the Makris-Vassiliou rocking-frame restitution and Housner's.
* Free rocking: amplitudes, impact times and velocities from energy + restitution.
* Energy: conserved between impacts after the pulse, never increases at impacts.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from tests.support.closed_forms import makris_vassiliou
from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.simulate import Settings, simulate


# --- uplift --------------------------------------------------------------------------
@pytest.mark.parametrize("mu", [0.0, 0.5, 1.0, 3.0])
@pytest.mark.parametrize("lam", [2.0, 5.0, 9.0])
def test_eq11_uplift_acceleration_without_pendulum(lam, mu):
    sc = Scene(b=0.6, lam=lam, mu=mu, gamma=0.0)
    b, h, mu_, gamma, j, l, g = sc.model_args()
    for side in (1.0, -1.0):
        a_up = eq.uplift_acceleration(0.0, 0.0, side, b, h, mu_, gamma, l, g)
        # Closed form: moment balance about a base corner; round-off only.
        assert a_up == pytest.approx(side * g / lam, rel=1e-13)


@pytest.mark.parametrize("amplitude,omega", [(2.5, 9.0), (6.0, 15.0), (-4.0, 5.0)])
def test_simulated_uplift_time_one_sine_without_pendulum(fig5_bare, amplitude, omega):
    a_up = fig5_bare.g / fig5_bare.lam
    tr = simulate(fig5_bare, Pulse(amplitude, omega), Settings(t_max=0.5 * 2 * math.pi / omega))
    up = [e for e in tr.events if e.kind == "uplift"][0]
    # |A| sin(W t) first reaches a_up in the first half cycle; A < 0 mirrors the
    # pulse, so the uplift is about the right corners at the same instant.
    expected = math.asin(a_up / abs(amplitude)) / omega
    assert up.side == (1 if amplitude > 0 else -1)
    # The margin is a pure function of t here: brentq's xtol (4 eps) plus the
    # nudge to margin <= 0 (a few eps) bound the error far below 1e-12 s.
    assert up.t == pytest.approx(expected, abs=1e-12)


def test_one_cosine_above_uplift_lifts_at_once(fig5_bare):
    a_up = fig5_bare.g / fig5_bare.lam
    tr = simulate(fig5_bare, Pulse(1.5 * a_up, 10.0, "cosine"), Settings(t_max=0.3))
    up = tr.events[0]
    assert (up.kind, up.t, up.side) == ("uplift", 0.0, 1)
    # Below a_up the cosine lifts on the other side at pi - acos(a_up/A) ... never:
    # at 0.9 a_up nothing happens in either direction (|xg| < a_up throughout).
    tr = simulate(fig5_bare, Pulse(0.9 * a_up, 10.0, "cosine"))
    assert not tr.events and tr.verdict.status == "survived"


@pytest.mark.parametrize("mu,gamma", [(1.0, 0.3), (0.0, 0.5), (2.0, 1.0)])
def test_uplift_with_pendulum_hanging_still(mu, gamma):
    # Independent derivation: at rest with psi = psi_dot = 0 the base acceleration
    # a gives the bob psi_ddot = -a/l, i.e. zero absolute acceleration, so the bob
    # adds only weight: g b (1+mu+gamma) = a h (1+mu) about the corners.
    sc = Scene(b=0.6, lam=5.0, mu=mu, gamma=gamma)
    b, h, mu_, gamma_, j, l, g = sc.model_args()
    expected = g * (1 + mu + gamma) / (sc.lam * (1 + mu))
    assert eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu_, gamma_, l, g) == pytest.approx(
        expected, rel=1e-13)  # round-off only


def test_simulated_uplift_with_swinging_pendulum(fig5):
    amplitude, omega = 2.3, 9.0  # just above a_up (2.256): the bob swings ~5 mrad first
    pulse = Pulse(amplitude, omega)
    tr = simulate(fig5, pulse, Settings(t_max=0.4))
    up = tr.events[0]
    assert up.kind == "uplift" and up.side == 1
    b, h, mu, gamma, j, l, g = fig5.model_args()
    # Pendulum state at uplift from an independent integration of Eq. 1 (Radau,
    # tighter tolerances than the simulator's DOP853).
    ref = solve_ivp(lambda t, y: (y[1], eq.rest_pendulum_acceleration(y[0], pulse.acceleration(t),
                                                                      l, g)),
                    (0.0, up.t), [0.0, 0.0], method="Radau", rtol=1e-12, atol=1e-14)
    psi, psi_dot = ref.y[:, -1]
    # The bob has swung before uplift (it is not hanging still) ...
    assert abs(psi) > 1e-3
    assert up.psi == pytest.approx(psi, abs=1e-8)  # two integrators at rtol 1e-10 / 1e-12
    # ... so uplift happens where Eq. 9's margin with that state reaches zero,
    # not at the hanging-still a_up.
    margin = eq.uplift_margin(psi, psi_dot, pulse.acceleration(up.t), 1.0, b, h, mu, gamma, l, g)
    scale = g * (1 + mu + gamma) * b  # the margin's size at rest
    assert abs(margin) < 1e-7 * scale  # state error 1e-8 times O(10) sensitivities
    a_still = g * (1 + mu + gamma) / (fig5.lam * (1 + mu))
    t_still = math.asin(a_still / amplitude) / omega
    assert abs(up.t - t_still) > 1e-4  # the swing shifts uplift by far more than the tolerance
    # No uplift earlier: the margin is positive on every earlier sample.
    before = tr.t < up.t
    xg = pulse.acceleration_array(tr.t[before])
    margins = [eq.uplift_margin(p, pd, a, s, b, h, mu, gamma, l, g)
               for p, pd, a in zip(tr.psi[before], tr.psi_dot[before], xg) for s in (1.0, -1.0)]
    assert min(margins) > 0.0


# --- restitution ----------------------------------------------------------------------
@pytest.mark.parametrize("lam", [1.5, 3.0, 5.0, 10.0])
@pytest.mark.parametrize("mu", [0.0, 0.3, 1.0, 5.0])
def test_eq20_is_makris_vassiliou(lam, mu):
    sc = Scene(b=0.6, lam=lam, mu=mu, gamma=0.0)
    b, h, mu_, gamma, j, l, g = sc.model_args()
    ref = makris_vassiliou(sc.alpha, mu / 2.0)  # two columns carry the lintel
    for side in (1.0, -1.0):
        e = eq.restitution_ratio(0.0, side, b, h, mu_, gamma, j)
        assert e == pytest.approx(ref, rel=1e-12)  # round-off only


def test_eq20_tends_to_housner_as_mu_vanishes():
    sc = Scene(b=0.6, lam=4.0, mu=0.0, gamma=0.0)
    b, h, _, _, j, _, _ = sc.model_args()
    housner = 1.0 - 1.5 * math.sin(sc.alpha) ** 2
    values = [eq.restitution_ratio(0.0, 1.0, b, h, mu, 0.0, j) for mu in (1e-2, 1e-4, 1e-6, 0.0)]
    errors = [abs(v - housner) for v in values]
    assert errors[-1] < 1e-14  # exact at mu = 0, round-off only
    assert errors[0] > errors[1] > errors[2]  # monotone approach, O(mu)
    assert errors[2] < 1e-6


# --- free rocking ----------------------------------------------------------------------
def _free_rocking_reference(scene: Scene, theta0: float, n: int):
    """Peaks, impact times and speeds from energy and restitution alone."""
    b, h, mu, _, j, _, g = scene.model_args()
    alpha, big_m = scene.alpha, 1.0 + mu
    r2 = math.hypot(b, h)
    inertia = 2.0 * j + (b * b + h * h) * (0.5 + mu)  # two columns + translating lintel
    e = makris_vassiliou(alpha, mu / 2.0)

    def drop(tn, th):  # V(tn) - V(th), V = g M (r2 cos(alpha - th) - h), cancellation-free
        return 2.0 * g * big_m * r2 * math.sin(alpha - 0.5 * (tn + th)) * math.sin(0.5 * (tn - th))

    def smooth(tn, th):  # (tn - th) / (2 drop / I): finite at th = tn
        u = 0.5 * (tn - th)
        q = u / math.sin(u) if u != 0.0 else 1.0
        return q * inertia / (2.0 * g * big_m * r2 * math.sin(alpha - 0.5 * (tn + th)))

    def quarter(tn):  # time from rest at tn to theta = 0; quad's 'alg' weight takes the
        # 1/sqrt(tn - th) singularity, the rest is smooth
        val, _ = quad(lambda th: math.sqrt(smooth(tn, th)), 0.0, tn,
                      weight="alg", wvar=(0.0, -0.5), epsabs=1e-14, epsrel=1e-13)
        return val

    peaks, times, speeds = [theta0], [], []
    t = 0.0
    for k in range(n):
        tn = peaks[-1]
        t += quarter(tn) if k == 0 else 2.0 * quarter(tn)
        times.append(t)
        speed = math.sqrt(2.0 * drop(tn, 0.0) / inertia)  # energy at theta = 0
        speeds.append(speed)
        # Kinetic energy times e^2 at the impact; next peak where V = e^2 V(tn):
        # cos(alpha - t_{n+1}) = cos(alpha) + e^2 (cos(alpha - t_n) - cos(alpha)).
        c = math.cos(alpha) + e * e * (math.cos(alpha - tn) - math.cos(alpha))
        peaks.append(alpha - math.acos(c))
    return np.array(peaks), np.array(times), np.array(speeds), e


def test_free_rocking_follows_energy_and_restitution(fig5_bare):
    theta0, n = 0.6 * fig5_bare.alpha, 6
    peaks, times, speeds, e = _free_rocking_reference(fig5_bare, theta0, n)
    st = Settings(theta0=theta0, t_max=float(times[-1]) + 1e-3, sample_dt=1e-4)
    tr = simulate(fig5_bare, Pulse(0.0, 1e4), st)  # zero-amplitude pulse: free rocking
    impacts = tr.impacts[:n]
    assert len(impacts) == n
    # Impact instants: event roots (~1e-15 s) on a solution with rtol 1e-10 over ~3 s.
    assert np.allclose([i.t for i in impacts], times, rtol=0, atol=1e-8)
    sign = np.array([(-1) ** (k + 1) for k in range(n)])  # theta0 > 0: first impact heads right
    assert np.allclose([i.theta_dot_before for i in impacts], sign * speeds, rtol=1e-8, atol=0)
    assert np.allclose([i.theta_dot_after for i in impacts], sign * e * speeds, rtol=1e-8, atol=0)
    # Peaks from the samples between impacts; at 0.1 ms spacing the sampled
    # maximum is below the true one by at most theta_ddot dt^2/8 ~ 1e-9 rad.
    edges = [0.0] + [i.t for i in impacts]
    for k in range(n):
        inside = (tr.t > edges[k]) & (tr.t < edges[k + 1]) if k else (tr.t < edges[1])
        assert np.max(np.abs(tr.theta[inside])) == pytest.approx(peaks[k], abs=1e-8)


# --- energy ------------------------------------------------------------------------------
def _phase_energy(scene, theta, theta_dot, psi, psi_dot):
    args = scene.model_args()
    if theta == 0.0 and theta_dot == 0.0:
        return eq.rest_energy(psi, psi_dot, args[3], args[5], args[6])
    return eq.energy(theta, theta_dot, psi, psi_dot, 1.0 if theta > 0 else -1.0, *args)


@pytest.mark.parametrize("amplitude,omega", [(5.0, 9.0), (15.0, 14.0)])
def test_energy_conserved_between_impacts_after_pulse(fig5, amplitude, omega):
    pulse = Pulse(amplitude, omega)
    tr = simulate(fig5, pulse, Settings(t_max=pulse.period + 6.0))
    assert tr.verdict.status == "survived" and tr.n_impacts >= 3
    cuts = sorted({e.t for e in tr.events if e.kind in ("impact", "rest")} | {pulse.period})
    checked = 0
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        if lo < pulse.period:
            continue
        inside = np.flatnonzero((tr.t > lo) & (tr.t < hi))
        energies = np.array([_phase_energy(fig5, tr.theta[i], tr.theta_dot[i], tr.psi[i],
                                           tr.psi_dot[i]) for i in inside])
        if energies.size < 2:
            continue
        scale = max(np.max(np.abs(energies)), 1e-3 * eq.overturn_energy_barrier(
            *fig5.model_args()[:4], fig5.g))
        # DOP853 at rtol 1e-10: the drift over one free swing is ~1e-10 relative.
        assert np.ptp(energies) < 1e-8 * scale
        checked += 1
    assert checked >= 3


def test_energy_never_increases_at_impacts_in_runs(fig5):
    tr = simulate(fig5, Pulse(5.0, 9.0), Settings(t_max=8.0))
    args = fig5.model_args()
    assert tr.n_impacts >= 5
    for e in tr.impacts:
        before = eq.energy(0.0, e.theta_dot_before, e.psi, e.psi_dot_before, -e.side, *args)
        after = eq.energy(0.0, e.theta_dot_after, e.psi, e.psi_dot_after, e.side, *args)
        assert after <= before + 1e-12 * abs(before)  # round-off of the map only


def test_energy_never_increases_at_impacts_random_states():
    rng = np.random.default_rng(20240611)
    checked = 0
    for _ in range(3000):
        sc = Scene(b=rng.uniform(0.1, 2.0), lam=rng.uniform(1.5, 12.0), mu=rng.uniform(0.0, 5.0),
                   gamma=rng.uniform(0.01, 1.0), l=rng.uniform(0.1, 5.0))
        args = sc.model_args()
        b, h, mu, gamma, j, l, g = args
        new_side = rng.choice([-1.0, 1.0])
        td = -new_side * rng.uniform(1e-3, 3.0)  # heading towards the new side's corners
        psi, pd = rng.uniform(-math.pi, math.pi), rng.uniform(-8.0, 8.0)
        tdp, pdp = eq.impact_velocities(td, psi, pd, new_side, b, h, mu, gamma, j, l)
        before = eq.energy(0.0, td, psi, pd, -new_side, *args)
        after = eq.energy(0.0, tdp, psi, pdp, new_side, *args)
        assert after <= before + 1e-11 * max(abs(before), 1.0), (args, td, psi, pd)
        checked += 1
    assert checked == 3000


@pytest.mark.parametrize("kind", ["sine", "cosine"])
@pytest.mark.parametrize("excess", [1e-3, 1e-9, 1e-14])
def test_uplift_threshold_is_sharp_without_pendulum(fig5_bare, kind, excess):
    # REST stops at the pulse's |xg| peaks, where the margin (a function of t only
    # here) is smallest, so a dip lasting nanoseconds is not stepped over; the
    # barely-lifted frame comes back and rests (no endless uplift/rest loop).
    a_up = fig5_bare.g / fig5_bare.lam
    omega = 9.0
    period = 2 * math.pi / omega
    above = simulate(fig5_bare, Pulse(a_up * (1 + excess), omega, kind))
    below = simulate(fig5_bare, Pulse(a_up * (1 - excess), omega, kind))
    assert below.events == () and below.verdict.status == "survived"
    assert above.verdict.status == "survived" and "barrier" in above.verdict.reason
    ups = [e for e in above.events if e.kind == "uplift"]
    # sine: +A at T/4, -A at 3T/4; cosine: +A at 0, -A at T/2 (then +A again at T).
    peaks = [0.25 * period, 0.75 * period] if kind == "sine" else [0.0, 0.5 * period]
    firsts = [next(e for e in ups if e.side == side) for side in (1, -1)]
    half_width = math.sqrt(2 * excess) / omega  # |xg| >= a_up for |t - peak| < this
    # Round-off of a few eps in the flat margin near the peak moves the root by
    # ~eps/(Omega^2 half_width); brentq's own xtol adds ~1e-15 s.
    tol = 1e-12 + 1e-15 / (omega ** 2 * half_width)
    for e, peak in zip(firsts, peaks):
        assert peak - half_width - tol <= e.t <= peak + tol  # uplift where the dip starts
    assert above.max_abs_theta < 1e-6  # a tiny lift only
