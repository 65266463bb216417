"""The backend contract, checked alike for every registered backend (brax-style
cross-backend tests).  Engine-specific behaviour stays in test_<engine>_engine.py.

Expected values come from closed forms where they exist: Eq. 20 is checked
against the Makris-Vassiliou rocking-frame restitution (an independent
derivation in test_closed_forms), Eq. 19 against the corrected
``restitution_ratio`` at the measured psi (no closed form with a pendulum).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import engines
from analytic.excitation import Pulse
from analytic.options import RunOptions
from compare.measure.restitution import measure_restitution
from engines.base import CAPABILITIES, Backend, EngineSettings
from scenes import PAPER_OUTCOMES, load_scene, point_pulse
from test_closed_forms import makris_vassiliou

ALL = engines.backend_names()
ENGINES = engines.ENGINES

# Acceptance bound of the engine contract (issue 13): Eq. 20 and Eq. 19 within 0.5 %.
# Measured at the defaults, first four impacts from alpha/2 (2026-11-23, one run):
# Eq. 20 worst Pymunk 0.24 %, PyBullet 0.23 % over lam {3,5,7} x mu {0.5,1,2}.
RESTITUTION_TOL = 5e-3


# ------------------------------------------------------------------ the contract
@pytest.mark.parametrize("name", ALL)
def test_backend_satisfies_the_protocol(name):
    module = engines.get_backend(name)
    assert isinstance(module, Backend)
    assert module.NAME == name
    assert issubclass(module.Settings, RunOptions)
    assert set(module.CAPABILITIES) <= set(CAPABILITIES)
    assert "trajectory" in module.CAPABILITIES
    assert isinstance(module.version(), str) and module.version()
    if name in ENGINES:
        assert issubclass(module.Settings, EngineSettings)
        assert {"time_step", "initial_tilt"} <= module.CAPABILITIES
    if "render" in module.CAPABILITIES:
        assert callable(module.render_frames)
    if "gui" in module.CAPABILITIES:
        assert callable(module.view)


@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize("option, value, exc", [
    ("t_max", -1.0, ValueError), ("t_max", math.nan, ValueError), ("t_max", "2", TypeError),
    ("theta0", 2.0, ValueError), ("psi0", 4.0, ValueError), ("early_stop", 1, TypeError),
    ("criterion", "sideways", ValueError)])
def test_bad_run_options_refused_at_construction(name, option, value, exc):
    with pytest.raises(exc, match=option if option != "criterion" else "criterion"):
        engines.configure(name, **{option: value})


@pytest.mark.parametrize("name", ENGINES)
@pytest.mark.parametrize("option, value", [("dt", 0.0), ("dt", 0.5), ("sample_every", 0),
                                           ("base_motion", "shake"), ("friction", -1.0),
                                           ("monitor", {"t_cap": -1.0}),
                                           ("monitor", {"rest_hold": math.nan})])
def test_bad_engine_settings_refused_at_construction(name, option, value):
    with pytest.raises(ValueError, match=option if option != "monitor" else
                       next(iter(value)) if isinstance(value, dict) else option):
        engines.configure(name, **{option: value})


def test_configure_names_the_options_a_backend_has():
    with pytest.raises(ValueError, match="analytic has no option 'dt'; its options: .*theta0"):
        engines.configure("analytic", dt=1e-4)
    with pytest.raises(ValueError, match="unknown engine 'bullet'"):
        engines.configure("bullet")
    s = engines.configure("pymunk", criterion="alpha")
    assert s.criterion.kind == "alpha" and s.criterion.topple_angle == 1.5


@pytest.mark.parametrize("name", ENGINES)
def test_friction_below_the_no_sliding_bound_is_refused_before_stepping(name, fig5, monkeypatch):
    module = engines.get_backend(name)
    monkeypatch.setattr(module, "simulate_world", lambda *a, **k: pytest.fail("stepped"))
    with pytest.raises(ValueError, match="friction must be >="):
        module.simulate(fig5, Pulse(25.0, 11.0), engines.configure(name, friction=0.5))


@pytest.mark.parametrize("name", ENGINES)
def test_theta0_beyond_alpha_is_refused_before_stepping(name, fig5):
    with pytest.raises(ValueError, match="theta0 must be in"):
        engines.simulate(name, fig5, Pulse(1.0, 10.0), theta0=1.1 * fig5.alpha)


# ------------------------------------------------------------- the paper's cases
@pytest.mark.slow
@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize("pendulum", [True, False], ids=["pendulum", "bare"])
@pytest.mark.parametrize("point", "ABCD")
def test_paper_points_give_the_papers_verdict_and_mode(name, point, pendulum, fig5):
    scene = fig5 if pendulum else fig5.without_pendulum()
    tr = engines.simulate(name, scene, point_pulse(point))
    assert (tr.verdict.status, tr.verdict.mode) == PAPER_OUTCOMES[(point, pendulum)], tr.verdict
    assert tr.backend == name


# ------------------------------------------------------------------- restitution
@pytest.mark.slow
@pytest.mark.parametrize("name", ENGINES)
@pytest.mark.parametrize("lam", [3.0, 5.0, 7.0])
@pytest.mark.parametrize("mu", [0.5, 1.0, 2.0])
def test_restitution_matches_makris_vassiliou(name, lam, mu):
    scene = load_scene("fig5", lam=lam, mu=mu, gamma=0.0)
    res = measure_restitution(name, scene, n_impacts=4)
    assert res.complete, res.status
    closed_form = makris_vassiliou(scene.alpha, mu / 2.0)  # two columns carry the lintel
    errors = [i.measured / closed_form - 1.0 for i in res.impacts]
    assert max(map(abs, errors)) <= RESTITUTION_TOL, errors


# Eq. 19 (pendulum) at the defaults, first four impacts from alpha/2: measured
# Pymunk <= 0.25 % at lam 3, 5, 7; PyBullet within 0.5 % at lam 3 and 5 but 1.2 %
# at lam 7 (docs/engine-trust.md: the two columns land one step apart).
EQ19_KNOWN = {("pybullet", 7.0): "PyBullet Eq. 19 at lam 7: ~1.2 %, columns land a step apart"}


@pytest.mark.slow
@pytest.mark.parametrize("name", ENGINES)
@pytest.mark.parametrize("lam", [3.0, 5.0, 7.0])
def test_restitution_with_pendulum_matches_eq19(name, lam, request):
    if (name, lam) in EQ19_KNOWN:
        request.applymarker(pytest.mark.xfail(strict=True, reason=EQ19_KNOWN[(name, lam)]))
    scene = load_scene("fig5", lam=lam)
    res = measure_restitution(name, scene, n_impacts=4)
    assert res.complete, res.status
    assert max(abs(i.psi) for i in res.impacts) > 0.05  # the pendulum swings: psi matters
    assert res.max_rel_error <= RESTITUTION_TOL, [i.rel_error for i in res.impacts]


# ---------------------------------------------------------------- run behaviour
@pytest.mark.parametrize("name", ALL)
def test_reruns_are_bit_identical(name, fig5):
    a = engines.simulate(name, fig5, Pulse(19.0, 15.0), t_max=1.0)
    b = engines.simulate(name, fig5, Pulse(19.0, 15.0), t_max=1.0)
    for field in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    assert a.verdict == b.verdict and a.events == b.events


@pytest.mark.parametrize("name", ALL)
def test_trajectory_carries_its_settings_and_version(name, fig5):
    s = engines.configure(name, t_max=0.3)
    tr = engines.get_backend(name).simulate(fig5, Pulse(5.0, 10.0), s)
    assert tr.backend == name and tr.t_max == 0.3 and tr.criterion == s.criterion
    assert tr.settings["t_max"] == 0.3
    if name in ENGINES:
        assert tr.settings["engine_version"] == engines.get_backend(name).version()
        assert tr.settings["dt"] == s.dt and tr.diagnostics["steps"] > 0
    assert len(tr.t) == len(tr.theta) and tr.t[-1] <= 0.3 + 0.01


@pytest.mark.parametrize("name", [n for n in ENGINES if engines.supports(n, "moving_ground")])
def test_gravity_trick_and_moving_ground_agree(name, fig5):
    """d'Alembert load vs a moving ground (DESIGN.md): peak angle within 0.1 %
    (measured 0.07 % PyBullet, 0.03 % Pymunk; both are exact for a rigid base,
    the rest is the engines' contact solution)."""
    pulse = Pulse(12.0, 12.0)
    a = engines.simulate(name, fig5, pulse, t_max=1.0)
    b = engines.simulate(name, fig5, pulse, t_max=1.0, base_motion="ground")
    assert a.max_abs_theta > 0.01  # it rocks
    assert b.max_abs_theta == pytest.approx(a.max_abs_theta, rel=1e-3)


@pytest.mark.parametrize("name", ENGINES)
def test_early_stop_off_runs_to_t_max(name, fig5):
    on = engines.simulate(name, fig5, Pulse(5.0, 10.0))
    off = engines.simulate(name, fig5, Pulse(5.0, 10.0), t_max=on.t[-1] + 0.5, early_stop=False)
    assert on.verdict.status == "survived"
    assert off.t[-1] >= on.t[-1] + 0.5 - 1e-9
    n = len(on.t)
    assert np.array_equal(on.theta, off.theta[:n])  # same run, only longer


def test_settings_are_frozen_dataclasses():
    for name in ALL:
        s = engines.configure(name)
        assert dataclasses.is_dataclass(s)
        with pytest.raises(dataclasses.FrozenInstanceError):
            s.t_max = 1.0


@pytest.mark.parametrize("name", ENGINES)
def test_pendulum_on_a_resting_trilith_follows_eq1(name, fig5):
    """A pendulum released at psi0 = 0.1 rad on the trilith at rest swings as Eq. 1
    (psi CCW from the downward vertical): sign convention and joint.  Tolerances
    1e-4 rad and 5e-4 rad/s: measured 2026-11-23 at most 2.0e-5 rad (Pymunk; PyBullet
    and MuJoCo 1.1e-5) and 6.8e-5 rad/s (PyBullet) over 1 s, the trilith swaying by
    < 1e-7 rad on its contacts; 5x headroom for the step error."""
    from scipy.integrate import solve_ivp

    from analytic import equations as eq
    from analytic.excitation import Still

    tr = engines.simulate(name, fig5, Still(), psi0=0.1, t_max=1.0, early_stop=False)
    assert tr.max_abs_theta < 1e-6  # the trilith stayed down
    l, g = fig5.pendulum_length, fig5.g
    sol = solve_ivp(lambda t, y: (y[1], eq.rest_pendulum_acceleration(y[0], 0.0, l, g)),
                    (0.0, tr.t[-1]), (0.1, 0.0), t_eval=tr.t, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(tr.psi - sol.y[0])) < 1e-4
    assert np.max(np.abs(tr.psi_dot - sol.y[1])) < 5e-4
