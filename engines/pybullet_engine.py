"""PyBullet (3D) backend: the trilith as boxes on a box ground, the pendulum as a
revolute link of the lintel (scene building in :mod:`engines.pybullet_scene`).

Contract (``engines/__init__.py``): ``NAME``, ``version()``, ``Settings``,
``simulate(scene, excitation, settings) -> Trajectory``; plus
:func:`render_frames` (headless RGB frames for recordings) and :func:`view`
(GUI window, real time).

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

import operator
import time
from dataclasses import dataclass

import numpy as np
from engines._quiet_pybullet import pybullet as pb

from analytic.options import check_real
from analytic.trajectory import Trajectory
from engines._common import required_friction
from engines import pybullet_scene as ps
from engines.base import BASE_MOTIONS, EngineSettings, check_run, simulate_world

__all__ = ["NAME", "Settings", "simulate", "version", "render_frames", "view",
           "required_friction", "default_friction", "BASE_MOTIONS", "CAPABILITIES"]

NAME = "pybullet"
CAPABILITIES = frozenset({"time_step", "solver_iterations", "render", "gui", "moving_ground",
                          "initial_tilt", "trajectory"})


def version() -> str:
    """PyBullet's version string (the wheel's, plus its API version)."""
    from importlib.metadata import version as _v

    return f"pybullet {_v('pybullet')} (API {pb.getAPIVersion()})"


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Numerical settings of a PyBullet run; defaults are the calibrated ones.

    The run options and engine fields (``criterion``, ``t_max``, ``theta0``,
    ``psi0``, ``early_stop``, ``dt``, ``base_motion``, ``sample_every``,
    ``monitor``) are :class:`engines.base.EngineSettings`; the defaults hold
    here (``dt`` 1e-4 s: 5e-5 measured no better at twice the cost).

    Parameters
    ----------
    friction : Coulomb coefficient of every contact; None: :func:`default_friction`.
        Bullet combines the two bodies' values by product, so each body gets
        ``sqrt(friction)``.  Must be >= :func:`required_friction`.
    solver_iterations : sequential-impulse iterations per step.
    contact_erp : Baumgarte factor for penetrations deeper than ``contact_slop``.
    contact_slop : penetration [m] left uncorrected (Bullet's ``contactSlop``).
    contact_breaking_threshold : distance [m] within which contact points are
        kept; None: 1 % of the column width.
    friction_anchor : Bullet's friction anchors (contacts stick in place).
    out_of_plane_limit : out-of-plane drift, as a fraction of the trilith size,
        beyond which a standing trilith is flagged unstable.

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

    friction: float | None = None  # auto: max(1, required_friction), see default_friction
    solver_iterations: int = 50  # PyBullet default; 10 or 200 measured no better
    contact_erp: float = 0.2  # PyBullet default; acts only beyond the slop
    friction_erp: float | None = None  # auto: contact_erp * min(1, dt / 1e-4), see pybullet_scene
    solver_residual_threshold: float | None = None  # (m/s)^2; auto: 1e-7 * min(1, dt / 1e-4)^2
    contact_slop: float | None = None  # m; auto: min(1e-4, dt * 1 m/s), see pybullet_scene.effective_slop
    contact_breaking_threshold: float | None = None  # auto 1 % of b; 0.02 m no better
    friction_anchor: bool = True  # DESIGN.md; without anchors errors reach 9 %
    out_of_plane_limit: float = 0.1  # fraction of the size: far beyond the 1e-5 m noise

    def __post_init__(self) -> None:
        super().__post_init__()
        o = "pybullet Settings"
        if self.friction is not None:
            check_real(o, "friction", self.friction, 0.0, 1e3)
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
        check_real(o, "out_of_plane_limit", self.out_of_plane_limit, 0.0, 10.0)

    def describe(self) -> dict:
        out = super().describe()
        out["contact_slop_effective"] = ps.effective_slop(self)
        out["friction_erp_effective"] = ps.effective_friction_erp(self)
        out["solver_residual_threshold_effective"] = ps.effective_residual_threshold(self)
        return out


def default_friction(scene, excitation) -> float:
    """``max(1, required_friction)`` (in practice ``max(1, peak |xg_ddot| / g)``,
    the shared bound's usual largest term): 1 is the calibrated value (DESIGN.md and
    the :class:`Settings` notes); stronger pulses need more while rocking: at
    the paper's point D (25 m/s^2 = 2.5 g, with the pendulum) friction 1 lets
    the pivots slide by 7 mm before the trilith passes alpha; the default 2.55
    keeps it below 1 um (without the pendulum 1 already does, since the bodies
    start on their contacts, see ``pybullet_scene.build_scene``; before that
    fix the early landing made it slide 2.5-9 mm).  ``peak/g`` is what the
    trilith would need to follow the peak acceleration while resting, a simple
    bound on the rocking demand."""
    return max(1.0, required_friction(scene, excitation))


def _validate(scene, excitation, s: Settings) -> float:
    """Checks that need the scene, before any stepping; returns the friction to use."""
    own = s.friction if isinstance(s, Settings) else None  # check_run refuses other types
    friction = default_friction(scene, excitation) if own is None else own
    return check_run(NAME, Settings, s, scene, excitation, friction)


def simulate(scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Run ``scene`` under ``excitation`` in PyBullet; returns a :class:`Trajectory`.

    Raises ``ValueError`` for bad settings before any stepping.  A blow-up (NaN,
    bodies flying away, out-of-plane drift) gives the verdict ``'unstable'``.
    """
    s = settings if settings is not None else Settings()
    friction = _validate(scene, excitation, s)
    info = s.describe()
    info["friction_used"] = friction
    info["engine_version"] = version()
    return simulate_world(NAME, lambda: ps.World(scene, excitation, s, friction), scene,
                          excitation, s, info)


