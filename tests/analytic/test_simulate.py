"""The accurate event-driven simulator (``analytic/simulate.py``): contract, phase
semantics, exact survival rules, symmetry, invariance and determinism."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import Pulse, SampledRecord
from trilith_xval.analytic.simulate import NAME, Settings, simulate, version
from trilith_xval.analytic.trajectory import OverturnCriterion
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.engines import get_backend

FREE = Pulse(0.0, 1e4)  # zero-amplitude pulse over 0.6 ms: free motion from the initial state


# --- contract ----------------------------------------------------------------------------
def test_backend_contract():
    backend = get_backend("analytic")
    assert backend.name == NAME == "analytic" and backend.Settings is Settings
    assert version().startswith("analytic-")
    assert dataclasses.is_dataclass(Settings) and Settings.__dataclass_params__.frozen
    assert {"criterion", "t_max"} <= {f.name for f in dataclasses.fields(Settings)}


def test_trajectory_is_self_describing(fig5):
    st = Settings(criterion=OverturnCriterion("alpha"), t_max=2.0)
    tr = simulate(fig5, Pulse(6.0, 10.0), st)
    assert tr.backend == "analytic"
    assert tr.settings["criterion"] == {"kind": "alpha", "topple_angle": 1.5}
    assert tr.settings["t_max"] == 2.0 and tr.t_max == 2.0 and tr.criterion == st.criterion
    assert {"n_steps", "n_rhs_evals", "n_segments"} <= set(tr.diagnostics)
    assert tr.diagnostics["n_steps"] > 0 and tr.wall_time > 0.0
    json.dumps(plain(tr.summary()), allow_nan=False)  # strict JSON


def test_samples_grid_and_event_instants(fig5):
    tr = simulate(fig5, Pulse(5.0, 9.0), Settings(t_max=3.0, sample_dt=1e-3))
    assert np.all(np.diff(tr.t) >= 0.0)
    assert tr.t[0] == 0.0 and tr.t[-1] == pytest.approx(3.0, abs=1e-12)
    on_grid = np.abs(tr.t / 1e-3 - np.round(tr.t / 1e-3)) < 1e-6
    for e in tr.events:
        assert np.any(tr.t == e.t)  # every event instant is a sample
    # Off-grid samples are exactly the event instants and the pulse end.
    special = {e.t for e in tr.events} | {2 * math.pi / 9.0}
    assert all(t in special for t in tr.t[~on_grid])
    # An impact gives two samples at its instant: before and after.
    imp = tr.impacts[0]
    at = np.flatnonzero(tr.t == imp.t)
    assert len(at) == 2
    assert tr.theta_dot[at[0]] == imp.theta_dot_before
    assert tr.theta_dot[at[1]] == imp.theta_dot_after
    assert np.all(tr.theta[at] == 0.0)


def test_sample_dt_none_keeps_integrator_steps(fig5):
    tr = simulate(fig5, Pulse(5.0, 9.0), Settings(t_max=3.0, sample_dt=None))
    # Samples are the start, the integrator's steps, breakpoints and event instants:
    # fewer than the steps + events + a few (each counted once).
    assert 10 < len(tr.t) <= tr.diagnostics["n_steps"] + 2 * len(tr.events) + 4


def test_without_pendulum_psi_stays_zero(fig5_bare):
    tr = simulate(fig5_bare, Pulse(10.0, 9.0))
    assert np.all(tr.psi == 0.0) and np.all(tr.psi_dot == 0.0)


# --- phases and verdicts -------------------------------------------------------------------
def test_no_uplift_below_threshold(fig5):
    tr = simulate(fig5, Pulse(2.0, 9.0))  # < a_up (2.26 m/s^2, hanging pendulum)
    assert tr.events == () and tr.verdict.status == "survived"
    assert np.all(tr.theta == 0.0) and np.any(tr.psi != 0.0)  # the bob still swings


def test_overturn_sample_and_event(fig5):
    tr = simulate(fig5, Pulse(25.0, 11.0))
    assert tr.events[-1].kind == "overturn"
    assert abs(tr.theta[-1]) == pytest.approx(1.5, abs=1e-12)
    assert tr.verdict.time == tr.events[-1].t == tr.t[-1]


def test_alpha_criterion_decides_earlier(fig5):
    topple = simulate(fig5, Pulse(25.0, 11.0))
    alpha = simulate(fig5, Pulse(25.0, 11.0), Settings(criterion=OverturnCriterion("alpha")))
    assert alpha.verdict.time < topple.verdict.time
    assert abs(alpha.theta[-1]) == pytest.approx(fig5.alpha, abs=1e-12)


def test_impacts_head_into_the_new_side_and_zeno_ends_in_rest(fig5_bare):
    tr = simulate(fig5_bare, FREE, Settings(theta0=0.5 * fig5_bare.alpha, t_max=20.0))
    kinds = [e.kind for e in tr.events]
    assert kinds[-1] == "rest" and kinds.count("rest") == 1
    times = [e.t for e in tr.impacts]
    assert np.all(np.diff(times) > 0.0)  # no impact fires at the start of a rock phase
    for e in tr.impacts:
        assert e.theta_dot_before * e.side > 0.0  # heading towards the new pivots
        assert abs(e.theta_dot_after) < abs(e.theta_dot_before)
    assert abs(tr.impacts[-1].theta_dot_after) < Settings().rest_velocity
    after = tr.t > tr.events[-1].t
    assert np.all(tr.theta[after] == 0.0)


def test_fixed_window_runs_to_t_max(fig5):
    tr = simulate(fig5, Pulse(5.0, 9.0), Settings(t_max=4.0))
    assert tr.verdict.status == "survived" and tr.t[-1] == pytest.approx(4.0, abs=1e-12)
    assert tr.verdict.reason.endswith("ran to t_max")  # an exact rule had also decided
    short = simulate(fig5, Pulse(5.0, 9.0), Settings(t_max=0.2))  # ends inside the pulse
    assert short.verdict.status == "survived" and "fixed window" in short.verdict.reason


def test_barrier_rule_stops_at_the_pulse_end(fig5):
    pulse = Pulse(4.0, 9.0)
    tr = simulate(fig5, pulse)
    assert tr.verdict.reason == "energy below the overturning barrier after the pulse"
    end = tr.t[-1]
    assert end >= pulse.period
    # ... and the same run continued for 10 s never gets near alpha again.
    long = simulate(fig5, pulse, Settings(t_max=pulse.period + 10.0))
    later = long.t > end
    assert np.max(np.abs(long.theta[later])) < fig5.alpha


def test_rest_period_rule_and_its_long_run_check(fig5):
    # Pendulum released at 1 rad on a trilith at rest: energy above the barrier
    # (rule 1 cannot decide), no uplift in one free period -> survived (rule 3).
    b, h, mu, gamma, j, l, g = fig5.model_args()
    assert eq.rest_energy(1.0, 0.0, gamma, l, g) > eq.overturn_energy_barrier(b, h, mu, gamma, g)
    tr = simulate(fig5, FREE, Settings(psi0=1.0))
    assert "one free-pendulum period" in tr.verdict.reason
    assert tr.events == ()
    # The period used matches the elliptic-integral period: the run ends one
    # period after the pulse, within the bisection-free event timing (exact).
    from trilith_xval.analytic.events import free_pendulum_period
    assert tr.t[-1] == pytest.approx(FREE.period + free_pendulum_period(1.0, 0.0, l, g), abs=1e-12)
    # Independent check of the rule's claim over ten periods.
    long = simulate(fig5, FREE, Settings(psi0=1.0, t_max=35.0))
    assert long.events == () and np.all(long.theta == 0.0)


def test_free_pendulum_period_against_direct_integration():
    from scipy.integrate import solve_ivp
    from trilith_xval.analytic.events import free_pendulum_period
    l, g = 2.0, 9.81
    for psi0, pd0 in [(0.3, 0.0), (2.5, 0.0), (0.0, 5.0)]:  # libration, large, rotation
        period = free_pendulum_period(psi0, pd0, l, g)
        sol = solve_ivp(lambda t, y: (y[1], -g / l * math.sin(y[0])), (0.0, period),
                        [psi0, pd0], rtol=1e-12, atol=1e-12)
        psi1, pd1 = sol.y[:, -1]
        wrap = 2 * math.pi * round((psi1 - psi0) / (2 * math.pi))  # one turn for rotation
        assert psi1 - wrap == pytest.approx(psi0, abs=1e-8)  # rtol 1e-12 over one period
        assert pd1 == pytest.approx(pd0, abs=1e-8)
    assert free_pendulum_period(0.0, 0.0, l, g) == pytest.approx(2 * math.pi * math.sqrt(l / g))


def test_cap_gives_undecided(fig5_bare):
    # Thrown inwards with energy above the barrier, cap shorter than the first swing.
    st = Settings(theta0=0.5 * fig5_bare.alpha, theta_dot0=-1.0, t_cap=1e-3)
    tr = simulate(fig5_bare, FREE, st)
    assert tr.verdict.status == "undecided"
    assert tr.t[-1] == pytest.approx(FREE.period + 1e-3, abs=1e-12)


def test_sampled_record_matches_the_pulse(fig5):
    pulse = Pulse(6.0, 9.0)
    times = np.linspace(0.0, pulse.period, 4001)
    record = SampledRecord(tuple(times), tuple(pulse.acceleration_array(times)))
    a = simulate(fig5, pulse, Settings(t_max=2.0))
    b = simulate(fig5, record, Settings(t_max=2.0))
    # Linear interpolation at 0.17 ms spacing: xg error <= A (W dt)^2 / 8 ~ 1.7e-6 m/s^2,
    # so the uplift time moves by ~1e-6 s and the response by ~1e-6 relative.
    assert b.uplift_time == pytest.approx(a.uplift_time, abs=1e-5)
    assert b.n_impacts == a.n_impacts
    ta, tb = a.impacts[0].t, b.impacts[0].t
    assert tb == pytest.approx(ta, abs=1e-4)


# --- symmetry, invariance, determinism ---------------------------------------------------------
@pytest.mark.parametrize("amplitude,omega,kind,pendulum", [
    (19.0, 15.0, "sine", True), (10.0, 9.0, "sine", True), (8.0, 6.0, "cosine", True),
    (10.0, 9.0, "sine", False)])
def test_mirrored_pulse_mirrors_the_response(fig5, amplitude, omega, kind, pendulum):
    scene = fig5 if pendulum else fig5.without_pendulum()
    st = Settings(t_max=6.0)
    a = simulate(scene, Pulse(amplitude, omega, kind), st)
    b = simulate(scene, Pulse(-amplitude, omega, kind), st)
    assert a.verdict.status == b.verdict.status and a.n_impacts == b.n_impacts
    assert np.allclose(a.t, b.t, rtol=0, atol=1e-12)
    # Eq. 8 and A.1 are mirror images (b -> -b): only round-off differs.
    assert np.max(np.abs(a.theta + b.theta)) < 1e-9
    assert np.max(np.abs(a.psi + b.psi)) < 1e-9
    assert [e.side for e in a.events] == [-e.side for e in b.events]


@pytest.mark.parametrize("change", [{"hinge_x": 1.5}, {"gap": 1.0}, {"lintel_height": 0.9},
                                    {"column_mass": 123.0}])
def test_engine_only_parameters_do_not_change_theta(fig5, change):
    pulse, st = Pulse(10.0, 9.0), Settings(t_max=5.0)
    ref = simulate(fig5, pulse, st)
    other = simulate(fig5.replace(**change), pulse, st)
    # The paper (Sec. 3) shows these drop out of Eq. 8, 9, 19-21: identical numbers.
    assert np.array_equal(ref.theta, other.theta) and np.array_equal(ref.psi, other.psi)
    assert ref.verdict == other.verdict


def test_determinism(fig5):
    pulse, st = Pulse(12.0, 13.0), Settings(t_max=5.0)
    a, b = simulate(fig5, pulse, st), simulate(fig5, pulse, st)
    for name in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    assert a.events == b.events and a.verdict == b.verdict
    assert a.diagnostics == b.diagnostics


# --- CLI --------------------------------------------------------------------------------------
def test_cli_json_csv_plot(tmp_path, capsys):
    from trilith_xval.compare.cli.main import main
    csv, png = tmp_path / "run.csv", tmp_path / "run.png"
    code = main(["simulate", "-A", "19", "-w", "15", "--no-pendulum", "--criterion", "alpha",
                 "--json", "--csv", str(csv), "--plot", str(png)])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "overturned" and out["criterion"] == "alpha"
    assert out["settings"]["criterion"]["kind"] == "alpha"
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert data.shape[1] == 5 and data[-1, 0] == pytest.approx(out["t_end"])
    assert png.stat().st_size > 1000 and png.read_bytes()[:4] == b"\x89PNG"


def test_cli_human_summary_and_t_max(capsys):
    from trilith_xval.compare.cli.main import main
    assert main(["simulate", "-A", "4", "-w", "9", "--t-max", "3", "--pulse", "cosine"]) == 0
    out = capsys.readouterr().out
    assert "verdict: survived" in out and "cosine pulse" in out and "t_end = 3.000 s" in out
