"""The pulse family: Ricker wavelets and the Mavroeidis-Papageorgiou pulse against
their closed forms (peaks, zero net velocity and displacement where the formula
says so, velocity and displacement as the integrals of the acceleration), the
one-sine pulse's peaks, and the model under a Ricker wavelet (uplift where Eq. 9
says)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import brentq

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.pulses import MavroeidisPapageorgiou, Ricker
from trilith_xval.analytic.simulate import Settings, simulate
from trilith_xval.scenes import load_scene

PULSES = [Ricker(3.0, 0.4), Ricker(-2.0, 1.1, "antisymmetric"),
          MavroeidisPapageorgiou(0.4, 1.5, 2.0, 0.0),
          MavroeidisPapageorgiou(0.3, 0.8, 2.7, 1.1),
          Pulse(2.0, 7.0), Pulse(2.0, 7.0, "cosine")]
N_FINE = 200_001


def fine(p):
    t = np.linspace(0.0, p.end_time, N_FINE)
    return t, p.acceleration_array(t)


@pytest.mark.parametrize("p", PULSES, ids=repr)
def test_velocity_and_displacement_are_the_integrals(p):
    t, a = fine(p)
    v = cumulative_trapezoid(a, t, initial=0.0)
    x = cumulative_trapezoid(v, t, initial=0.0)
    vs = np.array([p.velocity(s) for s in t[::1000]])
    xs = np.array([p.displacement(s) for s in t[::1000]])
    # Trapezoid on 2e5 intervals: error ~ T^2 a'' / (12 N^2) relative ~1e-9; the
    # MP pulse and the cosine jump at their ends (one interval, h a / 2).
    scale_v, scale_x = p.pgv, p.pgv * p.end_time
    assert np.max(np.abs(vs - v[::1000])) <= 1e-6 * scale_v + 1e-12
    assert np.max(np.abs(xs - x[::1000])) <= 1e-6 * scale_x + 1e-12


@pytest.mark.parametrize("p", PULSES, ids=repr)
def test_peaks(p):
    t, a = fine(p)
    # pga / pgv against the fine grid: grid spacing T/2e5 puts the sampled peak
    # within (pi / 2e5 * cycles)^2 / 2 relative of the true one.
    assert p.pga == pytest.approx(np.max(np.abs(a)), rel=1e-6)
    v = np.array([p.velocity(s) for s in t[::20]])
    assert p.pgv == pytest.approx(np.max(np.abs(v)), rel=1e-5)
    # The peak times are local extrema of |a| and the largest one is the PGA.
    peaks = np.abs(p.acceleration_array(np.array(p.peak_times)))
    assert np.max(peaks) == pytest.approx(p.pga, rel=1e-5)
    for tp in p.peak_times:
        h = 1e-4 * p.end_time
        mid = abs(p.acceleration(tp))
        assert mid >= abs(p.acceleration(tp - h)) - 1e-9 * p.pga
        assert mid >= abs(p.acceleration(tp + h)) - 1e-9 * p.pga


@pytest.mark.parametrize("p", [Ricker(3.0, 0.4), Ricker(-2.0, 1.1, "antisymmetric")], ids=repr)
def test_ricker_has_zero_net_velocity_and_displacement(p):
    """Exact for the untruncated wavelet.  Truncation at |tau| = 5 leaves terms of
    at most 49 exp(-25) = 6.8e-10 (the factor (1 - 2 tau^2) at tau = 5), times
    the pulse length over T_p/pi (10) for the displacement: below 1e-8
    relative to pgv and pgv T_p."""
    end = p.end_time
    assert abs(p.velocity(end)) <= 1e-8 * p.pgv
    assert abs(p.displacement(end)) <= 1e-8 * p.pgv * p.period
    assert abs(p.displacement(end + 3.0)) <= 1e-8 * p.pgv * (p.period + 3.0)


def test_ricker_centre_and_antisymmetric_peak():
    s = Ricker(3.0, 0.4)
    assert s.acceleration(s.centre) == pytest.approx(3.0, rel=1e-15)
    # (1 - 2 tau^2) exp(-tau^2) at its side lobes tau^2 = 3/2: -2 exp(-3/2).
    lobe = s.centre + math.sqrt(1.5) * s.period / math.pi
    assert s.acceleration(lobe) == pytest.approx(-2.0 * 3.0 * math.exp(-1.5), rel=1e-12)
    anti = Ricker(2.0, 0.4, "antisymmetric")
    assert anti.acceleration(anti.centre) == pytest.approx(0.0, abs=1e-15)
    # Odd about the centre.
    for d in (0.01, 0.05, 0.2):
        assert anti.acceleration(anti.centre + d) == pytest.approx(
            -anti.acceleration(anti.centre - d), rel=1e-12)


def test_mp_velocity_at_the_centre_and_ends():
    p = MavroeidisPapageorgiou(0.5, 1.2, 2.5, 0.7)
    assert p.velocity(p.t0) == pytest.approx(0.5 * math.cos(0.7), rel=1e-14)
    assert p.velocity(1e-12) == pytest.approx(0.0, abs=1e-12)
    assert p.velocity(p.end_time - 1e-12) == pytest.approx(0.0, abs=1e-12)



@pytest.mark.parametrize("gamma", [2.0, 2.5, 1.3, 3.0])
def test_mp_net_displacement_closed_form(gamma):
    """nu = 0: integrating v over |tau| <= gamma/(2 f_p) in product-to-sum form
    gives D = -A sin(pi gamma) / (2 pi f_p (gamma^2 - 1)): zero for an integer
    gamma, not otherwise (the MP pulse can leave the ground displaced)."""
    a, f = 0.5, 1.2
    q = MavroeidisPapageorgiou(a, f, gamma, 0.0)
    expected = -a * math.sin(math.pi * gamma) / (2.0 * math.pi * f * (gamma ** 2 - 1.0))
    assert q.displacement(q.end_time) == pytest.approx(expected, abs=1e-14)


@pytest.mark.parametrize("p", PULSES, ids=repr)
def test_scaled_and_mirrored(p):
    assert p.scaled(2.5).pga == pytest.approx(2.5 * p.pga, rel=1e-12)
    t = np.linspace(0.0, p.end_time, 101)
    assert p.mirrored().acceleration_array(t) == pytest.approx(-p.acceleration_array(t), abs=1e-15)


@pytest.mark.parametrize("make, match", [
    (lambda: Ricker(1.0, 0.0), "period"), (lambda: Ricker(1.0, 30.0), "period"),
    (lambda: Ricker(1e5, 1.0), "amplitude"), (lambda: Ricker(1.0, 1.0, "odd"), "kind"),
    (lambda: MavroeidisPapageorgiou(0.3, 1.0, 1.0), "gamma"),
    (lambda: MavroeidisPapageorgiou(0.3, 0.0), "frequency"),
    (lambda: MavroeidisPapageorgiou(0.3, 1.0, 2.0, 7.0), "nu"),
    (lambda: MavroeidisPapageorgiou(900.0, 10.0), "beyond"),
    (lambda: Pulse(1.0, 5.0).scaled(0.0), "factor")])
def test_bad_pulses_name_the_parameter(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_model_uplifts_under_a_ricker_where_eq9_says():
    """No pendulum: uplift when xg_ddot first reaches a_up (Eq. 9); for the
    symmetric wavelet that is the root of A (1 - 2 tau^2) exp(-tau^2) = a_up on
    the rising flank before the centre."""
    scene = load_scene("fig5").without_pendulum()
    b, h, mu, gamma, j, l, g = scene.model_args()
    a_up = eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu, gamma, l, g)
    w = Ricker(1.5 * a_up, 0.5)
    tau = brentq(lambda x: (1.0 - 2.0 * x * x) * math.exp(-x * x) - 1.0 / 1.5, -0.7, 0.0,
                 xtol=1e-15)
    expected = w.centre + tau * w.period / math.pi
    tr = simulate(scene, w, Settings(t_max=w.end_time + 1.0))
    # Root to ~1e-15 s then a nudge of a few ulp: far below any time scale here.
    assert tr.uplift_time == pytest.approx(expected, abs=1e-9)


def test_model_response_mirrors_under_the_mirrored_wavelet():
    scene = load_scene("fig5")
    w = Ricker(9.0, 0.35, "antisymmetric")
    st = Settings(t_max=3.0)
    a, m = simulate(scene, w, st), simulate(scene, w.mirrored(), st)
    assert m.verdict.status == a.verdict.status
    # Same equations mirrored (Eq. 8 <-> A.1): equal to the integrator's tolerance.
    assert m.theta == pytest.approx(-a.theta, abs=1e-7)
