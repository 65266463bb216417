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

import dataclasses
import math
import time
from dataclasses import dataclass, field

import pymunk

from analytic.trajectory import OverturnCriterion, Trajectory
from engines._common import MonitorSettings, RunMonitor, required_friction
# Scene building lives in engines.pymunk_scene; _World is re-exported because
# tests and benchmarks/bench_overhead.py build bare worlds through this module.
from engines.pymunk_scene import _World, _peak_ground_speed, _state_reader

__all__ = ["NAME", "Settings", "simulate", "version", "required_friction", "BASE_MOTIONS"]

NAME = "pymunk"
BASE_MOTIONS = ("gravity", "ground")


def version() -> str:
    """Pymunk and Chipmunk versions, e.g. ``'pymunk 7.3.1 (chipmunk 2.0.1)'``."""
    chip = pymunk.chipmunk_version.split("-")[0]
    return f"pymunk {pymunk.version} (chipmunk {chip})"


@dataclass(frozen=True)
class Settings:
    """Numerical settings of the Pymunk backend; defaults are the calibrated ones.

    Parameters
    ----------
    criterion : OverturnCriterion
        Shared overturning criterion (default: topple at 1.5 rad).
    t_max : float or None
        Run length [s]; None lets the monitor stop the run (rest, energy, cap).
    dt : float
        Time step [s].  1e-4 s: restitution error <= 0.15 % (first four impacts,
        lam in {3, 5, 7}); it grows about linearly with dt (0.25 % at 2e-4 s,
        0.8 % at 5e-4 s, 10-24 % at Pymunk's usual 1/60 s).
    theta0, psi0 : float
        Initial tilt [rad] (released at rest; > 0 on the left corners) and
        pendulum angle [rad].
    base_motion : {'gravity', 'ground'}
        How the base excitation is imposed (see module docstring).
    sample_every : int
        Steps between two samples read into the monitor.  20 (2 ms at the default
        ``dt``): impacts are measured by propagating away from them, so 2 ms is
        ample, and reading state is the costliest part of a step in Python (at 10
        the harness ran at 0.77-0.80 of the bare step rate, at 20 at 0.87-0.89,
        benchmarks/bench_overhead.py).
    monitor : MonitorSettings
        Shared stop/verdict thresholds.
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

    criterion: OverturnCriterion = OverturnCriterion()
    t_max: float | None = None
    dt: float = 1e-4
    theta0: float = 0.0
    psi0: float = 0.0
    base_motion: str = "gravity"
    sample_every: int = 20
    monitor: MonitorSettings = field(default_factory=MonitorSettings)
    friction: float = 10.0
    iterations: int = 30
    slop_fraction: float = 1e-4
    collision_bias: float | None = None
    pendulum_radius_fraction: float = 1e-2
    blowup_distance: float = 10.0
    blowup_speed: float = 50.0

    def describe(self) -> dict:
        out = dataclasses.asdict(self)
        out["criterion"] = self.criterion.describe()
        return out


def _validate(scene, excitation, s: Settings) -> None:
    def finite(name, value, lo, hi, lo_open=True):
        ok = isinstance(value, (int, float)) and math.isfinite(value) and (
            value > lo if lo_open else value >= lo) and value <= hi
        if not ok:
            left = "(" if lo_open else "["
            raise ValueError(f"pymunk settings: {name} must be finite in {left}{lo:g}, {hi:g}], "
                             f"got {value!r}")

    finite("dt", s.dt, 0.0, 0.1)
    if s.base_motion not in BASE_MOTIONS:
        raise ValueError(f"pymunk settings: base_motion must be one of {BASE_MOTIONS}, "
                         f"got {s.base_motion!r}")
    if not (isinstance(s.sample_every, int) and 1 <= s.sample_every <= 10_000):
        raise ValueError(f"pymunk settings: sample_every must be an integer in [1, 10000], "
                         f"got {s.sample_every!r}")
    if not (isinstance(s.iterations, int) and 1 <= s.iterations <= 10_000):
        raise ValueError(f"pymunk settings: iterations must be an integer in [1, 10000], "
                         f"got {s.iterations!r}")
    finite("theta0", s.theta0, -scene.alpha, scene.alpha, lo_open=False)
    if abs(s.theta0) >= scene.alpha:
        raise ValueError(f"pymunk settings: theta0 must be in (-alpha, alpha) = "
                         f"(-{scene.alpha:.4g}, {scene.alpha:.4g}) rad, got {s.theta0!r}")
    finite("psi0", s.psi0, -math.pi, math.pi, lo_open=False)
    finite("slop_fraction", s.slop_fraction, 0.0, 0.1)
    if s.collision_bias is not None:
        finite("collision_bias", s.collision_bias, 0.0, 1.0)
    finite("pendulum_radius_fraction", s.pendulum_radius_fraction, 0.0, 1.0)
    finite("blowup_distance", s.blowup_distance, 1.0, 1e6)
    finite("blowup_speed", s.blowup_speed, 1.0, 1e6)
    if s.t_max is not None:
        finite("t_max", s.t_max, 0.0, 1e5)
    if not isinstance(s.criterion, OverturnCriterion):
        raise ValueError(f"pymunk settings: criterion must be an OverturnCriterion, "
                         f"got {type(s.criterion).__name__}")
    if not isinstance(s.monitor, MonitorSettings):
        raise ValueError(f"pymunk settings: monitor must be a MonitorSettings, "
                         f"got {type(s.monitor).__name__}")
    finite("friction", s.friction, 0.0, 1e3)
    need = required_friction(scene, excitation)
    if s.friction < need:
        raise ValueError(f"pymunk settings: friction must be >= {need:.3g} for rocking without "
                         f"sliding in this scene and excitation (see required_friction), "
                         f"got {s.friction!r}")


# -------------------------------------------------------------------------- simulate
def simulate(scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Run ``scene`` under ``excitation`` in Pymunk; returns a :class:`Trajectory`.

    Raises ``ValueError`` for bad settings before any stepping (see
    :class:`Settings` and :func:`required_friction`).  A blown-up run (non-finite
    state, a body flown away or too fast) gets the verdict ``'unstable'``.
    """
    s = settings if settings is not None else Settings()
    if not isinstance(s, Settings):
        raise ValueError(f"pymunk settings must be engines.pymunk_engine.Settings, "
                         f"got {type(s).__name__}")
    if scene.mu == 0.0 and scene.has_pendulum:
        raise ValueError("pymunk: mu must be > 0 when gamma > 0 (a massless lintel, which the "
                         "analytic model allows, cannot carry the pendulum hinge in an engine)")
    _validate(scene, excitation, s)
    wall0 = time.perf_counter()
    world = _World(scene, s)
    monitor = RunMonitor(scene, excitation, s.criterion, s.t_max, s.monitor)
    space, dt, g = world.space, s.dt, scene.g
    cols, lintel, bob = world.columns, world.lintel, world.bob
    b, h = scene.b, scene.h
    gravity_mode = s.base_motion == "gravity"
    max_dist = s.blowup_distance * world.size
    max_speed = s.blowup_speed * (math.sqrt(g * world.size) + _peak_ground_speed(excitation))
    corner_x0 = [(x, x + b) for x in world.x_left]
    # Contact diagnostics over the rocking regime |theta| < alpha (what the analytic
    # model describes) and over the whole run (a falling column's contacts reshape).
    lintel_rot = slide = penetration = slide_all = penetration_all = 0.0
    alpha = scene.alpha
    step = 0
    n_sub = s.sample_every
    step_space = space.step
    accel = excitation.acceleration
    # After the pulse gravity stays (0, -g): stop setting it (a C call per step).
    t_gravity_off = excitation.end_time + dt
    done = False
    read_state = _state_reader(world)
    i_lintel = world.bodies.index(lintel) if lintel is not None else None
    i_bob = world.bodies.index(bob) if bob is not None else None
    hb, hh = 0.5 * b, 0.5 * h
    cos, sin, hypot = math.cos, math.sin, math.hypot
    starts = [(6 * i, x0, y0) for i, (x0, y0) in enumerate(world.start)]
    while True:
        t = step * dt
        x_ground = 0.0 if gravity_mode else excitation.displacement(t)
        st = read_state()  # per body: x, y, angle, vx, vy, omega (columns first)
        angles = (st[2], st[8])
        psi = s.psi0 + st[6 * i_bob + 2] if bob is not None else 0.0
        psi_dot = st[6 * i_bob + 5] if bob is not None else 0.0
        theta_dot = 0.5 * (st[5] + st[11])
        done = monitor.record(t, angles[0], angles[1], theta_dot, psi, psi_dot)
        in_well = abs(angles[0] + angles[1]) < 2.0 * alpha
        for k in (0, 1):
            # Bottom corners (-+b/2, -h/2) in the world, as Body.local_to_world
            # (Chipmunk's rigid transform of the centred box: rotate, then add p).
            px, py, angle = st[6 * k], st[6 * k + 1], angles[k]
            ca, sa = cos(angle), sin(angle)
            left_x, left_y = ca * -hb + -sa * -hh + px, sa * -hb + ca * -hh + py
            right_x, right_y = ca * hb + -sa * -hh + px, sa * hb + ca * -hh + py
            # The pivot is the corner on the side the column leans to.
            pivot_x, x0 = ((left_x, corner_x0[k][0]) if angle >= 0.0
                           else (right_x, corner_x0[k][1]))
            sl = abs(pivot_x - x0 - x_ground)
            pen = -(right_y if right_y < left_y else left_y)  # = -min(left_y, right_y)
            # Running maxima as comparisons (= max(), without a builtin call each).
            if sl > slide_all:
                slide_all = sl
            if pen > penetration_all:
                penetration_all = pen
            if in_well:
                if sl > slide:
                    slide = sl
                if pen > penetration:
                    penetration = pen
        if i_lintel is not None and in_well:
            lintel_rot = max(lintel_rot, abs(st[6 * i_lintel + 2]))
        if not done:
            for i, x0, y0 in starts:
                if hypot(st[i] - x0 - x_ground, st[i + 1] - y0) > max_dist:
                    monitor.mark_unstable(t, "a body flew away (> "
                                          f"{s.blowup_distance:g} trilith sizes)")
                    done = True
                    break
                if hypot(st[i + 3], st[i + 4]) > max_speed:
                    monitor.mark_unstable(t, f"a body exceeded {max_speed:.3g} m/s")
                    done = True
                    break
        if done:
            break
        if gravity_mode:  # the step loop is the hot path: one branch per sample
            for _ in range(n_sub):
                t = step * dt
                if t <= t_gravity_off:
                    space.gravity = (-accel(t + 0.5 * dt), -g)
                step_space(dt)
                step += 1
        else:
            for _ in range(n_sub):
                t = step * dt
                # Mean ground velocity over the step: the position follows exactly.
                vx = (excitation.displacement(t + dt) - excitation.displacement(t)) / dt
                world.ground.velocity = (vx, 0.0)
                step_space(dt)
                step += 1
    diagnostics = {"lintel_rotation_max": lintel_rot, "pivot_sliding_max": slide,
                   "penetration_max": penetration, "pivot_sliding_max_all": slide_all,
                   "penetration_max_all": penetration_all, "steps": step,
                   "required_friction": required_friction(scene, excitation)}
    wall = time.perf_counter() - wall0
    diagnostics["wall_time"] = wall
    settings_dict = s.describe()
    settings_dict["engine_version"] = version()
    return monitor.finish(NAME, settings_dict, diagnostics, wall)
