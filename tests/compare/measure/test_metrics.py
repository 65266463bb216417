"""compare.measure.trajectories / compare.measure.thresholds on synthetic trajectories and fake backends.

Expected values come from closed forms (sinusoid differences, Housner's
restitution), never from running the code under test.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import trilith_xval.compare.measure.thresholds as thr
from trilith_xval.compare.measure import jump_shift
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.trajectory import Event, OverturnCriterion, Trajectory, Verdict
from trilith_xval.compare.measure import trajectories as metrics
from trilith_xval.compare.measure.restitution import restitution_from_trajectory

ALPHA = 0.2


def _traj(t, theta, psi=None, events=(), verdict=None, backend="analytic", settings=None,
          scene=None, theta_dot=None):
    t = np.asarray(t, float)
    theta = np.asarray(theta, float)
    psi = np.zeros_like(t) if psi is None else np.asarray(psi, float)
    theta_dot = np.zeros_like(t) if theta_dot is None else np.asarray(theta_dot, float)
    return Trajectory(backend=backend, t=t, theta=theta, theta_dot=theta_dot,
                      psi=psi, psi_dot=np.zeros_like(t), events=tuple(events),
                      verdict=verdict or Verdict("survived"), criterion=OverturnCriterion(),
                      t_max=None, settings=settings or {}, wall_time=0.5, scene=scene)


def test_constant_offset_gives_exact_rms_and_max():
    t = np.linspace(0.0, 2.0, 2001)
    ref = _traj(t, 0.1 * np.sin(3 * t))
    test = _traj(t, 0.1 * np.sin(3 * t) + 0.004, backend="pymunk", settings={"dt": 1e-4})
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    # Linear interpolation of a constant offset is exact: only float rounding remains.
    assert c.theta_rms_all == pytest.approx(0.004 / ALPHA, rel=1e-9)
    assert c.theta_max_all == pytest.approx(0.004 / ALPHA, rel=1e-9)
    assert c.psi_rms_all == 0.0
    assert c.test.dt == 1e-4 and c.test.backend == "pymunk"
    d = c.to_dict()
    assert d["test"]["dt"] == 1e-4 and d["test"]["wall_time"] == 0.5


def test_time_shift_matches_closed_form_rms():
    # theta_test(t) = a sin(w (t - s)): difference RMS over whole periods is
    # a * 2 sin(w s / 2) / sqrt(2).
    a, w, s = 0.1, 2 * math.pi, 0.01
    t = np.linspace(0.0, 3.0, 30001)
    ref = _traj(t, a * np.sin(w * t))
    test = _traj(t, a * np.sin(w * (t - s)))
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    expected = a * 2 * math.sin(w * s / 2) / math.sqrt(2) / ALPHA
    # 1 ms grid over 3 whole periods, both end points counted: the discrete mean
    # of cos^2 is off by ~0.5/3001 relative, i.e. ~2e-4 on the RMS.
    assert c.theta_rms_all == pytest.approx(expected, rel=5e-4)
    assert c.theta_max_all == pytest.approx(a * 2 * math.sin(w * s / 2) / ALPHA, rel=1e-3)


def test_repeated_impact_samples_and_first_impact_window():
    # Reference: a triangle wave with an impact at t=1 (two samples at t=1).
    t_ref = np.r_[np.linspace(0, 1, 101), np.linspace(1, 2, 101)]
    th_ref = np.r_[np.linspace(0, 0.1, 51), np.linspace(0.1, 0, 51)[1:], -np.linspace(0, 0.05, 101)]
    assert t_ref.size == th_ref.size
    td_ref = np.r_[np.full(51, 0.2), np.full(50, -0.2), np.full(101, -0.05)]
    ev_ref = [Event("uplift", 0.0), Event("impact", 1.0, -1, -0.2, 0.16)]
    ev_test = [Event("uplift", 0.0), Event("impact", 1.02, -1, -0.2, 0.16)]
    ref = _traj(t_ref, th_ref, events=ev_ref, theta_dot=td_ref)
    # The test differs only after the impact.
    th_test = th_ref.copy()
    th_test[101:] *= 1.2
    test = _traj(t_ref, th_test, events=ev_test, backend="pybullet", theta_dot=1.2 * td_ref)
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    assert c.theta_rms_first == pytest.approx(0.0, abs=1e-15)  # identical before the impact
    assert c.theta_max_all == pytest.approx(0.2 * 0.05 / ALPHA, rel=1e-6)
    assert c.t_first_impact == 1.0
    assert c.uplift_time_error == pytest.approx(0.0, abs=1e-12)  # same samples before the impact
    # Impacts are read from the samples by the shared rule, not from each
    # backend's own events: both runs cross theta = 0 at the samples at t = 1.
    assert c.impact_time_errors == pytest.approx((0.0,), abs=1e-12)
    assert c.n_impacts_reference == c.n_impacts_test == 1


def test_impacts_and_uplift_read_by_the_shared_rule_on_both_samplings():
    # A reference sampled every 1 ms and a test every 8 ms, 3 ms late, of the same
    # rocking theta = 0.02 sin(2 pi t); the reference also chatters after 2 s at
    # 5e-3 rad/s, below the rule's 1e-2 rad/s impact speed.
    w, lag = 2 * math.pi, 3e-3
    t_ref = np.arange(0.0, 2.5, 1e-3)
    chatter = np.where(t_ref > 2.0, 1e-4 * np.sin(50 * t_ref), 0.0)
    th_ref = np.where(t_ref <= 2.0, 0.02 * np.sin(w * t_ref), 0.0) + chatter
    td_ref = np.where(t_ref <= 2.0, 0.02 * w * np.cos(w * t_ref),
                      5e-3 * np.cos(50 * t_ref))
    t_test = np.arange(lag, 2.0, 8e-3)
    th_test = 0.02 * np.sin(w * (t_test - lag))
    td_test = 0.02 * w * np.cos(w * (t_test - lag))
    ref = _traj(t_ref, th_ref, theta_dot=td_ref)
    test = _traj(t_test, th_test, theta_dot=td_test, backend="pymunk")
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    assert c.n_impacts_reference == c.n_impacts_test == 3  # at 0.5, 1.0, 1.5 s
    # Linear interpolation near a zero of a sine is exact to ~h^2 w^2 / 6 of h.
    assert c.impact_time_errors == pytest.approx((lag,) * 3, abs=1e-5)
    # |theta| = 1e-4 rad is reached 0.8 ms after each run's start; the test starts late.
    assert c.uplift_time_error == pytest.approx(lag, abs=1e-6)
    assert 0.0 < c.uplift_time_resolution <= 8e-3 + 1e-3


def test_window_stops_at_earlier_overturn_and_verdicts():
    t = np.linspace(0.0, 2.0, 201)
    ref = _traj(t, 0.5 * t, verdict=Verdict("overturned", 2.0, "no-impact"))
    test = _traj(t[:101], 0.5 * t[:101], verdict=Verdict("overturned", 1.0, "no-impact"))
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    assert c.t_end == 1.0
    assert c.peak_theta_reference == pytest.approx(0.5)  # measured in the common window only
    assert c.verdict_agrees
    other = _traj(t, 0.5 * t, verdict=Verdict("overturned", 2.0, "after-impact"))
    assert not metrics.compare_trajectories(ref, other, alpha=ALPHA).verdict_agrees


def test_bad_inputs_raise():
    t = np.linspace(0.0, 1.0, 11)
    ref = _traj(t, 0 * t)
    with pytest.raises(ValueError, match="alpha"):
        metrics.compare_trajectories(ref, ref, alpha=-1.0)
    with pytest.raises(ValueError, match="alpha must be given"):
        metrics.compare_trajectories(ref, ref)
    with pytest.raises(ValueError, match="n_impacts"):
        restitution_from_trajectory(ref, Scene(gamma=0.0), n_impacts=0)


def test_restitution_against_housner():
    # mu = 0, gamma = 0, uniform column: Eq. 20 is Housner's 1 - 1.5 sin^2(alpha).
    scene = Scene(lam=4.0, mu=0.0, gamma=0.0)
    e_h = 1.0 - 1.5 * math.sin(scene.alpha) ** 2
    events = [Event("uplift", 0.0),
              # theta_dot keeps its sign through an impact (theta goes on through 0).
              Event("impact", 0.5, -1, -0.3, -0.3 * e_h),
              Event("impact", 0.9, +1, 0.3 * e_h, 0.3 * e_h * e_h * 1.01)]
    t = np.linspace(0.0, 1.0, 11)
    imps = restitution_from_trajectory(_traj(t, 0 * t, events=events), scene)
    assert [i.predicted for i in imps] == pytest.approx([e_h, e_h], rel=1e-12)
    assert imps[0].rel_error == pytest.approx(0.0, abs=1e-12)
    assert imps[1].rel_error == pytest.approx(0.01, rel=1e-9)
    assert imps[1].to_dict()["rel_error"] == pytest.approx(0.01, rel=1e-9)


def test_restitution_with_pendulum_uses_measured_psi():
    scene = Scene(gamma=0.3)
    b, h, mu, gamma, j, _, _ = scene.model_args()
    psi = 0.3
    t = np.linspace(0.0, 1.0, 11)
    ev = Event("impact", 0.5, +1, 0.2, 0.15, psi=psi)
    imps = restitution_from_trajectory(_traj(t, 0 * t, events=[ev]), scene)
    # Eq. 19 (corrected) typed independently here from the paper's form with the factor 2:
    c = b * math.cos(psi) + h * math.sin(psi)
    num = -4 * j + gamma * (b * b + h * h) * math.cos(2 * psi) + (b * b - h * h) * (1 + 2 * mu + gamma)
    den = 4 * j + 2 * gamma * c * c + (b * b + h * h) * (1 + 2 * mu)
    assert imps[0].predicted == pytest.approx(-num / den, rel=1e-12)
    assert imps[0].predicted != pytest.approx(
        restitution_from_trajectory(_traj(t, 0 * t, events=[
            Event("impact", 0.5, +1, 0.2, 0.15, psi=0.0)]), scene)[0].predicted)


# ------------------------------------------------------------- thresholds
@pytest.fixture
def fake_engine(monkeypatch):
    """A fake backend: overturns iff A >= threshold(backend, omega)."""
    table = {}
    calls = []

    def fake(backend, scene, omega, amplitude, settings=None, kind="sine"):
        calls.append((backend, omega, amplitude))
        over = amplitude >= table[backend](omega)
        return thr.Probe(amplitude, "overturned" if over else "survived",
                         "no-impact" if over else None)

    monkeypatch.setattr(thr, "overturns", fake)
    return table, calls


def test_threshold_bisection_inside_bracket(fake_engine):
    table, calls = fake_engine
    table["pymunk"] = lambda w: 10.1
    p = thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None, rel_tol=2e-3)
    assert p.a_survives < 10.1 <= p.a_engine
    assert p.a_engine - p.a_survives <= 2e-3 * 10.0 + 1e-12
    assert p.rel_error == pytest.approx(0.01, abs=2e-3)
    # guard + 2 bracket widenings + bisections + 2 runs checking each end
    assert p.n_runs == len(calls) <= 1 + 6 + 6 + 4
    assert p.isolated == () and p.rel_resolution <= 2e-3
    assert p.mode_engine == "no-impact"


@pytest.mark.parametrize("true_a", [7.0, 14.0])
def test_threshold_bracket_expands(fake_engine, true_a):
    table, _ = fake_engine
    table["pymunk"] = lambda w: true_a
    p = thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None)
    assert p.bracketed
    assert p.a_survives < true_a <= p.a_engine <= true_a + 2e-3 * 10.0


def test_threshold_not_bracketed_gives_nan(fake_engine):
    table, _ = fake_engine
    table["pymunk"] = lambda w: 1e3  # never overturns within 2^5 widenings of 3 %
    p = thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None, max_expand=2)
    assert not p.bracketed and math.isnan(p.rel_error)
    with pytest.raises(ValueError, match="rel_tol"):
        thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None, rel_tol=0.5)
    with pytest.raises(ValueError, match="omega"):
        thr.engine_threshold("pymunk", Scene(), 0.0, 10.0, None)


def test_knife_edge_overturn_is_isolated_not_the_threshold(monkeypatch):
    """An overturn at exactly the guard probe (0.97 A_ref) that neither 0.97 (1 + 1e-4)
    nor a 1e-6 rad tilt reproduces (Pymunk, Omega 12, Fig. 5 without pendulum) is
    isolated; the threshold is the robust one above it."""
    calls = []

    def fake(backend, scene, omega, amplitude, settings=None, kind="sine"):
        tilted = settings is not None and settings.theta0 != 0.0
        calls.append(amplitude)
        over = amplitude >= 10.02 or (amplitude == 0.97 * 10.0 and not tilted)
        return thr.Probe(amplitude, "overturned" if over else "survived", None)

    monkeypatch.setattr(thr, "overturns", fake)
    p = thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None)
    assert p.a_survives < 10.02 <= p.a_engine <= 10.02 + 5e-3 * 10.0
    assert [i["amplitude"] for i in p.isolated] == [pytest.approx(9.7)]
    assert {n["status"] for n in p.isolated[0]["neighbours"]} == {"survived"}
    assert p.n_runs == len(calls)


def test_a_perturbation_that_flips_the_survivor_is_reported(monkeypatch):
    def fake(backend, scene, omega, amplitude, settings=None, kind="sine"):
        tilted = settings is not None and settings.theta0 != 0.0
        over = amplitude >= 10.1 or (tilted and amplitude > 10.0)
        return thr.Probe(amplitude, "overturned" if over else "survived", None)

    monkeypatch.setattr(thr, "overturns", fake)
    p = thr.engine_threshold("pymunk", Scene(), 12.0, 10.0, None)
    assert p.a_survives < 10.1 <= p.a_engine
    assert [i["perturbation"] for i in p.isolated] == ["tilt"]


def test_jump_frequency_shift(fake_engine):
    table, _ = fake_engine
    # Threshold 8 below the jump, 20 above; jumps at 10.0 (model) and 10.3 (engine).
    table["analytic-fast"] = lambda w: 8.0 if w < 10.0 else 20.0
    table["pymunk"] = lambda w: 8.0 if w < 10.3 else 20.0
    j = jump_shift.engine_jump_frequency("pymunk", Scene(), 14.0, 9.5, 10.2, None, omega_tol=0.01)
    assert j.omega_reference == pytest.approx(10.0, abs=0.01)
    assert j.omega_engine == pytest.approx(10.3, abs=0.01)  # found after one widening
    assert j.shift == pytest.approx(0.3, abs=0.02)
    assert j.to_dict()["shift"] == pytest.approx(j.shift)


def test_first_window_ends_where_a_run_passes_alpha():
    # No impact; the test run falls faster once past alpha: that part must not
    # count in the "before first impact" error.
    t = np.linspace(0.0, 2.0, 2001)
    ref_theta = np.where(t < 1.0, 0.1 * t, 0.1 + 0.5 * (t - 1.0))
    test_theta = np.where(t < 1.0, 0.1 * t, 0.1 + 0.9 * (t - 1.0))
    ref = _traj(t, ref_theta, events=[Event("uplift", 0.0)])
    test = _traj(t, test_theta, events=[Event("uplift", 0.0)])
    c = metrics.compare_trajectories(ref, test, alpha=0.15)
    # test reaches alpha = 0.15 at t = 1 + 0.05/0.9; the reference later.
    assert c.t_first_impact == pytest.approx(1.0 + 0.05 / 0.9, abs=1e-3)  # 1 ms samples
    assert c.theta_max_first <= 0.4 * 0.06 / 0.15 + 1e-9  # only the start of the divergence
    assert c.theta_max_all > c.theta_max_first


def test_uplift_timed_at_the_same_angle_in_both_runs():
    # theta = k (t - t0)^2 after t0: reaches 1e-4 rad at t0 + sqrt(1e-4 / k).
    t = np.linspace(0.0, 1.0, 1001)
    k = 1.0
    ref = _traj(t, np.where(t > 0.2, k * (t - 0.2) ** 2, 0.0), events=[Event("uplift", 0.2)])
    # The test run's event is declared late (at the threshold), as the engines do.
    test = _traj(t, np.where(t > 0.25, k * (t - 0.25) ** 2, 0.0), events=[Event("uplift", 0.26)])
    c = metrics.compare_trajectories(ref, test, alpha=ALPHA)
    # Linear interpolation of a parabola between 1 ms samples: error << 1 ms.
    assert c.uplift_time_error == pytest.approx(0.05, abs=5e-4)


def test_tongue_tip_is_where_the_spectrum_mode_changes():
    """The jump located by compare.measure.reference_spectra sits where analytic.spectrum's first
    overturning mode switches (an independent scan + bisection)."""
    from trilith_xval.compare.campaign.validation import CampaignConfig
    from trilith_xval.compare.measure.reference_spectra import first_overturning_amplitude, reference_spectrum
    from trilith_xval.scenes import load_scene

    scene = load_scene("no_pendulum")
    cfg = CampaignConfig(omega_range=(17.0, 18.5), spectrum_step=0.5)
    jump = reference_spectrum(scene, cfg)["jump"]
    tip = jump["omega_tip"]
    # The tip is bisected to d_omega = 0.02 rad/s; 0.05 on either side is clear of it.
    assert first_overturning_amplitude(scene, tip - 0.05)[1] == "after-impact"
    assert first_overturning_amplitude(scene, tip + 0.05)[1] == "no-impact"
    # The probe lies between the two threshold levels of the jump.
    assert jump["a_lo"] < jump["probe_amplitude"] < jump["a_hi"]
