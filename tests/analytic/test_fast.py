"""The compiled fast path (``analytic/fast.py``) against the accurate path
(``analytic/simulate.py``, DOP853 at rtol 1e-10): same verdicts, same events,
same theta(t); plus its own contract, validation and exact-survival rules."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.special import ellipk

from trilith_xval.analytic import _fast_kernels as kern
from trilith_xval.analytic import fast
from trilith_xval.analytic import simulate as accurate
from trilith_xval.analytic.events import free_pendulum_period
from trilith_xval.analytic.excitation import Pulse, SampledRecord
from trilith_xval.analytic.trajectory import OverturnCriterion
from trilith_xval.engines import get_backend

# The paper's labelled points of Fig. 5 (A_s [m/s^2], Omega [rad/s]) and a few more
# cases: overturning with and without impact, survival with impacts, low frequency.
PAPER_POINTS = {"A": (19.0, 15.0), "B": (4.0, 9.0), "C": (10.0, 9.0), "D": (25.0, 11.0)}
EXTRA = [(3.0, 5.0), (8.0, 12.0), (14.0, 20.0)]
CASES = [(a, w, kind) for kind in ("sine", "cosine")
         for a, w in list(PAPER_POINTS.values()) + EXTRA]

# theta agreement [rad].  Both integrators keep the local error at their rtol
# (1e-8 fast, 1e-10 accurate) and locate events on their dense output; measured
# differences are <= 2e-7 rad over these runs (most ~1e-9).  Before the first
# impact nothing amplifies the difference, so 1e-6 rad; over a run the impact map
# passes on the event-time error (~1e-7 s) times theta_dot, hence 1e-5 rad.
THETA_TOL_BEFORE_IMPACT = 1e-6
THETA_TOL_RUN = 1e-5
# Event times [s]: measured <= 1e-7 s (root location on two different interpolants).
EVENT_T_TOL = 1e-6


@pytest.fixture(scope="module", autouse=True)
def _compiled():
    fast.warm_up()  # compile or load once; no test below pays for it


def _theta_on(tr, grid):
    t, first = np.unique(tr.t, return_index=True)  # impact instants appear twice
    return np.interp(grid, t, tr.theta[first])


@pytest.mark.parametrize("with_pendulum", [True, False], ids=["pendulum", "bare"])
@pytest.mark.parametrize("amp,omega,kind", CASES)
def test_fast_matches_accurate(fig5, run_analytic, amp, omega, kind, with_pendulum):
    scene = fig5 if with_pendulum else fig5.without_pendulum()
    ref = run_analytic(scene, amp, omega, kind)
    tr = fast.simulate(scene, Pulse(amp, omega, kind))
    assert (tr.verdict.status, tr.verdict.mode, tr.n_impacts) == (
        ref.verdict.status, ref.verdict.mode, ref.n_impacts)
    assert [e.kind for e in tr.events] == [e.kind for e in ref.events]
    for e, r in zip(tr.events, ref.events):
        assert e.t == pytest.approx(r.t, abs=EVENT_T_TOL)
        assert e.side == r.side
    if tr.overturned:
        assert tr.verdict.time == pytest.approx(ref.verdict.time, abs=EVENT_T_TOL)
    t_end = min(tr.t[-1], ref.t[-1])
    grid = np.arange(0.0, t_end, 1e-3)
    # Linear interpolation across an event kink is not a model difference: skip
    # the samples within 2 ms of an event.
    away = np.ones(grid.size, dtype=bool)
    for e in ref.events:
        away &= np.abs(grid - e.t) > 2e-3
    diff = np.abs(_theta_on(tr, grid) - _theta_on(ref, grid))[away]
    first_impact = ref.impacts[0].t if ref.impacts else t_end
    before = grid[away] < first_impact
    assert np.max(diff[before], initial=0.0) < THETA_TOL_BEFORE_IMPACT
    assert np.max(diff, initial=0.0) < THETA_TOL_RUN


def test_paper_points_qualitative(fig5):
    """Section 5.2: the pendulum saves case A; C overturns after an impact, D
    without one (Fig. 7)."""
    a, w = PAPER_POINTS["A"]
    assert fast.simulate(fig5, Pulse(a, w)).verdict.status == "survived"
    assert fast.simulate(fig5.without_pendulum(), Pulse(a, w)).overturned
    c = fast.simulate(fig5, Pulse(*PAPER_POINTS["C"])).verdict
    d = fast.simulate(fig5, Pulse(*PAPER_POINTS["D"])).verdict
    assert (c.status, c.mode) == ("overturned", "after-impact")
    assert (d.status, d.mode) == ("overturned", "no-impact")


@pytest.mark.parametrize("amp,omega", [(8.06, 10.0), (7.05, 11.0), (17.43, 11.0)])
def test_near_threshold_verdicts(fig5, run_analytic, amp, omega):
    """Just below spectrum thresholds (many impacts, the pendulum handing energy
    back): only the verdict is compared, the trajectories are chaotic there."""
    for scene in (fig5, fig5.without_pendulum()):
        ref = run_analytic(scene, amp, omega)
        v = fast.verdict_for(scene, Pulse(amp, omega))
        assert (v.status, v.mode) == (ref.verdict.status, ref.verdict.mode)


def test_verdict_entry_points_agree(fig5):
    pulse = Pulse(10.0, 9.0)
    tr = fast.simulate(fig5, pulse)
    v = fast.verdict_for(fig5, pulse)
    st, _reason, t, n = fast.overturn_verdict(*fig5.model_args(), 10.0, 9.0, 0,
                                              OverturnCriterion().threshold(fig5.alpha))
    assert (v.status, v.time, v.n_impacts) == (tr.verdict.status, tr.verdict.time, tr.n_impacts)
    assert fast.STATUS_NAMES[st] == v.status and t == v.time and n == v.n_impacts


def test_alpha_criterion_and_modes(fig5, run_analytic):
    st = fast.Settings(criterion=OverturnCriterion("alpha"))
    for amp, omega in [(10.0, 9.0), (25.0, 11.0), (4.0, 9.0)]:
        ref = run_analytic(fig5, amp, omega, criterion="alpha")
        tr = fast.simulate(fig5, Pulse(amp, omega), st)
        assert (tr.verdict.status, tr.verdict.mode) == (ref.verdict.status, ref.verdict.mode)
        if tr.overturned:
            assert tr.max_abs_theta == pytest.approx(fig5.alpha, abs=1e-9)


def test_fixed_window(fig5, run_analytic):
    """With t_max the run goes on to t_max and a survivor is 'survived'."""
    tr = fast.simulate(fig5, Pulse(4.0, 9.0), fast.Settings(t_max=3.0))
    ref = run_analytic(fig5, 4.0, 9.0, t_max=3.0)
    assert tr.verdict.status == ref.verdict.status == "survived"
    assert tr.t[-1] == pytest.approx(3.0, abs=1e-12)
    assert tr.n_impacts == ref.n_impacts
    # The verdict-only kernel may stop early on an exact rule; same verdict.
    for amp, omega, t_max in [(4.0, 9.0, 3.0), (10.0, 9.0, 3.0), (10.0, 9.0, 10.0)]:
        ref = run_analytic(fig5, amp, omega, t_max=t_max).verdict
        v = fast.verdict_for(fig5, Pulse(amp, omega), fast.Settings(t_max=t_max))
        assert (v.status, v.mode) == (ref.status, ref.mode)


def test_samples_and_events(fig5):
    tr = fast.simulate(fig5, Pulse(5.0, 9.0), fast.Settings(t_max=3.0))
    assert tr.t[0] == 0.0 and np.all(np.diff(tr.t) >= 0.0)
    imp = tr.impacts[0]
    at = np.flatnonzero(tr.t == imp.t)
    assert len(at) == 2  # before and after, like the accurate path
    assert tr.theta_dot[at[0]] == imp.theta_dot_before
    assert tr.theta_dot[at[1]] == imp.theta_dot_after
    assert tr.events[0].kind == "uplift" and tr.events[0].side == 1


def test_mirror_symmetry(fig5):
    """A negative amplitude mirrors the response (theta -> -theta, psi -> -psi)."""
    a = fast.simulate(fig5, Pulse(6.0, 10.0), fast.Settings(t_max=2.0))
    b = fast.simulate(fig5, Pulse(-6.0, 10.0), fast.Settings(t_max=2.0))
    n = min(len(a.t), len(b.t))
    # Same arithmetic up to the sign of b: round-off only.
    np.testing.assert_allclose(b.theta[:n], -a.theta[:n], atol=1e-9)
    np.testing.assert_allclose(b.psi[:n], -a.psi[:n], atol=1e-9)


def test_deterministic(fig5):
    a = fast.simulate(fig5, Pulse(10.0, 9.0))
    b = fast.simulate(fig5, Pulse(10.0, 9.0))
    assert np.array_equal(a.theta, b.theta) and a.verdict == b.verdict


def test_no_pendulum_keeps_psi_zero(fig5):
    tr = fast.simulate(fig5.without_pendulum(), Pulse(10.0, 9.0))
    assert not np.any(tr.psi) and not np.any(tr.psi_dot)


def test_pendulum_period_kernel_matches_scipy():
    """The AGM elliptic integral in the kernel against scipy's ellipk, for
    libration and rotation."""
    l, g = 2.0, 9.81
    for psi, psi_dot in [(0.0, 0.0), (0.3, 0.0), (2.5, 0.1), (0.0, 5.0), (1.0, -6.0)]:
        assert kern._pendulum_period(psi, psi_dot, l, g) == pytest.approx(
            free_pendulum_period(psi, psi_dot, l, g), rel=1e-12)
    assert kern._ellipk(0.7) == pytest.approx(float(ellipk(0.7)), rel=1e-14)


def test_rest_after_pulse_rules(fig5):
    """Below uplift nothing moves: without a pendulum the run is decided at the
    pulse end; with one after a free-pendulum period (or the energy barrier)."""
    bare = fast.verdict_for(fig5.without_pendulum(), Pulse(1.0, 10.0))
    assert bare.status == "survived" and "energy" in bare.reason
    tr = fast.simulate(fig5, Pulse(1.0, 10.0))
    assert tr.verdict.status == "survived" and not tr.events


def test_sampled_record_is_compiled(fig5):
    rec = SampledRecord((0.0, 0.2, 0.4), (0.0, 4.0, 0.0))
    tr = fast.simulate(fig5, rec, fast.Settings(t_max=1.0))
    assert tr.backend == fast.NAME
    assert "fast_path_fallback" not in tr.diagnostics


def test_contract_and_validation(fig5):
    backend = get_backend("analytic-fast")
    assert backend.name == fast.NAME == "analytic-fast" and backend.Settings is fast.Settings
    assert "numba" in fast.version() and backend.version() == fast.version()
    assert dataclasses.is_dataclass(fast.Settings) and fast.Settings.__dataclass_params__.frozen
    for bad in ({"t_max": -1.0}, {"t_max": math.inf}, {"rtol": 0.0}, {"atol": -1.0},
                {"rest_velocity": math.nan}, {"sample_dt": 0.0}, {"max_steps": 5},
                {"criterion": "topple"}):
        name = next(iter(bad))
        with pytest.raises((ValueError, TypeError), match=name):  # TypeError: wrong type
            fast.Settings(**bad)
    with pytest.raises(ValueError, match="scene"):
        fast.simulate("fig5", Pulse(1.0, 1.0))
    with pytest.raises(TypeError, match="excitation must be an analytic.excitation.Excitation"):
        fast.simulate(fig5, 3.0)
    with pytest.raises(ValueError, match="settings"):
        fast.simulate(fig5, Pulse(1.0, 1.0), accurate.Settings())


def test_stale_numba_cache_is_dropped(tmp_path):
    """numba does not notice an edit of equations.py inside a cached kernel: the
    fast path drops its cache when the source digest changes."""
    from trilith_xval.analytic import _numba_cache
    kept = tmp_path / "other.func-1.py311.nbi"
    stale = [tmp_path / "_fast_kernels.run-9.py311.nbi", tmp_path / "equations.energy-3.py311.1.nbc"]
    for p in stale + [kept]:
        p.write_text("x")
    (tmp_path / "_fast_sources.sha256").write_text("not the digest\n")
    assert _numba_cache.invalidate_if_stale(tmp_path)
    assert not any(p.exists() for p in stale) and kept.exists()
    assert not _numba_cache.invalidate_if_stale(tmp_path)  # stamp now current


def test_cosine_pulse_exactly_at_uplift_is_decided():
    """A one-cosine pulse with A exactly g/lam starts with a zero uplift margin: the
    frame may lift by round-off and fall back within nanoseconds.  That must end at
    rest and be decided, not loop uplift/rest at t = 0 until the step budget runs
    out (which the spectrum scan start used to hit: 21 'undecided' runs per
    one-cosine spectrum)."""
    from trilith_xval.analytic import Pulse
    from trilith_xval.analytic.fast import simulate as fast_simulate, verdict_for
    from trilith_xval.scenes import load_scene

    scene = load_scene("fig9_lam5_b0.4").without_pendulum()
    for omega in (3.5, 7.0, 8.0):
        pulse = Pulse(scene.g / scene.lam, omega, "cosine")
        assert verdict_for(scene, pulse).status == "survived"
        assert fast_simulate(scene, pulse).verdict.status == "survived"


def test_certain_overturn_exit_keeps_verdicts(fig5, run_analytic):
    """The verdict-only path ends a certain overturn early (past alpha below the
    energy barrier after the pulse, or without pendulum past alpha moving out):
    same status and mode as the accurate path, which integrates the whole fall,
    at A-D and at a seeded random sample around the spectrum's thresholds; the
    reported time is when the overturn became certain, no later than the fall."""
    rng = np.random.default_rng(16)
    cases = list(PAPER_POINTS.values()) + [
        (float(a), float(w)) for a, w in zip(rng.uniform(2.0, 40.0, 10), rng.uniform(3.0, 20.0, 10))]
    n_certain = 0
    for scene in (fig5, fig5.without_pendulum()):
        for amp, omega in cases:
            v = fast.verdict_for(scene, Pulse(amp, omega))
            ref = run_analytic(scene, amp, omega).verdict
            assert (v.status, v.mode) == (ref.status, ref.mode), (scene.gamma, amp, omega)
            if v.reason == fast.REASONS[kern.R_CERTAIN]:
                n_certain += 1
                assert v.time < ref.time
    assert n_certain >= 5  # the exit is exercised (point D among them)
    d = fast.verdict_for(fig5, Pulse(*PAPER_POINTS["D"]))
    assert d.reason == fast.REASONS[kern.R_CERTAIN] and d.time == pytest.approx(
        Pulse(*PAPER_POINTS["D"]).end_time)


def test_energy_out_of_the_pulse_without_pendulum(fig5, run_analytic):
    """Without the pendulum the verdict kernel stops at the pulse end when the frame
    rocks inward (back over alpha if past it): the energy is conserved down to the
    impact at theta = 0, which keeps r^2 of it (Eq. 20).  The energy it reports carried out of
    the pulse, max(potential at the pulse end, r^2 E), must be at least the recorded
    run's energy just after that impact, and equal it where that term dominates;
    the verdict must be the accurate path's."""
    from trilith_xval.analytic.equations import energy
    scene = fig5.without_pendulum()
    b, h, mu, gamma, j, l, g = scene.model_args()
    rng = np.random.default_rng(20)
    n_inward = n_after = n_past = 0
    for amp, omega in zip(rng.uniform(3.0, 80.0, 50), rng.uniform(5.0, 30.0, 50)):
        pulse = Pulse(float(amp), float(omega))
        # The state at the pulse end, from a run stopped there (last sample <= 1 ms
        # before it: theta_dot moves by < 1e-3 rad/s in that time, hence the 0.02).
        upto = fast.simulate(scene, pulse, fast.Settings(t_max=pulse.end_time))
        if upto.verdict.overturned:
            continue  # fell during the pulse
        assert pulse.end_time - upto.t[-1] <= 1e-3
        th, td = upto.theta[-1], upto.theta_dot[-1]
        if not (th * td < 0.0 and abs(td) > 0.02):
            continue  # at rest or moving out at the pulse end
        # A recorded fixed window integrates on through the impact.
        tr = fast.simulate(scene, pulse, fast.Settings(t_max=pulse.end_time + 5.0))
        first = next((e for e in tr.events if e.kind == "impact" and e.t > pulse.end_time),
                     None)
        if first is None:  # past alpha below the barrier: cannot come back
            assert tr.verdict.overturned and abs(th) > scene.alpha
            continue
        n_inward += 1
        n_past += abs(th) > scene.alpha
        e_after = energy(0.0, first.theta_dot_after, 0.0, 0.0, first.side, b, h, mu, gamma,
                         j, l, g)
        args = fast.kernel_args(scene, float(omega), "sine", fast.Settings())
        _st, _rs, tv, _ni, e_out = kern.verdicts(np.array([float(amp)]), *args)
        # Both sides carry the DP5 local error (rtol 1e-8) over one free swing.
        assert e_out[0] >= e_after * (1 - 1e-6), (amp, omega)
        n_after += e_out[0] == pytest.approx(e_after, rel=1e-6)
        assert tv[0] == pytest.approx(pulse.end_time)
        ref = run_analytic(scene, float(amp), float(omega)).verdict
        verdict = fast.verdict_for(scene, pulse)
        assert (verdict.status, verdict.mode) == (ref.status, ref.mode), (amp, omega)
    assert n_inward >= 8  # not vacuous: the pulse-end rule decided these runs
    assert n_after >= 4  # and r^2 E, the closed form, was the larger term
    assert n_past >= 2  # and some came back over alpha
