"""Pymunk (Chipmunk2D): the trilith as three rigid polygons on a ground box.

The plane scene is built from the :class:`~analytic.parameters.Scene` only
(:mod:`engines.geometry`, in :mod:`engines.pymunk_.world`): two ``b x h``
columns, a ``lintel_length x lintel_thickness`` lintel resting on both column
tops, and a point-like pendulum bob hinged on the lintel underside with a
:class:`pymunk.PivotJoint`; the bob collides with nothing, like the analytic
pendulum (Eq. 1, 8).  ``gamma = 0`` builds no pendulum body, ``mu = 0`` no
lintel: the two columns rock independently, which is the ``mu = 0`` rocking
frame (Eq. 8 and 20 with ``mu = 0`` are a single column's equations).

Base motion: ``"gravity"`` sets the d'Alembert load as gravity's x component
before each step; ``"ground"`` moves a kinematic ground box.  Pymunk's y axis
points up and angles are counter-clockwise: a body's state is already in the
analytic plane; ``psi`` is ``psi0`` plus the bob's rotation.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import pymunk

from trilith_xval.analytic.options import check_real
from trilith_xval.engines.base import Engine, EngineSettings
from trilith_xval.engines.diagnostics import PlaneState, Pose

from .world import build_space, state_reader

__all__ = ["PymunkEngine", "Settings"]


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Numerical settings of the Pymunk backend; defaults are the calibrated ones.

    The run options and engine fields (``criterion``, ``t_max``, ``theta0``,
    ``psi0``, ``early_stop``, ``dt``, ``base_motion``, ``sample_every``,
    ``monitor``) are :class:`engines.base.EngineSettings`; their defaults hold.
    ``dt`` 1e-4 s: restitution error <= 0.24 % (first four impacts, lam in
    {3, 5, 7}); it grows about linearly with dt (0.25 % at 2e-4 s, 0.8 % at
    5e-4 s, 10-24 % at Pymunk's usual 1/60 s).

    Parameters
    ----------
    friction : float or None
        Coulomb coefficient at every contact.  Pymunk multiplies the two shapes'
        values, so each shape gets ``sqrt(friction)``.  None: ``max(10, 1.2
        required_friction)`` (:class:`engines.base.EngineSettings`).  10 is
        above the no-sliding bound for any pulse up to 81 m/s^2 (point D needs
        2.55); measured restitution is the same to 1e-5 for 1.1, 3 and 10, so
        headroom costs nothing.
    iterations : int
        Solver iterations per step.  30: the stacked contacts (ground-column-
        lintel) and the pendulum joint need more than Chipmunk's default 10
        (which gives 3.4 % restitution error at lam = 3); 30 and 100 give the
        same ratios to 1e-5.
    slop_fraction : float
        ``space.collision_slop`` as a fraction of the column width ``b``.  1e-4
        (60 um at b = 0.6 m): just above the contacts' own penetration (~30 um),
        so Chipmunk's position correction stays idle.  At 1e-5 b it fights that
        penetration every step and about one impact in five on lam = 3 came out
        4-6 % too elastic (column and lintel impacts out of step).  Pymunk's
        default 0.1 m gives the same ratios but would let a corner sink 0.1 m.
    collision_bias : float or None
        Fraction of overlap left uncorrected after one second; None keeps
        Pymunk's default ``0.9**60`` (position correction is then gentle enough
        not to inject energy at impacts).
    pendulum_radius_fraction : float
        The bob's radius of gyration as a fraction of ``l`` (own inertia
        ``m4 (f l)^2``).  1e-2: a point mass within 1e-4 of the pendulum's
        inertia, yet not so small that the joint rows become ill-conditioned.
    """

    iterations: int = 30
    slop_fraction: float = 1e-4
    collision_bias: float | None = None
    pendulum_radius_fraction: float = 1e-2

    @property
    def solver_iterations(self) -> int:
        """The contract's name for ``iterations`` (convergence studies double it)."""
        return self.iterations

    def with_solver_iterations(self, n: int) -> Settings:
        return dataclasses.replace(self, iterations=n)

    def __post_init__(self) -> None:
        super().__post_init__()
        o = "pymunk Settings"
        if (isinstance(self.iterations, bool) or not isinstance(self.iterations, int)
                or not 1 <= self.iterations <= 10_000):
            raise ValueError(f"{o}: iterations must be an integer in [1, 10000], "
                             f"got {self.iterations!r}")
        check_real(o, "slop_fraction", self.slop_fraction, 0.0, 0.1)
        if self.collision_bias is not None:
            check_real(o, "collision_bias", self.collision_bias, 0.0, 1.0)
        check_real(o, "pendulum_radius_fraction", self.pendulum_radius_fraction, 0.0, 1.0)