def render_frames(scene, excitation, times, settings: Settings | None = None,
                  width: int = 320, height: int = 240) -> list[np.ndarray]:
    """RGB ``uint8`` frames ``(height, width, 3)`` of a run at the requested
    ``times`` [s] (headless, ``ER_TINY_RENDERER``).  The run stops at the last time."""
    s = settings if settings is not None else Settings()
    friction = _validate(scene, excitation, s)
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or not np.all(np.isfinite(times)) or np.any(times < 0.0) or np.any(
            np.diff(times) < 0.0):
        raise ValueError("times must be a 1-D non-decreasing sequence of finite values >= 0 s")
    try:
        width, height = operator.index(width), operator.index(height)
    except TypeError:
        raise ValueError(f"width and height must be integers, got {width!r}, {height!r}") from None
    if not (8 <= width <= 4096 and 8 <= height <= 4096):
        raise ValueError(f"width and height must be in [8, 4096] px, got {width}, {height}")
    world = ps.World(scene, excitation, s, friction)
    frames = []
    try:
        span = scene.lintel_length
        view_m = pb.computeViewMatrix((0.5 * span, -1.9 * max(span, scene.h), 0.5 * scene.h),
                                      (0.5 * span, 0.0, 0.5 * scene.h), (0.0, 0.0, 1.0))
        proj = pb.computeProjectionMatrixFOV(40.0, width / height, 0.1, 100.0 * max(span, scene.h))
        for t in times:
            while world.step_index * s.dt < t - 0.5 * s.dt:
                world.step()
            img = pb.getCameraImage(width, height, view_m, proj, renderer=pb.ER_TINY_RENDERER,
                                    physicsClientId=world.client)
            rgba = np.reshape(np.asarray(img[2], dtype=np.uint8), (height, width, 4))
            frames.append(rgba[:, :, :3].copy())
    finally:
        world.close()
    return frames


def view(scene, excitation, settings: Settings | None = None, duration: float = 10.0) -> None:
    """Open a PyBullet GUI window and run ``scene`` in real time (needs a display)."""
    s = settings if settings is not None else Settings()
    friction = _validate(scene, excitation, s)
    world = ps.World(scene, excitation, s, friction, mode=pb.GUI)
    try:
        span = scene.lintel_length
        pb.resetDebugVisualizerCamera(2.0 * max(span, scene.h), 0.0, -5.0,
                                      (0.5 * span, 0.0, 0.5 * scene.h),
                                      physicsClientId=world.client)
        wall0 = time.perf_counter()
        while world.step_index * s.dt < duration:
            world.step()
            lag = world.step_index * s.dt - (time.perf_counter() - wall0)
            if lag > 0.0:
                time.sleep(lag)
    finally:
        world.close()
