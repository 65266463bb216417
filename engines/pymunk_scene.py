"""Pymunk scene building for :mod:`engines.pymunk_engine`: the trilith's bodies and
state reading.

:class:`_World` builds a fresh :class:`pymunk.Space` from the
:class:`~analytic.parameters.Scene` (geometry and the ``mu = 0`` / ``gamma = 0``
cases are described in :mod:`engines.pymunk_engine`); :func:`_state_reader`
reads every body's state in one call per sample.  Split from the adapter only to
keep modules short; the simulation loop stays in :mod:`engines.pymunk_engine`.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import pymunk

if TYPE_CHECKING:  # annotation only: the adapter imports this module
    from engines.pymunk_engine import Settings

__all__ = ["World", "_World", "_state_reader", "_peak_ground_speed"]

def _rotate(v: tuple[float, float], angle: float) -> tuple[float, float]:
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _column_com(x_left: float, theta: float, b: float, h: float) -> tuple[float, float]:
    """Centre of a column tilted by ``theta`` about the base corner of its side."""
    if theta >= 0.0:  # left corner at (x_left, 0) stays put
        r = _rotate((0.5 * b, 0.5 * h), theta)
        return (x_left + r[0], r[1])
    r = _rotate((-0.5 * b, 0.5 * h), theta)
    return (x_left + b + r[0], r[1])


def _lintel_shift(theta: float, b: float, h: float) -> tuple[float, float]:
    """Translation of the lintel: that of the column-top corner it rests on
    (top-right corners for ``theta > 0``, top-left ones for ``theta < 0``)."""
    corner = (b, h) if theta >= 0.0 else (-b, h)
    r = _rotate(corner, theta)
    return (r[0] - corner[0], r[1] - corner[1])


class World:
    """A fresh Pymunk space holding one trilith; nothing is shared between runs.

    The engine side of the contract (:class:`engines.base.World`): ``advance``
    steps the space, ``sample`` reads every body once and updates the contact
    diagnostics in ``diag`` (over the rocking regime ``|theta| < alpha`` that the
    analytic model describes, and ``*_all`` over the whole run).
    """

    def __init__(self, scene, s: Settings, excitation=None) -> None:
        b, h, d = scene.b, scene.h, scene.d
        t_l = scene.lintel_thickness
        self.size = max(scene.lintel_length, h + t_l)
        space = pymunk.Space()
        space.iterations = s.iterations
        space.collision_slop = s.slop_fraction * b
        if s.collision_bias is not None:
            space.collision_bias = s.collision_bias
        space.gravity = (0.0, -scene.g)
        shape_friction = math.sqrt(s.friction)  # Pymunk multiplies the pair's values

        def add_box(body, w, hh):
            shape = pymunk.Poly.create_box(body, (w, hh), radius=0.0)
            shape.friction = shape_friction
            shape.elasticity = 0.0
            space.add(shape)
            return shape

        kind = pymunk.Body.KINEMATIC if s.base_motion == "ground" else pymunk.Body.STATIC
        self.ground = pymunk.Body(body_type=kind)
        # A box, not a segment: its top face is one flat edge under both columns.
        ground_w = scene.lintel_length + 2.0 * self.size
        ground_t = max(b, 0.1 * self.size)
        self.ground.position = (0.5 * scene.lintel_length, -0.5 * ground_t)
        space.add(self.ground)
        add_box(self.ground, ground_w, ground_t)

        th = s.theta0
        self.columns = []
        self.x_left = (0.0, b + d)
        for x_left in self.x_left:
            body = pymunk.Body(scene.m1, scene.inertia_J_G)
            body.position = _column_com(x_left, th, b, h)
            body.angle = th
            space.add(body)
            add_box(body, b, h)
            self.columns.append(body)

        shift = _lintel_shift(th, b, h)
        self.lintel = None
        self.bob = None
        if scene.mu > 0.0:
            length = scene.lintel_length
            lintel = pymunk.Body(scene.m3, scene.m3 * (length ** 2 + t_l ** 2) / 12.0)
            lintel.position = (0.5 * length + shift[0], h + 0.5 * t_l + shift[1])
            space.add(lintel)
            add_box(lintel, length, t_l)
            self.lintel = lintel
        if scene.has_pendulum:
            l = scene.pendulum_length
            hinge = (0.5 * scene.lintel_length + scene.hinge_x + shift[0], h + shift[1])
            radius = s.pendulum_radius_fraction * l
            bob = pymunk.Body(scene.m4, scene.m4 * radius ** 2)
            bob.position = (hinge[0] + l * math.sin(s.psi0), hinge[1] - l * math.cos(s.psi0))
            space.add(bob)
            dot = pymunk.Circle(bob, radius)
            dot.filter = pymunk.ShapeFilter(categories=0, mask=0)  # collides with nothing
            space.add(dot)
            anchor_bob = (hinge[0] - bob.position.x, hinge[1] - bob.position.y)
            # The bob's body is the rod: its rotation is the pendulum's (psi - psi0).
            joint = pymunk.PivotJoint(self.lintel, bob, (scene.hinge_x, -0.5 * t_l), anchor_bob)
            joint.collide_bodies = False
            space.add(joint)
            self.bob = bob
        self.space = space
        self.bodies = [c for c in self.columns] + [x for x in (self.lintel, self.bob) if x]
        self.start = [(bd.position.x, bd.position.y) for bd in self.bodies]
        self.scene, self.s, self.excitation = scene, s, excitation
        self.step_index = 0
        self.diag = dict(lintel_rotation_max=0.0, pivot_sliding_max=0.0, penetration_max=0.0,
                         pivot_sliding_max_all=0.0, penetration_max_all=0.0)
        if excitation is not None:
            self._prepare_run(excitation)

    # ------------------------------------------------------------ the run loop
    def _prepare_run(self, excitation) -> None:
        """Constants of the per-sample reads (the hot path reads them once)."""
        scene, s = self.scene, self.s
        self._read_state = _state_reader(self)
        self._i_lintel = self.bodies.index(self.lintel) if self.lintel is not None else None
        self._i_bob = self.bodies.index(self.bob) if self.bob is not None else None
        self._corner_x0 = [(x, x + scene.b) for x in self.x_left]
        self._starts = [(6 * i, x0, y0) for i, (x0, y0) in enumerate(self.start)]
        self._max_dist = s.blowup_distance * self.size
        self._max_speed = s.blowup_speed * (math.sqrt(scene.g * self.size)
                                            + _peak_ground_speed(excitation))
        # After the pulse gravity stays (0, -g): stop setting it (a C call per step).
        self._t_gravity_off = excitation.end_time + s.dt

    def close(self) -> None:
        """Nothing to release (the space is garbage-collected)."""

    def advance(self, count: int) -> None:
        """``count`` steps; the base motion is imposed before each (mid-step load)."""
        space, dt, step_space = self.space, self.s.dt, self.space.step
        excitation, step = self.excitation, self.step_index
        if self.s.base_motion == "gravity":  # the step loop is the hot path
            accel, g, t_off = excitation.acceleration, self.scene.g, self._t_gravity_off
            for _ in range(count):
                t = step * dt
                if t <= t_off:
                    space.gravity = (-accel(t + 0.5 * dt), -g)
                step_space(dt)
                step += 1
        else:
            for _ in range(count):
                t = step * dt
                # Mean ground velocity over the step: the position follows exactly.
                vx = (excitation.displacement(t + dt) - excitation.displacement(t)) / dt
                self.ground.velocity = (vx, 0.0)
                step_space(dt)
                step += 1
        self.step_index = step

    def sample(self) -> tuple[float, float, float, float, float, str | None]:
        """``(theta_left, theta_right, theta_dot, psi, psi_dot, problem)``; updates ``diag``."""
        s, diag = self.s, self.diag
        t = self.step_index * s.dt
        x_ground = 0.0 if s.base_motion == "gravity" else self.excitation.displacement(t)
        st = self._read_state()  # per body: x, y, angle, vx, vy, omega (columns first)
        angles = (st[2], st[8])
        i_bob = self._i_bob
        psi = s.psi0 + st[6 * i_bob + 2] if i_bob is not None else 0.0
        psi_dot = st[6 * i_bob + 5] if i_bob is not None else 0.0
        theta_dot = 0.5 * (st[5] + st[11])
        in_well = abs(angles[0] + angles[1]) < 2.0 * self.scene.alpha
        hb, hh = 0.5 * self.scene.b, 0.5 * self.scene.h
        cos, sin = math.cos, math.sin
        for k in (0, 1):
            # Bottom corners (-+b/2, -h/2) in the world, as Body.local_to_world
            # (Chipmunk's rigid transform of the centred box: rotate, then add p).
            px, py, angle = st[6 * k], st[6 * k + 1], angles[k]
            ca, sa = cos(angle), sin(angle)
            left_x, left_y = ca * -hb + -sa * -hh + px, sa * -hb + ca * -hh + py
            right_x, right_y = ca * hb + -sa * -hh + px, sa * hb + ca * -hh + py
            # The pivot is the corner on the side the column leans to.
            pivot_x, x0 = ((left_x, self._corner_x0[k][0]) if angle >= 0.0
                           else (right_x, self._corner_x0[k][1]))
            sl = abs(pivot_x - x0 - x_ground)
            pen = -(right_y if right_y < left_y else left_y)  # = -min(left_y, right_y)
            if sl > diag["pivot_sliding_max_all"]:
                diag["pivot_sliding_max_all"] = sl
            if pen > diag["penetration_max_all"]:
                diag["penetration_max_all"] = pen
            if in_well:
                if sl > diag["pivot_sliding_max"]:
                    diag["pivot_sliding_max"] = sl
                if pen > diag["penetration_max"]:
                    diag["penetration_max"] = pen
        if self._i_lintel is not None and in_well:
            diag["lintel_rotation_max"] = max(diag["lintel_rotation_max"],
                                              abs(st[6 * self._i_lintel + 2]))
        problem = None
        hypot = math.hypot
        for i, x0, y0 in self._starts:
            if hypot(st[i] - x0 - x_ground, st[i + 1] - y0) > self._max_dist:
                problem = f"a body flew away (> {s.blowup_distance:g} trilith sizes)"
                break
            if hypot(st[i + 3], st[i + 4]) > self._max_speed:
                problem = f"a body exceeded {self._max_speed:.3g} m/s"
                break
        return angles[0], angles[1], theta_dot, psi, psi_dot, problem


_World = World  # the name tests and benchmarks/bench_overhead.py used


def _state_reader(world):
    """A function returning ``[x, y, angle, vx, vy, omega]`` of every body of
    ``world.bodies``, concatenated in that order.

    One ``pymunk.batch`` call per sample instead of ~20 property reads (each a C
    call plus a ``Vec2d``: ~1 us, a sixth of a step): the per-sample cost that
    keeps the harness above 80 % of the bare step rate (``benchmarks/bench_overhead``).
    ``pymunk.batch`` is marked experimental, so its output is checked against the
    properties once, bit for bit, and the properties are used if it differs.
    """
    bodies = world.bodies

    def by_property() -> list[float]:
        out: list[float] = []
        for body in bodies:
            (x, y), (vx, vy) = body.position, body.velocity
            out += (x, y, body.angle, vx, vy, body.angular_velocity)
        return out

    try:
        from pymunk import batch
        f = batch.BodyFields
        flags = f.POSITION | f.ANGLE | f.VELOCITY | f.ANGULAR_VELOCITY
        ids = batch.Buffer()
        batch.get_space_bodies(world.space, f.BODY_ID, ids)
        order = memoryview(ids.int_buf()).cast("P").tolist()
        # Chipmunk keeps its bodies in insertion order; nothing is added or removed
        # (and nothing sleeps) during a run, so the order found here holds.
        index = [6 * order.index(body.id) for body in bodies]
    except Exception:  # an experimental API that changed: fall back, never fail
        return by_property
    buf, space = batch.Buffer(), world.space
    n = len(bodies)
    contiguous = index == [6 * k for k in range(n)]

    def batched() -> list[float]:
        buf.clear()
        batch.get_space_bodies(space, flags, buf)
        flat = memoryview(buf.float_buf()).cast("d").tolist()
        if contiguous:
            return flat[:6 * n]
        out: list[float] = []
        for k in index:
            out += flat[k:k + 6]
        return out

    try:
        same = batched() == by_property()
    except Exception:  # an experimental API that changed: fall back, never fail
        same = False
    return batched if same else by_property


def _peak_ground_speed(excitation) -> float:
    """A bound of ``max |xg_dot|`` [m/s] (it only scales the blow-up speed limit)."""
    from analytic.excitation import Pulse
    if isinstance(excitation, Pulse):  # integral of one sine/cosine lobe: <= 2 A / Omega
        return 2.0 * abs(excitation.amplitude) / excitation.omega
    if excitation.end_time <= 0.0:
        return 0.0
    ts = [excitation.end_time * k / 400.0 for k in range(401)]
    return max(abs(excitation.velocity(t)) for t in ts)
