"""The backend contract as public checks (in the manner of scikit-learn's ``check_estimator``).

Every check is a function of the backend class (:func:`engines.get_backend`),
gated by what the backend declares: physics engines (subclasses of
:class:`engines.base.Engine`) get the engine checks, the capabilities
(``initial_tilt``, ``moving_ground``, ``render``, ...) select the rest.  A
backend lists the checks it is known to fail in ``known_failures`` (check id ->
the measured reason); such a check must keep failing (strict), so a fix is
noticed.

:func:`check_backend` runs them all and raises ``AssertionError`` naming the
first failing check; :func:`backend_checks` is the pytest parametrizer the
suite uses (slow checks marked ``slow``, known failures ``xfail(strict=True)``).

Tolerances
----------
Restitution against the closed forms: 0.5 % (``RESTITUTION_TOL``), the
acceptance bound of the engine contract; measured at the defaults, first four
impacts from ``alpha / 2``: Eq. 20 worst Pymunk 0.24 %, PyBullet 0.23 %, MuJoCo
0.06 % over ``lam`` {3, 5, 7} x ``mu`` {0.5, 1, 2} (2026-11-23).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Check", "CHECKS", "checks_for", "check_backend", "backend_checks",
           "RESTITUTION_TOL", "makris_vassiliou"]

RESTITUTION_TOL = 5e-3


@dataclass(frozen=True)
class Check:
    """One check of the contract: ``run(backend_class)`` raises on failure."""

    id: str
    run: Callable[[type], None]
    needs: frozenset = frozenset()  # capabilities the backend must declare
    engine: bool = False  # physics engines only
    slow: bool = False


def makris_vassiliou(alpha: float, gamma_mv: float) -> float:
    """Rocking-frame restitution of uniform columns under a cap beam (Makris &
    Vassiliou 2013), ``gamma_mv`` = beam mass / total column mass; Eq. 20 of the
    paper without pendulum."""
    s2 = math.sin(alpha) ** 2
    return (1.0 - 1.5 * s2 + 3.0 * gamma_mv * math.cos(2.0 * alpha)) / (1.0 + 3.0 * gamma_mv)


def _fig5(**changes):
    from trilith_xval.scenes import load_scene
    return load_scene("fig5", **changes)


def _refused_before_work(backend, match: str, exc, *args, **options) -> None:
    """``backend`` refuses (``exc`` matching ``match``) without building a world."""
    from trilith_xval import engines
    from trilith_xval.engines.base import Engine
    built = []
    if issubclass(backend, Engine):
        class Probe(backend):
            def build(self):
                built.append(True)
                raise AssertionError("a world was built before the input was checked")
        backend = Probe
    try:
        engines.simulate(backend, *args, **options)
    except exc as err:
        assert match in str(err), f"{type(err).__name__} {err} does not name {match!r}"
    else:
        raise AssertionError(f"no {exc.__name__} naming {match!r}")
    assert not built


# ---------------------------------------------------------------------- checks
def _contract(backend) -> None:
    from trilith_xval.analytic.options import RunOptions
    from trilith_xval.engines.base import CAPABILITIES, Engine, EngineSettings
    assert isinstance(backend.name, str) and backend.name
    assert all(isinstance(getattr(backend, k), str) for k in ("label", "color", "marker"))
    assert issubclass(backend.Settings, RunOptions)
    assert set(backend.capabilities) <= set(CAPABILITIES)
    assert "trajectory" in backend.capabilities
    assert isinstance(backend.version(), str) and backend.version()
    if issubclass(backend, Engine):
        assert issubclass(backend.Settings, EngineSettings)
        assert {"time_step", "initial_tilt"} <= backend.capabilities
        assert backend.default_friction > 0.0
    if "render" in backend.capabilities:
        assert callable(backend.render_frames)
    if "gui" in backend.capabilities:
        assert callable(backend.view)
    s = backend.Settings()
    assert dataclasses.is_dataclass(s)
    try:
        s.t_max = 1.0
    except dataclasses.FrozenInstanceError:
        pass
    else:
        raise AssertionError("Settings must be frozen")


def _bad_run_options(backend) -> None:
    from trilith_xval import engines
    for option, value, exc in (("t_max", -1.0, ValueError), ("t_max", math.nan, ValueError),
                               ("t_max", "2", TypeError), ("theta0", 2.0, ValueError),
                               ("psi0", 4.0, ValueError), ("early_stop", 1, TypeError),
                               ("criterion", "sideways", ValueError)):
        try:
            engines.configure(backend, **{option: value})
        except exc as err:
            assert option in str(err), (option, str(err))
        else:
            raise AssertionError(f"{option}={value!r} accepted")


def _bad_engine_settings(backend) -> None:
    from trilith_xval import engines
    for option, value, word in (("dt", 0.0, "dt"), ("dt", 0.5, "dt"),
                                ("sample_every", 0, "sample_every"),
                                ("base_motion", "shake", "base_motion"),
                                ("friction", -1.0, "friction"),
                                ("monitor", {"t_cap": -1.0}, "t_cap"),
                                ("monitor", {"rest_hold": math.nan}, "rest_hold")):
        try:
            engines.configure(backend, **{option: value})
        except ValueError as err:
            assert word in str(err), (option, str(err))
        else:
            raise AssertionError(f"{option}={value!r} accepted")


def _bad_input_before_work(backend) -> None:
    from trilith_xval.analytic.excitation import Pulse
    scene = _fig5()
    _refused_before_work(backend, "friction must be >=", ValueError, scene, Pulse(25.0, 11.0),
                         friction=0.5)
    _refused_before_work(backend, "theta0 must be in", ValueError, scene, Pulse(1.0, 10.0),
                         theta0=1.1 * scene.alpha)
    _refused_before_work(backend, "scene", TypeError, {"b": 0.6}, Pulse(1.0, 10.0))
    _refused_before_work(backend, "excitation", TypeError, scene, (1.0, 10.0))
    # 1e4 s at 1e-4 s is 1e8 steps, over the 5e6-step budget.
    _refused_before_work(backend, "dt", ValueError, scene, Pulse(1.0, 10.0), t_max=1e4)


def _friction_follows_the_excitation(backend) -> None:
    """The documented pulse range (|A| <= 1e4 m/s^2) never fails on friction the
    user did not set; an explicit friction below the bound is still refused."""
    from trilith_xval.analytic.bounds import required_friction
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.engines.base import FRICTION_MARGIN
    scene = _fig5()
    for pulse in (Pulse(100.0, 11.0), Pulse(-1e4, 100.0)):
        need = required_friction(scene, pulse)
        run = backend(scene, pulse)  # checked, not built
        assert run.friction == max(backend.default_friction, FRICTION_MARGIN * need)
    assert backend(scene, Pulse(1.0, 10.0)).friction == backend.default_friction


def _paper_points(backend) -> None:
    from trilith_xval.scenes import PAPER_OUTCOMES, point_pulse
    fig5 = _fig5()
    for (point, pendulum), expected in PAPER_OUTCOMES.items():
        scene = fig5 if pendulum else fig5.without_pendulum()
        tr = backend.simulate(scene, point_pulse(point))
        got = (tr.verdict.status, tr.verdict.mode)
        assert got == expected, (point, pendulum, tr.verdict)
        assert tr.backend == backend.name


def _free_rocking_impacts(backend, scene, n: int) -> tuple:
    """The first ``n`` impact events of ``scene`` released at rest from ``alpha / 2``
    in ``backend``, run to midway between the analytic model's impacts ``n`` and
    ``n + 1`` (the run's impact velocities are the monitor's, propagated to
    ``theta = 0`` from samples away from the impact)."""
    from trilith_xval import engines
    from trilith_xval.analytic.excitation import Still
    theta0 = 0.5 * scene.alpha
    ref = engines.simulate("analytic", scene, Still(), theta0=theta0, early_stop=False,
                           sample_dt=None, t_cap=60.0)
    times = [e.t for e in ref.impacts[:n + 1]]
    assert len(times) == n + 1, f"the model comes to rest after {len(times)} impacts"
    tr = engines.simulate(backend, scene, Still(), theta0=theta0, early_stop=False,
                          t_max=0.5 * (times[n - 1] + times[n]))
    impacts = tr.impacts[:n]
    assert len(impacts) == n, (tr.verdict, len(impacts))
    return impacts


def _restitution_eq20(lam: float, mu: float) -> Callable[[type], None]:
    def check(backend) -> None:
        scene = _fig5(lam=lam, mu=mu, gamma=0.0)
        closed_form = makris_vassiliou(scene.alpha, mu / 2.0)  # two columns carry the lintel
        errors = [e.velocity_ratio / closed_form - 1.0
                  for e in _free_rocking_impacts(backend, scene, 4)]
        assert max(map(abs, errors)) <= RESTITUTION_TOL, errors
    return check


def _restitution_eq19(lam: float) -> Callable[[type], None]:
    def check(backend) -> None:
        from trilith_xval.analytic import equations as eq
        scene = _fig5(lam=lam)
        b, h, mu, gamma, j, _, _ = scene.model_args()
        impacts = _free_rocking_impacts(backend, scene, 4)
        assert max(abs(e.psi) for e in impacts) > 0.05  # the pendulum swings: psi matters
        errors = [e.velocity_ratio / eq.restitution_ratio(e.psi, e.side, b, h, mu, gamma, j)
                  - 1.0 for e in impacts]
        assert max(map(abs, errors)) <= RESTITUTION_TOL, errors
    return check


def _reruns_bit_identical(backend) -> None:
    from trilith_xval.analytic.excitation import Pulse
    s = dataclasses.replace(backend.Settings(), t_max=1.0)
    a = backend.simulate(_fig5(), Pulse(19.0, 15.0), s)
    b = backend.simulate(_fig5(), Pulse(19.0, 15.0), s)
    for field in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    assert a.verdict == b.verdict and a.events == b.events


def _trajectory_carries_settings(backend) -> None:
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.engines.base import Engine
    s = dataclasses.replace(backend.Settings(), t_max=0.3)
    tr = backend.simulate(_fig5(), Pulse(5.0, 10.0), s)
    assert tr.backend == backend.name and tr.t_max == 0.3 and tr.criterion == s.criterion
    assert tr.settings["t_max"] == 0.3
    if issubclass(backend, Engine):
        assert tr.settings["engine_version"] == backend.version()
        assert tr.settings["dt"] == s.dt and tr.diagnostics["steps"] > 0
        assert tr.settings["friction_used"] >= tr.diagnostics["required_friction"]
    assert len(tr.t) == len(tr.theta) and tr.t[-1] <= 0.3 + 0.01


def _moving_ground_agrees(backend) -> None:
    """d'Alembert load vs a moving ground (DESIGN.md): peak angle within 0.1 %
    (measured 0.07 % PyBullet, 0.03 % Pymunk; both are exact for a rigid base,
    the rest is the engines' contact solution)."""
    from trilith_xval import engines
    from trilith_xval.analytic.excitation import Pulse
    pulse = Pulse(12.0, 12.0)
    a = engines.simulate(backend, _fig5(), pulse, t_max=1.0)
    b = engines.simulate(backend, _fig5(), pulse, t_max=1.0, base_motion="ground")
    assert a.max_abs_theta > 0.01  # it rocks
    assert abs(b.max_abs_theta / a.max_abs_theta - 1.0) <= 1e-3


def _early_stop_off_runs_to_t_max(backend) -> None:
    from trilith_xval import engines
    from trilith_xval.analytic.excitation import Pulse
    on = engines.simulate(backend, _fig5(), Pulse(5.0, 10.0))
    off = engines.simulate(backend, _fig5(), Pulse(5.0, 10.0), t_max=on.t[-1] + 0.5,
                           early_stop=False)
    assert on.verdict.status == "survived"
    assert off.t[-1] >= on.t[-1] + 0.5 - 1e-9
    assert np.array_equal(on.theta, off.theta[:len(on.t)])  # same run, only longer


def _pendulum_follows_eq1(backend) -> None:
    """A pendulum released at psi0 = 0.1 rad on the trilith at rest swings as Eq. 1.
    Tolerances 1e-4 rad and 5e-4 rad/s: measured 2026-11-23 at most 2.0e-5 rad
    (Pymunk; PyBullet and MuJoCo 1.1e-5) and 6.8e-5 rad/s (PyBullet) over 1 s;
    5x headroom for the step error."""
    from trilith_xval import engines
    from scipy.integrate import solve_ivp

    from trilith_xval.analytic import equations as eq
    from trilith_xval.analytic.excitation import Still
    fig5 = _fig5()
    tr = engines.simulate(backend, fig5, Still(), psi0=0.1, t_max=1.0, early_stop=False)
    assert tr.max_abs_theta < 1e-6  # the trilith stayed down
    l, g = fig5.pendulum_length, fig5.g
    sol = solve_ivp(lambda t, y: (y[1], eq.rest_pendulum_acceleration(y[0], 0.0, l, g)),
                    (0.0, tr.t[-1]), (0.1, 0.0), t_eval=tr.t, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(tr.psi - sol.y[0])) < 1e-4
    assert np.max(np.abs(tr.psi_dot - sol.y[1])) < 5e-4


TILT = frozenset({"initial_tilt"})
CHECKS: tuple[Check, ...] = (
    Check("contract", _contract),
    Check("bad_run_options", _bad_run_options),
    Check("bad_engine_settings", _bad_engine_settings, engine=True),
    Check("bad_input_before_work", _bad_input_before_work, engine=True),
    Check("friction_follows_the_excitation", _friction_follows_the_excitation, engine=True),
    Check("reruns_bit_identical", _reruns_bit_identical),
    Check("trajectory_carries_settings", _trajectory_carries_settings),
    Check("moving_ground_agrees", _moving_ground_agrees, frozenset({"moving_ground"}), True),
    Check("early_stop_off_runs_to_t_max", _early_stop_off_runs_to_t_max, engine=True),
    Check("pendulum_follows_eq1", _pendulum_follows_eq1, TILT, True),
    Check("paper_points", _paper_points, slow=True),
    *(Check(f"restitution_eq20_lam{lam:g}_mu{mu:g}", _restitution_eq20(lam, mu), TILT, True,
            slow=True) for lam in (3.0, 5.0, 7.0) for mu in (0.5, 1.0, 2.0)),
    *(Check(f"restitution_eq19_lam{lam:g}", _restitution_eq19(lam), TILT, True, slow=True)
      for lam in (3.0, 5.0, 7.0)),
)


def checks_for(backend) -> list[Check]:
    """The checks that apply to ``backend`` (a class), by kind and capabilities."""
    from trilith_xval.engines.base import Engine
    is_engine = issubclass(backend, Engine)
    return [c for c in CHECKS
            if (is_engine or not c.engine) and c.needs <= set(backend.capabilities)]


def check_backend(name_or_class, slow: bool = True) -> None:
    """Run every applicable check on a backend; ``AssertionError`` naming the first
    that fails (or a known failure that now passes).  ``slow=False`` skips the
    paper points and the restitution grids (minutes)."""
    from trilith_xval import engines
    backend = engines.get_backend(name_or_class)
    known = getattr(backend, "known_failures", {})
    for check in checks_for(backend):
        if check.slow and not slow:
            continue
        try:
            check.run(backend)
        except Exception as err:
            if check.id in known:
                continue
            raise AssertionError(f"{backend.name}: check {check.id!r} failed: {err}") from err
        if check.id in known:
            raise AssertionError(f"{backend.name}: check {check.id!r} passes now; remove it "
                                 f"from known_failures ({known[check.id]})")


def backend_checks(names=None):
    """A pytest ``parametrize`` over ``(backend, check)`` for every registered backend
    (or ``names``): slow checks marked ``slow``, known failures ``xfail(strict=True)``."""
    import pytest

    from trilith_xval import engines
    params = []
    for name in (names if names is not None else engines.backend_names()):
        backend = engines.get_backend(name)
        known = getattr(backend, "known_failures", {})
        for check in checks_for(backend):
            marks = [pytest.mark.slow] if check.slow else []
            if check.id in known:
                marks.append(pytest.mark.xfail(strict=True, reason=known[check.id]))
            params.append(pytest.param(backend, check, marks=marks,
                                       id=f"{backend.name}-{check.id}"))
    return pytest.mark.parametrize("backend, check", params)
