"""A free planar block in Pymunk, started from a given state: the world of a
measured impact's replay (:mod:`compare.peers.impact_replay`).

The trilith's world (:mod:`.world`) starts at rest on its pivots; a measured
impact starts in flight, with ``x, z, theta`` and their rates set at once, so it
has this small world of its own, with the same contact settings (the calibrated
:class:`~engines.pymunk_.Settings`: iterations, slop, bias, plastic contact).
"""
from __future__ import annotations

import math

__all__ = ["free_block"]


def free_block(side: float, mass: float, inertia: float, g: float, state, friction: float,
               n_frames: int, frame_rate: float, on_step, settings) -> tuple[list, None]:
    """Run one ``side x side`` block of ``mass`` [kg] and ``inertia`` [kg m^2]
    under gravity ``g`` [m/s^2] on flat ground (top face ``z = 0``) from ``state``
    ``(x, z, theta, vx, vz, omega)`` for ``n_frames - 1`` frames of ``1 /
    frame_rate`` s; ``(thetas, None)``: ``theta`` [rad] at each frame, the start
    included (Pymunk has no solver warnings to count).

    ``settings`` is the engine's :class:`~engines.pymunk_.Settings` (step, iterations,
    slop, bias); ``on_step(z, theta, omega, omega_before)`` is called after every step (the
    caller watches the landing corner); ``friction`` is the pair's coefficient
    (Pymunk multiplies the two shapes' values, so each gets its square root).
    """
    import pymunk

    s = settings
    space = pymunk.Space()
    space.iterations = s.iterations
    space.collision_slop = s.slop_fraction * side
    if s.collision_bias is not None:
        space.collision_bias = s.collision_bias
    space.gravity = (0.0, -g)
    shape_friction = math.sqrt(friction)
    ground = pymunk.Body(body_type=pymunk.Body.STATIC)
    ground.position = (0.0, -0.5 * side)
    floor = pymunk.Poly.create_box(ground, (1000.0 * side, side), radius=0.0)
    block = pymunk.Body(mass, inertia)
    box = pymunk.Poly.create_box(block, (side, side), radius=0.0)
    for shape in (floor, box):
        shape.friction, shape.elasticity = shape_friction, 0.0
    x, z, th, vx, vz, w = state
    block.position, block.angle = (x, z), th
    block.velocity, block.angular_velocity = (vx, vz), w
    space.add(ground, floor, block, box)
    steps = int(round(1.0 / (frame_rate * s.dt)))
    thetas = [th]
    for _ in range(n_frames - 1):
        for _ in range(steps):
            w0 = block.angular_velocity
            space.step(s.dt)
            on_step(block.position[1], block.angle, block.angular_velocity, w0)
        thetas.append(block.angle)
    return thetas, None
