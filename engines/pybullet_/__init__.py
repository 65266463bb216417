"""PyBullet (3D) backend: the trilith as boxes on a box ground, the pendulum as a
revolute link of the lintel (bodies built in :mod:`engines.pybullet_.bodies` from
the scene's body list, :class:`~engines.geometry.Structure`, so the other kinds of
:mod:`analytic.kinds` run too; the trilith's world is the one built before the
body list, bit for bit).

The hooks of :class:`engines.base.Engine`, plus
:meth:`PyBulletEngine.render_frames` (headless RGB frames for recordings) and
:meth:`PyBulletEngine.view` (GUI window, real time).

Base motion (DESIGN.md): ``"gravity"`` adds the d'Alembert load ``-xg_ddot(t)``
to gravity in the base frame (exact for a rigid translating base);
``"ground"`` moves a heavy ground body kinematically (its prismatic joint state
is reset to the ground's motion before every step).

Every run opens its own ``pybullet.DIRECT`` client and disconnects at the end.
Some physics parameters are *process-global* in Bullet (``contactBreakingThreshold``
in particular): every parameter this module relies on is set explicitly at the
start of every run, so runs do not depend on what ran before in the process.

``mu = 0``: no lintel body (a zero-mass PyBullet body is static); the columns
rock independently, which is the ``mu = 0`` frame of Eq. 8.  With a pendulum
this is refused (the hinge needs a lintel).

Measured accuracy at the defaults (fig. 5 scale, see :class:`Settings`):
restitution vs Eq. 20 median 0.03 %, 95 % of impacts within 0.5 %, with
occasional outliers (up to 6.5 %) when the two columns land in different steps;
vs Eq. 19 (pendulum) within 0.06 %; the Fig. 5 points A-D give the analytic
verdicts and modes, overturning times within 0.8 % (0.77 % measured), uplift within 0.2 ms of
Eq. 9 and theta within 1.3-2.8e-4 alpha (RMS) up to the first impact;
"gravity" and "ground" base motion agree within 0.07 % of the peak angle.
Strong pulses (45-100 m/s^2 at 16-30 rad/s) overturn as in the model; past
alpha the engine's columns part (the collapse is beyond the model), so the
overturning time there is not comparable.
"""
from __future__ import annotations

import math
import operator
import time
from dataclasses import dataclass

import numpy as np

from trilith_xval.analytic.kinds import KindScene
from trilith_xval.analytic.options import check_real
from trilith_xval.engines import geometry
from trilith_xval.engines.base import Engine, EngineSettings
from trilith_xval.engines.diagnostics import PlaneState, Pose
from trilith_xval.engines._quiet_pybullet import pybullet as pb

from . import world
from .bodies import build_scene