class PymunkEngine(Engine):
    """Pymunk (Chipmunk2D 2D rigid bodies); the hooks of :class:`engines.base.Engine`."""

    name = "pymunk"
    label = "Pymunk"
    color = "tab:orange"
    marker = "s"
    capabilities = frozenset({"time_step", "solver_iterations", "moving_ground",
                              "initial_tilt", "trajectory", "free_block"})
    default_friction = 10.0
    structures = True  # builds any body list (engines.geometry.Structure)
    # `trilith calibrate`'s search beside the step: more iterations, a ten times looser
    # collision slop (defaults first).
    calibration_space = {"iterations": (30, 60), "slop_fraction": (1e-4, 1e-3)}
    impact_variants = (
        ("iterations=10", "Chipmunk's default iterations", {"iterations": 10}),
        ("iterations=100", "more iterations", {"iterations": 100}),
        ("slop=1e-3", "collision slop x10", {"slop_fraction": 1e-3}),
        ("slop=1e-2", "collision slop x100", {"slop_fraction": 1e-2}),
    )
    impact_fixed = "elasticity (0 on every shape, engines/pymunk_/world.py) is fixed"
    Settings = Settings

    @classmethod
    def free_block(cls, *args, settings=None):
        """A free planar block started in flight (:mod:`.free_block`), at
        ``settings`` (default: the calibrated defaults)."""
        from .free_block import free_block
        return free_block(*args, cls.Settings() if settings is None else settings)

    @classmethod
    def version(cls) -> str:
        """Pymunk and Chipmunk versions, e.g. ``'pymunk 7.3.1 (chipmunk 2.0.1)'``."""
        chip = pymunk.chipmunk_version.split("-")[0]
        return f"pymunk {pymunk.version} (chipmunk {chip})"

    def build(self) -> None:
        self.world = build_space(self.scene, self.settings, self.friction)
        self._read_state = state_reader(self.world)

    def advance(self, steps: int) -> None:
        space, dt, step_space = self.world.space, self.settings.dt, self.world.space.step
        n = self.step_index
        if self.settings.base_motion == "gravity":
            minus_g, load, end = -self.scene.g, self.base_load, self._load_end
            for k in range(n, n + steps):
                if k <= end:  # after the pulse the load stays 0 (a C call saved per step)
                    space.gravity = (load(k), minus_g)
                step_space(dt)
        else:
            ground, motion = self.world.ground, self.ground_motion
            for k in range(n, n + steps):
                ground.velocity = (motion(k)[1], 0.0)
                step_space(dt)
        self.step_index = n + steps

    def read(self) -> PlaneState:
        st = self._read_state()  # per body: x, y, angle, vx, vy, omega (structure order)
        n = len(self.world.boxes)
        poses = tuple(Pose(*st[6 * k:6 * k + 6]) for k in range(n))
        psi = psi_dot = 0.0
        if self.world.bob is not None:
            i = 6 * n
            psi, psi_dot = self.settings.psi0 + st[i + 2], st[i + 5]
        gx = (0.0 if self.settings.base_motion == "gravity"
              else self.excitation.displacement(self.step_index * self.settings.dt))
        if not self.world.structure.is_trilith:
            return PlaneState((), None, psi, psi_dot, gx, bodies=poses)
        lintel = poses[2] if n > 2 else None
        return PlaneState(poses[:2], lintel, psi, psi_dot, gx)
