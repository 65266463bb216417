"""LEGACY COPY (tests only) of the pre-body-list builder.

The trilith as three rigid polygons in a Pymunk space, for :mod:`engines.pymunk_`.

:func:`build_space` builds a fresh :class:`pymunk.Space` from the scene's
geometry (:mod:`engines.geometry`); :func:`state_reader` reads every body's
state in one call per sample.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import pymunk

from trilith_xval.engines import geometry

__all__ = ["Space", "build_space", "state_reader"]


@dataclass
class Space:
    """A built space and its bodies (columns first, then lintel and bob if any)."""

    space: pymunk.Space
    ground: pymunk.Body
    columns: list
    lintel: pymunk.Body | None
    bob: pymunk.Body | None

    @property
    def bodies(self) -> list:
        return self.columns + [x for x in (self.lintel, self.bob) if x is not None]


def build_space(scene, s, friction: float) -> Space:
    """A fresh space holding ``scene`` at rest at ``s.theta0`` / ``s.psi0``, every
    contact with the Coulomb coefficient ``friction`` (``s``: the Pymunk Settings)."""
    b, h = scene.b, scene.h
    t_l = scene.lintel_thickness
    space = pymunk.Space()
    space.iterations = s.iterations
    space.collision_slop = s.slop_fraction * b
    if s.collision_bias is not None:
        space.collision_bias = s.collision_bias
    space.gravity = (0.0, -scene.g)
    shape_friction = math.sqrt(friction)  # Pymunk multiplies the pair's values

    def add_box(body, w, hh):
        shape = pymunk.Poly.create_box(body, (w, hh), radius=0.0)
        shape.friction = shape_friction
        shape.elasticity = 0.0
        space.add(shape)
        return shape

    kind = pymunk.Body.KINEMATIC if s.base_motion == "ground" else pymunk.Body.STATIC
    ground = pymunk.Body(body_type=kind)
    half_w, _, half_t = geometry.ground_box(scene)
    ground.position = (0.5 * scene.lintel_length, -half_t)
    space.add(ground)
    add_box(ground, 2.0 * half_w, 2.0 * half_t)

    poses = geometry.rest_poses(scene, s.theta0, s.psi0)
    columns = []
    for centre in poses.columns:
        body = pymunk.Body(scene.m1, scene.inertia_J_G)
        body.position = centre
        body.angle = s.theta0
        space.add(body)
        add_box(body, b, h)
        columns.append(body)
    lintel = bob = None
    if scene.mu > 0.0:
        length = scene.lintel_length
        lintel = pymunk.Body(scene.m3, geometry.box_inertia(scene.m3, length, scene.depth, t_l)[1])
        lintel.position = poses.lintel
        space.add(lintel)
        add_box(lintel, length, t_l)
    if scene.has_pendulum:
        l = scene.pendulum_length
        radius = s.pendulum_radius_fraction * l
        bob = pymunk.Body(scene.m4, scene.m4 * radius ** 2)
        bob.position = poses.bob
        space.add(bob)
        dot = pymunk.Circle(bob, radius)
        dot.filter = pymunk.ShapeFilter(categories=0, mask=0)  # collides with nothing
        space.add(dot)
        anchor_bob = (poses.hinge[0] - poses.bob[0], poses.hinge[1] - poses.bob[1])
        # The bob's body is the rod: its rotation is the pendulum's (psi - psi0).
        joint = pymunk.PivotJoint(lintel, bob, (scene.hinge_x, -0.5 * t_l), anchor_bob)
        joint.collide_bodies = False
        space.add(joint)
    return Space(space, ground, columns, lintel, bob)


def state_reader(world: Space):
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
