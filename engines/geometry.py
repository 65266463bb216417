"""The trilith in the analytic plane, once, for every engine.

The analytic plane has x to the right, y up and angles counter-clockwise (a
column's angle *is* its ``theta``: ``theta > 0`` leans left, on the left
corners).  The left column's bottom-left corner is at the origin, the clear gap
is ``d``, the ground's top face is ``y = 0``.  3D engines put this plane at
their x-z plane (z up) with the scene's ``depth`` along y.

Every engine builds its bodies from these numbers (nothing typed twice):
:func:`rest_poses` (the bodies of a trilith tilted by ``theta0``, at rest),
:func:`box_inertia`, :func:`ground_box`, :func:`size`, and the diagnostics
(:mod:`engines.diagnostics`) read the same :func:`base_corners`.
"""
from __future__ import annotations

import math
from typing import NamedTuple

__all__ = ["RestPoses", "size", "column_lefts", "rest_poses", "base_corners", "box_inertia",
           "ground_box"]


class RestPoses(NamedTuple):
    """Centres of mass [m] of the bodies of a trilith at rest (analytic plane).

    ``columns``: the two column centres; ``lintel``: the lintel's centre (the
    lintel never rotates at rest); ``hinge``: the pendulum hinge on the lintel's
    underside; ``bob``: the bob, ``l`` from the hinge at ``psi0``; ``theta``:
    the columns' angle.
    """

    columns: tuple[tuple[float, float], tuple[float, float]]
    lintel: tuple[float, float]
    hinge: tuple[float, float]
    bob: tuple[float, float]
    theta: float


def size(scene) -> float:
    """The trilith's size [m]: ``max(lintel_length, h + lintel_thickness)``, its
    width or its height, the scale of the blow-up rules and the ground box."""
    return max(scene.lintel_length, scene.h + scene.lintel_thickness)


def column_lefts(scene) -> tuple[float, float]:
    """x [m] of the upright columns' bottom-left corners: ``(0, b + d)``."""
    return (0.0, scene.b + scene.d)


def rest_poses(scene, theta0: float = 0.0, psi0: float = 0.0) -> RestPoses:
    """The bodies of ``scene`` tilted by ``theta0`` [rad], at rest.

    The columns rotate rigidly about their pivot corners (the left ones if
    ``theta0 >= 0``, the right ones if < 0); the lintel translates with the top
    corner diagonally opposite the pivot, the highest one, on which it rests
    (the parallelogram of Eq. 5-6), so every contact starts at zero gap; the
    bob hangs from the hinge at ``psi0`` from the downward vertical.
    """
    b, h = scene.b, scene.h
    c, s = math.cos(theta0), math.sin(theta0)

    def rotate_about(px: float, py: float, x: float, y: float) -> tuple[float, float]:
        rx, ry = x - px, y - py
        return px + c * rx - s * ry, py + s * rx + c * ry

    columns = []
    for x_left in column_lefts(scene):
        pivot_x = x_left if theta0 >= 0.0 else x_left + b
        columns.append(rotate_about(pivot_x, 0.0, x_left + 0.5 * b, 0.5 * h))
    pivot, top = (0.0, b) if theta0 >= 0.0 else (b, 0.0)
    top_x, top_y = rotate_about(pivot, 0.0, top, h)
    shift = (top_x - top, top_y - h)
    lintel = (0.5 * scene.lintel_length + shift[0], h + 0.5 * scene.lintel_thickness + shift[1])
    hinge = (0.5 * scene.lintel_length + scene.hinge_x + shift[0], h + shift[1])
    l = scene.pendulum_length
    bob = (hinge[0] + l * math.sin(psi0), hinge[1] - l * math.cos(psi0))
    return RestPoses((columns[0], columns[1]), lintel, hinge, bob, theta0)


def base_corners(x: float, y: float, angle: float, b: float, h: float
                 ) -> tuple[float, float, float, float]:
    """``(x_left, y_left, x_right, y_right)`` of the bottom corners of a ``b x h``
    column whose centre is at ``(x, y)``, rotated by ``angle`` (CCW)."""
    hb, hh = 0.5 * b, 0.5 * h
    ca, sa = math.cos(angle), math.sin(angle)
    return (x - ca * hb + sa * hh, y - sa * hb - ca * hh,
            x + ca * hb + sa * hh, y + sa * hb - ca * hh)


def box_inertia(mass: float, sx: float, sy: float, sz: float) -> tuple[float, float, float]:
    """Principal inertias [kg m^2] of a uniform box with full side lengths sx, sy, sz."""
    return (mass * (sy * sy + sz * sz) / 12.0, mass * (sx * sx + sz * sz) / 12.0,
            mass * (sx * sx + sy * sy) / 12.0)


def ground_box(scene) -> tuple[float, float, float]:
    """Half extents ``(along x, along the depth, thickness)`` [m] of the ground box,
    centred at ``x = lintel_length / 2`` with its top face at ``y = 0``.

    Wide enough for columns lying on their sides (``lintel_length + 2.5 h`` each
    way), thick enough that a corner cannot tunnel through it (``max(b/2, 0.1 m)``).
    A box, not a plane: a plane made top and bottom impacts resolve one step
    apart in PyBullet (DESIGN.md).
    """
    return (scene.lintel_length + 2.5 * scene.h, scene.depth + scene.h,
            max(0.5 * scene.b, 0.1))
