"""The engine contract, written once (in the spirit of scipy's ``OdeSolver``).

An engine is a subclass of :class:`Engine`: one run is one instance.  The base
class validates everything before any work (types, the scene, friction, the run
budget), owns the run loop (:meth:`Engine.run`: build, then read / judge /
advance until the verdict is decided, close, finish) and the shared rules (the
monitor of :mod:`engines.monitor`, the diagnostics of :mod:`engines.diagnostics`,
the geometry of :mod:`engines.geometry`).  An engine fills four hooks
(:meth:`~Engine.build`, :meth:`~Engine.advance`, :meth:`~Engine.read`,
:meth:`~Engine.close`) and declares its settings, capabilities and display
metadata.  The implementer's rules are in :class:`Engine`'s docstring.
"""
from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
import dataclasses
from dataclasses import dataclass, field
from typing import ClassVar

from trilith_xval.analytic.bounds import required_friction
from trilith_xval.analytic.excitation import check_excitation
from trilith_xval.analytic.kinds import KindScene
from trilith_xval.analytic.options import MAX_ENGINE_DT, MAX_RUN_STEPS, RunOptions, check_real
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.trajectory import Trajectory

from . import geometry
from .diagnostics import Diagnostics, PlaneState
from .monitor import MonitorSettings, RunMonitor
from .structure_monitor import StructureMonitor

__all__ = ["Engine", "EngineSettings", "CAPABILITIES", "BASE_MOTIONS", "MAX_RUN_STEPS",
           "FRICTION_MARGIN", "run_steps"]