__all__ = ["PyBulletEngine", "Settings"]


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Numerical settings of a PyBullet run; defaults are the calibrated ones.

    The run options and engine fields (``criterion``, ``t_max``, ``theta0``,
    ``psi0``, ``early_stop``, ``dt``, ``base_motion``, ``sample_every``,
    ``monitor``) are :class:`engines.base.EngineSettings`; the defaults hold
    here (``dt`` 1e-4 s: 5e-5 measured no better at twice the cost).

    Parameters
    ----------
    friction : Coulomb coefficient of every contact; None: ``max(1, 1.2
        required_friction)`` (:class:`engines.base.EngineSettings`; 1 is the
        calibrated value, see :attr:`PyBulletEngine.default_friction`).  Bullet
        combines the two bodies' values by product, so each body gets
        ``sqrt(friction)``.
    solver_iterations : sequential-impulse iterations per step.
    contact_erp : Baumgarte factor for penetrations deeper than ``contact_slop``.
    contact_slop : penetration [m] left uncorrected (Bullet's ``contactSlop``).
    contact_breaking_threshold : distance [m] within which contact points are
        kept; None: 1 % of the column width.
    friction_anchor : Bullet's friction anchors (contacts stick in place).

    Calibration (free rocking, no pendulum, fig. 5 scale ``b = 0.6`` m, impacts
    measured against Eq. 20; ``lam`` in {3, 5, 7} x ``mu`` in {0.5, 1, 2} x
    release at {0.3, 0.5, 0.8} ``alpha``, first 4 impacts, 41 impacts):

    * ``contact_slop``: the one setting that matters.  Bullet's default 1e-5 m
      lets the Baumgarte push-out of the impact penetration (corner travel per
      step ``b theta_dot dt`` ~ 3e-5 m) inject energy: errors up to +8 % from the
      second impact on.  Larger slops (3e-4, 1e-3 m) leave random uncorrected
      penetrations that put the two columns out of step (mismatch ~slop/b) so
      they land one step apart: errors up to 16 %.  1e-4 m: median |error|
      0.03 %, 95 % of impacts within 0.5 %, worst 6.5 % (5e-5 m: 7 % beyond
      0.5 %; 2e-4 m: 12 %).  The outliers coincide with a column mismatch
      >= 1e-5 rad (``column_mismatch_max``): the two columns land in different
      steps.
    * ``contact_slop`` must shrink with the step: a slop of 1e-4 m at dt = 1e-5 s
      lets the resting columns creep (0.2 m pivot sliding, 0.037 rad by 0.1 s
      under a 3 m/s^2 pulse) and restitution errors reach 24 %; at 5e-5 s the
      error is 2.7 %.  With ``slop = dt * 1 m/s`` (the default below 1e-4 s):
      0.05 % at 5e-5 s, 1.2 % at 2e-5 s, 12 % at 1e-5 s, and no creep
      (lam 3, 5, 7, mu 1, release at alpha/2, 3 impacts; one run, 2026-11-22).
    * Below 1e-4 s ``friction_erp`` scales with ``dt`` and
      ``solver_residual_threshold`` with ``dt^2`` (both per-step quantities in
      Bullet; fixed, they made PyBullet worse at smaller steps: at 2.5e-5 s
      restitution +3.3 % (lam 3) and +1.2 % (lam 5), and an out-of-plane blow-up
      at Omega 24 / A 60; scaled: <= 0.02 % and none; docs/engine-trust.md,
      ``benchmarks/pybullet_small_step.py``).  At >= 1e-4 s they are the
      calibrated 0.2 and 1e-7 (m/s)^2, so results there are unchanged.
    * ``dt`` 5e-5 s is no better (10 % of impacts beyond 0.5 %) at twice the cost.
    * ``solver_iterations`` 10 or 200 and ``solverResidualThreshold`` 0: no gain.
    * ``friction`` 2: 10 % of impacts beyond 0.5 % (the same lottery); 25
      (Bullet's product of 5 and 5): unstable; no anchors: errors up to 9 %.
    * ``maximal coordinates`` (btRigidBody instead of btMultiBody): 2x faster,
      but the same outliers; PyBullet's split impulse only acts on those.
    * A column width of 1.5 m (17 t columns) gives outliers of 5-20 % with every
      setting tried: the calibration holds for the paper's 0.2-0.8 m.
    """

    solver_iterations: int = 50  # PyBullet default; 10 or 200 measured no better
    contact_erp: float = 0.2  # PyBullet default; acts only beyond the slop
    friction_erp: float | None = None  # auto: contact_erp * min(1, dt / 1e-4), see world.effective_friction_erp
    solver_residual_threshold: float | None = None  # (m/s)^2; auto: 1e-7 * min(1, dt / 1e-4)^2
    contact_slop: float | None = None  # m; auto: min(1e-4, dt * 1 m/s), see world.effective_slop
    contact_breaking_threshold: float | None = None  # auto 1 % of b; 0.02 m no better
    friction_anchor: bool = True  # DESIGN.md; without anchors errors reach 9 %

    def __post_init__(self) -> None:
        super().__post_init__()
        o = "pybullet Settings"
        if (isinstance(self.solver_iterations, bool) or not isinstance(self.solver_iterations, int)
                or not 1 <= self.solver_iterations <= 10_000):
            raise ValueError(f"{o}: solver_iterations must be an integer in [1, 10000], "
                             f"got {self.solver_iterations!r}")
        check_real(o, "contact_erp", self.contact_erp, 0.0, 1.0, lo_open=False)
        if self.contact_slop is not None:
            check_real(o, "contact_slop", self.contact_slop, 0.0, 0.1, lo_open=False)
        if self.friction_erp is not None:
            check_real(o, "friction_erp", self.friction_erp, 0.0, 1.0, lo_open=False)
        if self.solver_residual_threshold is not None:
            check_real(o, "solver_residual_threshold", self.solver_residual_threshold, 0.0, 1.0,
                       lo_open=False)
        if self.contact_breaking_threshold is not None:
            check_real(o, "contact_breaking_threshold", self.contact_breaking_threshold, 0.0, 1.0)
        if not isinstance(self.friction_anchor, bool):
            raise TypeError(f"{o}: friction_anchor must be True or False, "
                            f"got {self.friction_anchor!r}")

    def describe(self) -> dict:
        out = super().describe()
        out["contact_slop_effective"] = world.effective_slop(self)
        out["friction_erp_effective"] = world.effective_friction_erp(self)
        out["solver_residual_threshold_effective"] = world.effective_residual_threshold(self)
        return out


class PyBulletEngine(Engine):
    """PyBullet (Bullet 3D multibodies); the hooks of :class:`engines.base.Engine`."""

    name = "pybullet"
    label = "PyBullet"
    color = "tab:blue"
    regression_point = ("no_pendulum", 12.5)
    impact_variants = (
        ("iterations=10", "fewer PGS iterations", {"solver_iterations": 10}),
        ("iterations=200", "more PGS iterations", {"solver_iterations": 200}),
        ("erp=0.05", "softer position correction", {"contact_erp": 0.05}),
        ("erp=0.8", "stiffer position correction", {"contact_erp": 0.8}),
    )
    impact_fixed = ("restitution (0 on every body: the rocking impact is plastic by "
                    "construction, engines/pybullet_/bodies.py) and split impulse (always "
                    "on, engines/pybullet_/world.py) are fixed, not Settings fields")
    marker = "o"
    capabilities = frozenset({"time_step", "solver_iterations", "render", "gui",
                              "moving_ground", "initial_tilt", "trajectory"})
    # 1, the calibrated value (Settings notes): stronger pulses need more while
    # rocking; at the paper's point D (25 m/s^2 = 2.5 g, with the pendulum)
    # friction 1 lets the pivots slide by 7 mm before the trilith passes alpha,
    # the bound (2.55, times the margin) keeps it below 1 um.  The other kinds
    # (drums, unequal, block_on_block) do not slip at 1 at their strong pulses
    # (8-12 m/s^2, tests/engines/test_kinds_engines.py).
    default_friction = 1.0
    structures = True  # builds any body list (engines.geometry.Structure)
    # `trilith calibrate`'s search beside the step: more solver iterations, a stiffer
    # position correction (defaults first; both within Bullet's documented ranges).
    calibration_space = {"solver_iterations": (50, 100), "contact_erp": (0.2, 0.4)}
    known_failures = {"restitution_eq19_lam7": "Eq. 19 at lam 7: ~1.2 % (first four impacts "
                      "from alpha/2, 2026-11-23): the two columns land one step apart "
                      "(docs/engine-trust.md)"}
    Settings = Settings

    @classmethod
    def version(cls) -> str:
        """PyBullet's version string (the wheel's, plus its API version)."""
        from importlib.metadata import version as _v
        return f"pybullet {_v('pybullet')} (API {pb.getAPIVersion()})"

    def build(self, mode: int = pb.DIRECT) -> None:
        s = self.settings
        self.mode = mode
        self.structure = structure = geometry.structure_of(self.scene, s.theta0, s.psi0)
        self.client = c = world.acquire_client(mode)
        world.configure_client(c, structure, s)
        self.moving = s.base_motion == "ground"
        # An excitation whose window is empty (Still) never loads the bodies.
        exc = self.excitation
        self.bodies = build_scene(c, structure, math.sqrt(self.friction), self.moving,
                                  s.friction_anchor, slop=world.effective_slop(s),
                                  under_load=exc.end_time > exc.start_time)
        self.start_y = {body: pb.getBasePositionAndOrientation(body, physicsClientId=c)[0][1]
                        for body in self.bodies.dynamic}
        if self.moving:
            self._set_ground(0)

    def close(self) -> None:
        """Hand the client back (idempotent): kept for the next run or disconnected."""
        client, self.client = getattr(self, "client", None), None
        if client is not None:
            world.release_client(client, self.mode)

    def _set_ground(self, step: int) -> None:
        x, v = self.ground_motion(step)
        pb.resetJointState(self.bodies.ground, 0, x, v, physicsClientId=self.client)

    def advance(self, steps: int) -> None:
        """One loop with local names: stepping is the hot path (a call per step
        costs ~3 % of the run, ``benchmarks/bench_overhead.py``)."""
        n, c = self.step_index, self.client
        step = pb.stepSimulation
        if self.moving:
            for k in range(n, n + steps):
                self._set_ground(k)
                step(physicsClientId=c)
                self.step_index = k + 1
            return
        load, minus_g, set_gravity = self.base_load, -self.scene.g, pb.setGravity
        try:
            for k in range(n, n + steps):
                set_gravity(load(k), 0.0, minus_g, physicsClientId=c)
                step(physicsClientId=c)
        finally:  # the steps taken, even if one raised
            self.step_index = k + 1 if steps > 0 else n

    def read(self) -> PlaneState:
        c, bodies = self.client, self.bodies
        # Each body is read once per sample: a sample's reads cost about two steps
        # (benchmarks/bench_overhead.py), so re-reading would slow every run.
        poses, drift, roll_yaw = [], 0.0, 0.0
        psi = psi_dot = 0.0
        for body in bodies.boxes:
            read = world.body_state(c, body)
            pos, quat, vel, omega = read
            m = pb.getMatrixFromQuaternion(quat)
            # The box's up axis is the third column of R: (m[2], m[5], m[8]).
            poses.append(Pose(pos[0], pos[2], math.atan2(-m[2], m[8]), vel[0], vel[2],
                              -omega[1]))
            drift, roll_yaw = self._out_of_plane(body, pos, quat, drift, roll_yaw)
            if body == bodies.parent:
                psi, psi_dot = world.pendulum_state(c, bodies, read)
        gx = (pb.getJointState(bodies.ground, 0, physicsClientId=c)[0] if self.moving else 0.0)
        if not self.structure.is_trilith:
            return PlaneState((), None, psi, psi_dot, gx, drift, roll_yaw, bodies=tuple(poses))
        lintel = poses[2] if len(poses) > 2 else None
        return PlaneState((poses[0], poses[1]), lintel, psi, psi_dot, gx, drift, roll_yaw)

    def _out_of_plane(self, body, pos, quat, drift, roll_yaw) -> tuple[float, float]:
        roll, _, yaw = pb.getEulerFromQuaternion(quat)
        return (max(drift, abs(pos[1] - self.start_y[body])),
                max(roll_yaw, abs(roll), abs(yaw)))

    # ------------------------------------------------------------- rendering
    @classmethod
    def render_frames(cls, scene, excitation, times, settings: Settings | None = None,
                      width: int = 320, height: int = 240) -> list[np.ndarray]:
        """RGB ``uint8`` frames ``(height, width, 3)`` of a run at the requested
        ``times`` [s] (headless, ``ER_TINY_RENDERER``).  The run stops at the last time."""
        _trilith_only(scene, "render_frames")
        engine = cls(scene, excitation, settings)
        times = np.asarray(times, dtype=float)
        if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(times < 0.0) or np.any(
                np.diff(times) < 0.0):
            raise ValueError("times must be a 1-D non-decreasing sequence of finite values >= 0 s")
        try:
            width, height = operator.index(width), operator.index(height)
        except TypeError:
            raise ValueError(f"width and height must be integers, got {width!r}, "
                             f"{height!r}") from None
        if not (8 <= width <= 4096 and 8 <= height <= 4096):
            raise ValueError(f"width and height must be in [8, 4096] px, got {width}, {height}")
        dt = engine.settings.dt
        frames = []
        engine.build()
        try:
            span = scene.lintel_length
            view_m = pb.computeViewMatrix((0.5 * span, -1.9 * max(span, scene.h), 0.5 * scene.h),
                                          (0.5 * span, 0.0, 0.5 * scene.h), (0.0, 0.0, 1.0))
            proj = pb.computeProjectionMatrixFOV(40.0, width / height, 0.1,
                                                 100.0 * max(span, scene.h))
            for t in times:
                while engine.step_index * dt < t - 0.5 * dt:
                    engine.advance(1)
                img = pb.getCameraImage(width, height, view_m, proj,
                                        renderer=pb.ER_TINY_RENDERER,
                                        physicsClientId=engine.client)
                rgba = np.reshape(np.asarray(img[2], dtype=np.uint8), (height, width, 4))
                frames.append(rgba[:, :, :3].copy())
        finally:
            engine.close()
        return frames

    @classmethod
    def view(cls, scene, excitation, settings: Settings | None = None,
             duration: float = 10.0) -> None:
        """Open a PyBullet GUI window and run ``scene`` in real time (needs a display)."""
        _trilith_only(scene, "view")
        engine = cls(scene, excitation, settings)
        dt = engine.settings.dt
        engine.build(mode=pb.GUI)
        try:
            span = scene.lintel_length
            pb.resetDebugVisualizerCamera(2.0 * max(span, scene.h), 0.0, -5.0,
                                          (0.5 * span, 0.0, 0.5 * scene.h),
                                          physicsClientId=engine.client)
            wall0 = time.perf_counter()
            while engine.step_index * dt < duration:
                engine.advance(1)
                lag = engine.step_index * dt - (time.perf_counter() - wall0)
                if lag > 0.0:
                    time.sleep(lag)
        finally:
            engine.close()


def _trilith_only(scene, what: str) -> None:
    # The camera is placed from the trilith's lintel length and column height.
    if isinstance(scene, KindScene):
        raise ValueError(f"pybullet {what} draws the parametric trilith only, not the "
                         f"{scene.kind!r} kind")
