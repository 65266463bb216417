"""Pymunk (Chipmunk2D) backend: the trilith as three rigid polygons on a ground box.

The adapter (settings, validation, the stepping loop); the world itself is built
in :mod:`engines.pymunk_scene`.

The plane scene is built from the :class:`~analytic.parameters.Scene` only: two
``b x h`` columns at clear gap ``d`` (left column's bottom-left corner at ``x = 0``),
a ``lintel_length x lintel_thickness`` lintel resting on both column tops, and a
point-like pendulum bob hinged on the lintel underside with a
:class:`pymunk.PivotJoint`; the bob collides with nothing, like the analytic
pendulum (Eq. 1, 8).  ``gamma = 0`` builds no pendulum body.  ``mu = 0`` builds no
lintel body: the two columns rock independently, which is the ``mu = 0`` rocking
frame (Eq. 8 and 20 with ``mu = 0`` are a single column's equations because the
columns are equal and start in phase); ``mu = 0`` with a pendulum is refused
(a massless lintel cannot carry the hinge in an engine).

Base motion (``Settings.base_motion``): ``"gravity"`` imposes ``-xg_ddot(t)`` as a
horizontal gravity component in the base frame (d'Alembert, exact for a rigid
translating base); ``"ground"`` moves a kinematic ground box along
``excitation.displacement``.  The run is stopped and judged by
:class:`engines._common.RunMonitor` (shared with every engine).

Diagnostics (``Trajectory.diagnostics``): ``lintel_rotation_max`` [rad],
``pivot_sliding_max`` [m] (horizontal drift of the pivot corners relative to the
ground), ``penetration_max`` [m] (depth of the base corners below the ground
top), all over the rocking regime ``|theta| < alpha`` that the analytic model
describes; ``*_all`` variants over the whole run (a column lying down near the
topple angle reshapes its contacts with the lintel and may slide), ``steps``,
``wall_time`` [s], ``required_friction`` and the monitor's column mismatch.

Signs: Pymunk's y axis points up and angles are counter-clockwise, so a column's
rotation angle is ``theta`` directly (``theta > 0``: leaning left on the left
corners); ``psi`` is the bob's angle about the hinge from the downward vertical.
"""
from __future__ import annotations

from dataclasses import dataclass

import pymunk

from analytic.options import check_real
from analytic.trajectory import Trajectory
from engines._common import required_friction
from engines.base import BASE_MOTIONS, EngineSettings, check_run, simulate_world
# Scene building lives in engines.pymunk_scene; _World is re-exported because
# tests and benchmarks/bench_overhead.py build bare worlds through this module.
from engines.pymunk_scene import World, _World  # noqa: F401

__all__ = ["NAME", "Settings", "simulate", "version", "required_friction", "BASE_MOTIONS",
           "CAPABILITIES"]

NAME = "pymunk"
CAPABILITIES = frozenset({"time_step", "solver_iterations", "moving_ground", "initial_tilt",
                          "trajectory"})


def version() -> str:
    """Pymunk and Chipmunk versions, e.g. ``'pymunk 7.3.1 (chipmunk 2.0.1)'``."""
    chip = pymunk.chipmunk_version.split("-")[0]
    return f"pymunk {pymunk.version} (chipmunk {chip})"


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
    friction : float
        Coulomb coefficient at every contact.  Pymunk multiplies the two shapes'
        values, so each shape gets ``sqrt(friction)``.  10: above the no-sliding
        bound :func:`required_friction` for any pulse up to 98 m/s^2 (10 g, past
        the paper's spectra; point D needs 2.55); measured restitution is the
        same to 1e-5 for 1.1, 3 and 10, so headroom costs nothing.
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
    blowup_distance : float
        A body farther than this many trilith sizes from its start marks the
        run unstable.  10: as the engine contract states.
    blowup_speed : float
        Speed bound [m/s] as a multiple of ``sqrt(g * size) + peak ground speed``.
        50: a toppling column's tip never exceeds ``~2 sqrt(g size)``.
    """

    friction: float = 10.0
    iterations: int = 30
    slop_fraction: float = 1e-4
    collision_bias: float | None = None
    pendulum_radius_fraction: float = 1e-2
    blowup_distance: float = 10.0
    blowup_speed: float = 50.0

    @property
    def solver_iterations(self) -> int:
        """The contract's name for ``iterations`` (convergence studies double it)."""
        return self.iterations

    def __post_init__(self) -> None:
        super().__post_init__()
        o = "pymunk Settings"
        if (isinstance(self.iterations, bool) or not isinstance(self.iterations, int)
                or not 1 <= self.iterations <= 10_000):
            raise ValueError(f"{o}: iterations must be an integer in [1, 10000], "
                             f"got {self.iterations!r}")
        check_real(o, "friction", self.friction, 0.0, 1e3)
        check_real(o, "slop_fraction", self.slop_fraction, 0.0, 0.1)
        if self.collision_bias is not None:
            check_real(o, "collision_bias", self.collision_bias, 0.0, 1.0)
        check_real(o, "pendulum_radius_fraction", self.pendulum_radius_fraction, 0.0, 1.0)
        check_real(o, "blowup_distance", self.blowup_distance, 1.0, 1e6)
        check_real(o, "blowup_speed", self.blowup_speed, 1.0, 1e6)


def _validate(scene, excitation, s: Settings) -> None:
    """Checks that need the scene, before anything is built."""
    check_run(NAME, Settings, s, scene, excitation)


# -------------------------------------------------------------------------- simulate
def simulate(scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Run ``scene`` under ``excitation`` in Pymunk; returns a :class:`Trajectory`.

    Raises ``ValueError`` for bad settings before any stepping (see
    :class:`Settings` and :func:`required_friction`).  A blown-up run (non-finite
    state, a body flown away or too fast) gets the verdict ``'unstable'``.
    """
    s = settings if settings is not None else Settings()
    _validate(scene, excitation, s)
    info = s.describe()
    info["engine_version"] = version()

    def make_world() -> World:
        world = World(scene, s, excitation)
        world.diag["required_friction"] = required_friction(scene, excitation)
        return world

    return simulate_world(NAME, make_world, scene, excitation, s, info)