# Optional features an engine declares in ``capabilities``.
CAPABILITIES = {
    "time_step": "Settings has a fixed step 'dt' [s] (engines; convergence studies halve it)",
    "solver_iterations": "Settings has 'solver_iterations' (convergence studies double it)",
    "render": "render_frames(scene, excitation, times, settings, width, height) -> RGB frames",
    "gui": "view(scene, excitation, settings, duration) opens a live window",
    "moving_ground": "base_motion='ground' moves a ground body (besides the gravity trick)",
    "initial_tilt": "theta0/psi0 releases (free-rocking restitution)",
    "trajectory": "simulate() samples theta(t) (every backend does)",
    "free_block": "free_block(side, mass, inertia, g, state, friction, n_frames, frame_rate, "
                  "on_step) -> (thetas, warnings): a free planar block started in flight "
                  "(a measured impact's replay, compare/peers/impact_replay.py)",
}
BASE_MOTIONS = ("gravity", "ground")
# Default friction is at least this multiple of the no-sliding bound
# (analytic.bounds.required_friction): 20 % headroom over a bound that is itself
# conservative (it exceeded the exact demand along the analytic runs at A-D).
FRICTION_MARGIN = 1.2


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
        Coulomb coefficient at every contact, in (0, 1000] (each engine
        documents how it combines two bodies' values).  None (default) follows
        the excitation: ``max(Engine.default_friction, FRICTION_MARGIN *
        required_friction)``, the calibrated value unless the pulse needs more.
        A value given is refused below :func:`~analytic.bounds.required_friction`
        (rocking without sliding).
    """

    dt: float = 1e-4
    base_motion: str = "gravity"
    sample_every: int = 80
    monitor: MonitorSettings = field(default_factory=MonitorSettings)
    friction: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        owner = type(self).__name__
        check_real(owner, "dt", self.dt, 0.0, MAX_ENGINE_DT)
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

    def with_solver_iterations(self, n: int) -> EngineSettings:
        """These settings with ``n`` solver iterations per step (engines declaring
        ``solver_iterations``; each names its own field, this is the one way to
        set it)."""
        return dataclasses.replace(self, solver_iterations=n)


def run_steps(settings: EngineSettings, excitation) -> int:
    """Most steps a run can take: its length (``t_max``, else the excitation's end
    plus the monitor's ``t_cap``) over ``dt``, rounded up."""
    length = (settings.t_max if settings.t_max is not None
              else excitation.end_time + settings.monitor.t_cap)
    return int(math.ceil(length / settings.dt))


class Engine:
    """One run of one physics engine; subclass it to add an engine.

    The base class checks the inputs, owns the run loop (:meth:`run`) and the
    rules every engine is judged by; a subclass declares what it is and fills
    four hooks.

    Rules for implementers
    ----------------------
    * Declare ``name`` (the registry name), ``label``, ``color``, ``marker``
      (display), ``capabilities`` (keys of :data:`CAPABILITIES`, never probed at
      run time), ``known_failures`` (check name -> measured reason, see
      :mod:`engines.testing`), ``calibration_space`` (Settings field -> values
      ``trilith calibrate`` searches besides ``dt``; optional), ``default_friction``
      (the calibrated Coulomb coefficient) and ``Settings``: a frozen dataclass derived from
      :class:`EngineSettings` whose defaults are the calibrated values, each
      documented with its measurement.  Implement :meth:`version`.
    * :meth:`build` creates a fresh world (nothing shared between runs) from
      :mod:`engines.geometry`: the rest poses at ``settings.theta0`` /
      ``settings.psi0``, box inertias, the ground box; the column inertia is the
      scene's ``J_G``; the pendulum bob collides with nothing; ``mu = 0`` builds
      no lintel.  Every contact uses ``self.friction`` (combined so that the
      pair sees exactly it) and is plastic.
    * :meth:`advance` steps ``steps`` times.  Base motion ``'gravity'``: add
      :meth:`base_load` of each step to gravity's x component (d'Alembert,
      mid-step, zero after the pulse); ``'ground'`` (capability
      ``moving_ground``): move a ground body by :meth:`ground_motion`.
    * :meth:`read` returns the bodies in the analytic plane
      (:class:`~engines.diagnostics.PlaneState`); it judges nothing.  Every
      verdict, diagnostic and blow-up rule lives in :mod:`engines.monitor` and
      :mod:`engines.diagnostics`, the same for every engine.
    * :meth:`close` releases what :meth:`build` took; it is called once, also
      after an error.
    * Optionally, :meth:`build` turns the body list
      (:func:`engines.geometry.structure_of`) into the world and the class sets
      ``structures = True``: it then also runs the scenes of
      :mod:`analytic.kinds` (judged by :mod:`engines.structure_monitor`), whose
      :meth:`read` fills ``PlaneState.bodies``; otherwise they are refused.
    * The class is registered by one line in :data:`engines.ENGINES` (or an
      entry point of the group ``trilith_xval.engines``) and must pass
      :func:`engines.testing.check_backend`.

    Parameters
    ----------
    scene : Scene
    excitation : Excitation
        Any :class:`~analytic.excitation.Excitation` (the shipped pulses and
        records, or a user's own subclass).
    settings : Settings, optional
        The engine's own ``Settings``; None: the calibrated defaults.

    Raises
    ------
    TypeError
        A scene, excitation or settings of the wrong type.
    ValueError
        A tilt beyond ``alpha``, a massless lintel carrying a pendulum, a
        friction below the no-sliding bound, or a run over :data:`MAX_RUN_STEPS`.
    """

    name: ClassVar[str]
    label: ClassVar[str]
    color: ClassVar[str]
    marker: ClassVar[str]
    capabilities: ClassVar[frozenset[str]]
    known_failures: ClassVar[Mapping[str, str]] = {}
    # Cheap enough for a default multi-engine run (atlas, trust): about a CPU
    # second or less per threshold point at its threshold step.
    affordable: ClassVar[bool] = True
    calibration_space: ClassVar[Mapping[str, Sequence]] = {}
    # (scene, Omega [rad/s]) of the engine's regression threshold against the model
    # (tests/engines/test_regression_engines.py): on one of Fig. 5's well-posed
    # branches, away from mode jumps and overturning windows.
    regression_point: ClassVar[tuple[str, float]] = ("fig5", 13.0)
    default_friction: ClassVar[float]
    Settings: ClassVar[type[EngineSettings]]
    # Builds any body list (engines.geometry.Structure: the kinds of analytic.kinds),
    # not only the parametric trilith; read() then fills PlaneState.bodies.
    structures: ClassVar[bool] = False
    # The restitution map's variants beyond the step (name, why, options over the
    # defaults): the parameters of this engine that act on a rocking impact
    # (compare/measure/restitution_map.py); and those it fixes rather than exposes,
    # said beside the map.
    impact_variants: ClassVar[tuple[tuple[str, str, Mapping], ...]] = ()
    impact_fixed: ClassVar[str] = ""

    @classmethod
    def version(cls) -> str:
        """The engine library's version string."""
        raise NotImplementedError

    @classmethod
    def simulate(cls, scene, excitation, settings=None) -> Trajectory:
        """Run ``scene`` under ``excitation``; returns a :class:`Trajectory`."""
        return cls(scene, excitation, settings).run()

    def __init__(self, scene, excitation, settings=None) -> None:
        name = self.name
        if isinstance(scene, KindScene):
            if not self.structures:
                raise ValueError(f"{name} runs the parametric trilith only, not the "
                                 f"{scene.kind!r} kind (engines that run it: "
                                 f"{', '.join(geometry.STRUCTURE_ENGINES)})")
        elif not isinstance(scene, Scene):
            raise TypeError(f"{name}: scene must be a Scene, got {type(scene).__name__}")
        check_excitation(excitation, where=name)
        s = settings if settings is not None else self.Settings()
        if not isinstance(s, self.Settings):
            raise TypeError(f"{name} settings must be {type(self).__module__}.Settings, "
                            f"got {type(s).__name__}")
        if isinstance(scene, KindScene):
            self._init_kind(scene, excitation, s)
            return
        if scene.mu == 0.0 and scene.has_pendulum:
            raise ValueError(f"{name}: mu must be > 0 when gamma > 0 (a massless lintel, which "
                             "the analytic model allows, cannot carry the pendulum hinge in an "
                             "engine)")
        s.check_scene(scene)
        self._start(scene, excitation, s, required_friction(scene, excitation),
                    "for rocking without sliding in this scene and excitation (see "
                    "analytic.bounds.required_friction)")

    def _init_kind(self, scene, excitation, s) -> None:
        """The checks of a scene of :mod:`analytic.kinds`: an initial tilt only as
        a plumb error (:data:`engines.geometry.MAX_KIND_TILT`), the run budget,
        and the friction.

        The friction is the engine's calibrated default unless given, raised to
        ``FRICTION_MARGIN * PGA/g`` when the pulse asks more; a value given must
        be at least ``PGA/g``.  Why ``PGA/g`` for a stack of blocks: until a part
        uplifts the whole structure moves with the ground, and every interface
        (a column or a drum on the ground, a drum on a drum, a lintel on its
        columns) carries the horizontal force ``m_above a(t)`` of the bodies above
        it under their weight ``m_above g``: each level needs the same ``a/g``, the
        bound of a single block, whatever the stack.  The model's bound
        (:func:`~analytic.bounds.required_friction`) adds the rocking trilith's
        demand; the rocking demand of the other kinds has no model, so it is
        measured instead (PyBullet at its calibrated 1: no contact slips beyond
        the contact slop at the strong pulses of ``tests/engines/test_kinds_engines.py``)."""
        self.structure = geometry.structure_of(scene, s.theta0, s.psi0)
        need = excitation.acceleration_bound() / scene.g
        self._start(scene, excitation, s, need,
                    "(the peak ground acceleration over g) for this excitation")

    def _start(self, scene, excitation, s, need: float, why: str) -> None:
        """The checks every run shares, then its state: the friction (the engine's
        default unless given, raised to ``FRICTION_MARGIN * need`` when the
        excitation asks more; a value given must be at least ``need``, the
        no-sliding bound, ``why`` saying which), the run budget
        (:data:`MAX_RUN_STEPS`), and the step counter and load window."""
        if s.friction is None:
            friction = max(self.default_friction, FRICTION_MARGIN * need)
        else:
            friction = check_real(type(s).__name__, "friction", s.friction, 0.0, 1e3)
            if friction < need:
                raise ValueError(f"{type(s).__name__}: friction must be >= {need:.4g} {why}, "
                                 f"got {s.friction!r}")
        steps = run_steps(s, excitation)
        if steps > MAX_RUN_STEPS:
            raise ValueError(f"{self.name}: a run of {steps * s.dt:.4g} s (t_max, or the "
                             f"excitation's end plus t_cap) at dt = {s.dt:g} s is {steps:.3g} "
                             f"steps, over the budget of {MAX_RUN_STEPS:.0e}; raise dt or "
                             "shorten t_max")
        self.scene, self.excitation, self.settings = scene, excitation, s
        self.friction, self.required_friction = friction, need
        self.step_index = 0
        # The d'Alembert load is evaluated mid-step; from this step on it is 0.
        self._load_end = max(0, math.ceil(excitation.end_time / s.dt) + 1)

    # ------------------------------------------------------------------ the hooks
    def build(self) -> None:
        """Create the world's bodies (see the implementer's rules)."""
        raise NotImplementedError

    def advance(self, steps: int) -> None:
        """Step the world ``steps`` times (and add them to ``step_index``)."""
        raise NotImplementedError

    def read(self) -> PlaneState:
        """The bodies' state now, in the analytic plane."""
        raise NotImplementedError

    def close(self) -> None:
        """Release what :meth:`build` took (called once, also after an error)."""

    # ---------------------------------------------------------------- for hooks
    def base_load(self, step: int) -> float:
        """Horizontal d'Alembert acceleration [m/s^2] to add to gravity during step
        ``step`` (from ``step dt`` to ``(step + 1) dt``): ``-xg_ddot`` at mid-step,
        which makes the step's velocity change second-order accurate, and exactly
        0 after the pulse."""
        if step >= self._load_end:
            return 0.0
        return -self.excitation.acceleration((step + 0.5) * self.settings.dt)

    def ground_motion(self, step: int) -> tuple[float, float]:
        """``(x, v)`` of a moving ground at the start of step ``step``: its
        displacement [m] and the mean velocity [m/s] over the step (so the
        position follows the excitation exactly)."""
        dt, displacement = self.settings.dt, self.excitation.displacement
        x0, x1 = displacement(step * dt), displacement((step + 1) * dt)
        return x0, (x1 - x0) / dt

    def describe(self) -> dict:
        """The settings as the result carries them, with the friction used and
        the engine's version."""
        info = self.settings.describe()
        info["friction_used"] = self.friction
        info["engine_version"] = self.version()
        return info

    # ------------------------------------------------------------------ the loop
    def run(self) -> Trajectory:
        """Build, then read / judge / advance every ``sample_every`` steps until the
        monitor decides; close and return the :class:`Trajectory` (samples,
        events, verdict, diagnostics, ``steps``, ``wall_time`` and ``cpu_time``:
        this process's CPU seconds for the run, which a load on the machine does
        not inflate as it does the wall time)."""
        s = self.settings
        if isinstance(self.scene, KindScene):
            return self._run_structure()
        wall0, cpu0 = time.perf_counter(), time.process_time()
        monitor = RunMonitor(self.scene, self.excitation, s)
        # Kept on the run: an engine's own extra readings may consult the window.
        self.diagnostics = diagnostics = Diagnostics(self.scene, self.excitation, s.monitor)
        try:
            self.build()
            while True:
                t = self.step_index * s.dt
                state = self.read()
                problem = diagnostics.update(state)
                left, right = state.columns
                if problem is not None:
                    monitor.mark_unstable(t, problem)
                    break
                if (monitor.record(t, left.angle, right.angle, 0.5 * (left.omega + right.omega),
                                   state.psi, state.psi_dot)
                        or monitor.check_frame(t, diagnostics.values)):
                    break
                self.advance(s.sample_every)
        finally:
            self.close()
        wall = time.perf_counter() - wall0
        diag = dict(diagnostics.values, steps=self.step_index, wall_time=wall,
                    cpu_time=time.process_time() - cpu0,
                    required_friction=self.required_friction)
        return monitor.finish(self.name, self.describe(), diag, wall)

    def _run_structure(self) -> Trajectory:
        """:meth:`run` for a scene of :mod:`analytic.kinds`: the same loop, judged
        by :class:`~engines.structure_monitor.StructureMonitor` (the model's rules
        do not apply)."""
        s = self.settings
        wall0, cpu0 = time.perf_counter(), time.process_time()
        monitor = StructureMonitor(self.scene, self.structure, self.excitation, s)
        try:
            self.build()
            while not monitor.record(self.step_index * s.dt, self.read()):
                self.advance(s.sample_every)
        finally:
            self.close()
        wall = time.perf_counter() - wall0
        diag = dict(steps=self.step_index, wall_time=wall, cpu_time=time.process_time() - cpu0,
                    required_friction=self.required_friction)
        return monitor.finish(self.name, self.describe(), diag, wall)

