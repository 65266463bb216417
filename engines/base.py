"""The backend contract, written once (in the spirit of scipy's ``OdeSolver`` base).

A *backend* is a module registered in :data:`engines.BACKENDS` that satisfies
:class:`Backend`: a ``NAME``, a frozen ``Settings`` dataclass derived from
:class:`analytic.options.RunOptions` (engines: from :class:`EngineSettings`),
``simulate(scene, excitation, settings) -> Trajectory``, ``version()`` and the set
``CAPABILITIES`` of optional features it declares (never probed at run time).

An *engine* adapter is the same short loop for every engine,
:func:`simulate_world`: build a :class:`World` (the engine's bodies from the
:class:`~analytic.parameters.Scene`), then alternately ``advance`` it by
``sample_every`` steps and ``sample`` its state into the shared
:class:`~engines._common.RunMonitor`, which decides when the verdict is certain.
A new engine is one module (its ``Settings``, ``World`` and ``version``) and one
line in :data:`engines.BACKENDS`; see ``docs/adding-an-engine.md``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Protocol, runtime_checkable

from analytic.options import RunOptions, check_real
from analytic.trajectory import Trajectory

from ._common import MonitorSettings, RunMonitor, required_friction

__all__ = ["Backend", "World", "EngineSettings", "simulate_world", "check_run", "CAPABILITIES",
           "BASE_MOTIONS"]

# Optional features a backend may declare in its CAPABILITIES.
CAPABILITIES = {
    "time_step": "Settings has a fixed step 'dt' [s] (engines; convergence studies halve it)",
    "solver_iterations": "Settings has 'solver_iterations' (convergence studies double it)",
    "render": "render_frames(scene, excitation, times, settings, width, height) -> RGB frames",
    "gui": "view(scene, excitation, settings, duration) opens a live window",
    "moving_ground": "base_motion='ground' moves a ground body (besides the gravity trick)",
    "initial_tilt": "theta0/psi0 releases (free-rocking restitution)",
    "trajectory": "simulate() samples theta(t) (every backend does)",
}
BASE_MOTIONS = ("gravity", "ground")


@runtime_checkable
class Backend(Protocol):
    """What :func:`engines.get_backend` returns (a module, checked structurally)."""

    NAME: str
    Settings: type
    CAPABILITIES: frozenset

    def simulate(self, scene, excitation, settings=None) -> Trajectory: ...

    def version(self) -> str: ...


class World(Protocol):
    """One engine's bodies, built fresh for one run (nothing shared between runs).

    ``sample()`` returns ``(theta_left, theta_right, theta_dot, psi, psi_dot,
    problem)`` in the analytic model's signs (``theta > 0``: rocking on the left
    corners; ``psi`` from the downward vertical, counter-clockwise) and updates the
    contact diagnostics in ``diag``; ``problem`` names a blow-up (non-finite state,
    a body flown away) or is None.
    """

    step_index: int
    diag: dict

    def advance(self, count: int) -> None: ...

    def sample(self) -> tuple[float, float, float, float, float, str | None]: ...

    def close(self) -> None: ...


@dataclass(frozen=True)
class EngineSettings(RunOptions):
    """What every engine's ``Settings`` adds to :class:`~analytic.options.RunOptions`.

    Parameters
    ----------
    dt : float
        Time step [s] in (0, 0.1].  1e-4 s for every engine: their restitution
        error grows about linearly with the step (``docs/benchmarks.md``).
    base_motion : {'gravity', 'ground'}
        ``'gravity'`` (default) imposes ``-xg_ddot(t)`` as a horizontal gravity
        component in the base frame (d'Alembert, exact for a rigid translating
        base); ``'ground'`` moves a ground body (engines declaring
        ``'moving_ground'``).
    sample_every : int
        Steps between two samples read into the monitor, in [1, 10000].  80 (8 ms
        at the default step).  Impacts are measured by propagating samples away
        from them with the rocking equations, so the spacing does not limit them:
        measured 2026-11-23 at 20 / 40 / 80, worst restitution error vs Eq. 20 on
        lam {3,5,7} x mu {0.5,1,2} Pymunk 0.235 / 0.234 / 0.233 %, PyBullet 0.233
        / 0.234 / 0.234 %, MuJoCo 0.051 / 0.056 / 0.059 %, vs Eq. 19 (lam 3-7) the
        same to 0.005 %, A-D verdicts and modes unchanged.  Reading state is the
        costliest part of a step in Python (PyBullet ~50 us a sample): at 20 the
        harness ran at 0.78-0.87 of the bare step rate, at 80 at >= 0.90
        (``benchmarks/bench_overhead.py``, docs/benchmarks.md).  The overturn time
        is resolved to a sample (8 ms, 0.5 % of a 1.7 s fall).
    monitor : MonitorSettings
        The shared stop and verdict thresholds.
    friction : float or None
        Coulomb coefficient at every contact, in (0, 1000]; None: the engine's
        calibrated default (each engine documents its own and how it combines
        two bodies' values).  Never below
        :func:`~engines._common.required_friction` (rocking without sliding).
    """

    dt: float = 1e-4
    base_motion: str = "gravity"
    sample_every: int = 80
    monitor: MonitorSettings = field(default_factory=MonitorSettings)
    friction: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        owner = type(self).__name__
        check_real(owner, "dt", self.dt, 0.0, 0.1)
        if self.base_motion not in BASE_MOTIONS:
            raise ValueError(f"{owner}: base_motion must be one of {BASE_MOTIONS}, "
                             f"got {self.base_motion!r}")
        if (isinstance(self.sample_every, bool) or not isinstance(self.sample_every, int)
                or not 1 <= self.sample_every <= 10_000):
            raise ValueError(f"{owner}: sample_every must be an integer in [1, 10000], "
                             f"got {self.sample_every!r}")
        if self.friction is not None:
            check_real(owner, "friction", self.friction, 0.0, 1e3)
        if not isinstance(self.monitor, MonitorSettings):
            raise TypeError(f"{owner}: monitor must be a MonitorSettings, "
                            f"got {type(self.monitor).__name__}")

    def check_friction(self, friction: float, scene, excitation) -> float:
        """``friction`` if it is at least :func:`~engines._common.required_friction`
        for rocking without sliding under ``excitation``, else ``ValueError``."""
        need = required_friction(scene, excitation)
        value = check_real(type(self).__name__, "friction", friction, 0.0, 1e3)
        if value < need:
            raise ValueError(f"{type(self).__name__}: friction must be >= {need:.4g} for rocking "
                             f"without sliding in this scene and excitation (see "
                             f"required_friction), got {friction!r}")
        return value


def check_run(name: str, settings_cls: type, s, scene, excitation,
              friction: float | None = None) -> float:
    """The checks every engine makes before building anything, with the scene and
    excitation at hand; returns the friction coefficient to use (``friction``, by
    default ``s.friction``).

    Raises ``TypeError`` for settings of another backend, ``ValueError`` for a
    massless lintel carrying a pendulum (the analytic model allows it, a body
    cannot), a tilt beyond ``alpha`` or friction below the no-sliding bound.
    """
    if not isinstance(s, settings_cls):
        raise TypeError(f"{name} settings must be {settings_cls.__module__}.Settings, "
                        f"got {type(s).__name__}")
    if scene.mu == 0.0 and scene.has_pendulum:
        raise ValueError(f"{name}: mu must be > 0 when gamma > 0 (a massless lintel, which the "
                         "analytic model allows, cannot carry the pendulum hinge in an engine)")
    s.check_scene(scene)
    return s.check_friction(s.friction if friction is None else friction, scene, excitation)


def simulate_world(name: str, make_world: Callable[[], World], scene, excitation,
                   settings: EngineSettings, info: dict) -> Trajectory:
    """The adapter loop every engine shares: build, then advance/sample until decided.

    Parameters
    ----------
    name : str
        The backend's registry name (``Trajectory.backend``).
    make_world : callable
        Builds the engine's :class:`World` (called once, timed with the run).
    scene, excitation
        What is simulated (the monitor judges the run with the analytic rules).
    settings : EngineSettings
        Validated settings (``dt``, ``sample_every``, the run options).
    info : dict
        The settings as the result should carry them (``describe()`` plus what
        the engine resolved, e.g. the friction used and its version).

    Returns
    -------
    Trajectory
        Samples every ``sample_every`` steps, events, the verdict and the world's
        diagnostics (plus ``steps``, ``wall_time`` and ``cpu_time``: this
        process's CPU seconds for the run, which a load on the machine does not
        inflate as it does the wall time).
    """
    wall0, cpu0 = time.perf_counter(), time.process_time()
    monitor = RunMonitor(scene, excitation, settings)
    world = make_world()
    try:
        while True:
            t = world.step_index * settings.dt
            *state, problem = world.sample()
            if problem is not None:
                monitor.mark_unstable(t, problem)
                break
            if monitor.record(t, *state) or monitor.check_frame(t, world.diag):
                break
            world.advance(settings.sample_every)
        diagnostics = dict(world.diag, steps=world.step_index)
    finally:
        world.close()
    wall = time.perf_counter() - wall0
    diagnostics["wall_time"] = wall
    diagnostics["cpu_time"] = time.process_time() - cpu0
    return monitor.finish(name, info, diagnostics, wall)
