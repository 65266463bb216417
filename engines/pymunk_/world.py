"""A scene's body list as rigid polygons in a Pymunk space, for :mod:`engines.pymunk_`.

:func:`build_space` builds a fresh :class:`pymunk.Space` from the scene's
:class:`~engines.geometry.Structure` (the trilith, the block, or another kind
of :mod:`analytic.kinds`); :func:`state_reader` reads every body's state in
one call per sample.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import pymunk

from trilith_xval.engines import geometry

__all__ = ["Space", "build_space", "state_reader"]


@dataclass
class Space:
    """A built space and its bodies in the structure's order (for the trilith:
    columns first, then lintel), the bob last if any; ``columns``/``lintel``
    name the trilith's bodies (empty/None for the other kinds)."""

    space: pymunk.Space
    ground: pymunk.Body
    boxes: list
    bob: pymunk.Body | None
    structure: geometry.Structure

    @property
    def columns(self) -> list:
        names = [x.name for x in self.structure.bodies]
        return [self.boxes[names.index(n)] for n in ("column_left", "column_right")
                if n in names] if self.structure.is_trilith else []

    @property
    def lintel(self) -> pymunk.Body | None:
        if self.structure.is_trilith and len(self.boxes) > 2:
            return self.boxes[2]
        return None

    @property
    def bodies(self) -> list:
        return self.boxes + ([self.bob] if self.bob is not None else [])


def build_space(scene, s, friction: float) -> Space:
    """A fresh space holding ``scene`` (a scene, or its
    :class:`~engines.geometry.Structure`) at rest at ``s.theta0`` / ``s.psi0``,
    every contact with the Coulomb coefficient ``friction`` (``s``: the Pymunk
    Settings).

    Bodies are added in the structure's order after the ground (Chipmunk keeps
    insertion order; :func:`state_reader` relies on it)."""
    structure = (scene if isinstance(scene, geometry.Structure)
                 else geometry.structure_of(scene, s.theta0, s.psi0))
    space = pymunk.Space()
    space.iterations = s.iterations
    space.collision_slop = s.slop_fraction * structure.width_scale
    if s.collision_bias is not None:
        space.collision_bias = s.collision_bias
    space.gravity = (0.0, -structure.g)
    shape_friction = math.sqrt(friction)  # Pymunk multiplies the pair's values

    def add_box(body, w, hh):
        shape = pymunk.Poly.create_box(body, (w, hh), radius=0.0)
        shape.friction = shape_friction
        shape.elasticity = 0.0
        space.add(shape)
        return shape

    kind = pymunk.Body.KINEMATIC if s.base_motion == "ground" else pymunk.Body.STATIC
    ground = pymunk.Body(body_type=kind)
    centre_x, half_w, _, half_t = structure.ground
    ground.position = (centre_x, -half_t)
    space.add(ground)
    add_box(ground, 2.0 * half_w, 2.0 * half_t)

    boxes = []
    for box in structure.bodies:
        # The in-plane principal inertia (the depth axis) is the one that turns.
        body = pymunk.Body(box.mass, box.inertia[1])
        x, y, angle = box.start
        body.position = (x, y)
        if angle != 0.0:
            body.angle = angle
        space.add(body)
        add_box(body, box.b, box.h)
        boxes.append(body)
    bob = None
    if structure.bob is not None:
        spec = structure.bob
        parent = boxes[structure.index(spec.parent)]
        radius = s.pendulum_radius_fraction * spec.length
        bob = pymunk.Body(spec.mass, spec.mass * radius ** 2)
        bob.position = spec.start
        space.add(bob)
        dot = pymunk.Circle(bob, radius)
        dot.filter = pymunk.ShapeFilter(categories=0, mask=0)  # collides with nothing
        space.add(dot)
        anchor_bob = (spec.hinge[0] - spec.start[0], spec.hinge[1] - spec.start[1])
        # The bob's body is the rod: its rotation is the pendulum's (psi - psi0).
        joint = pymunk.PivotJoint(parent, bob, spec.anchor, anchor_bob)
        joint.collide_bodies = False
        space.add(joint)
    return Space(space, ground, boxes, bob, structure)


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
