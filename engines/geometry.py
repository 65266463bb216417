"""The trilith in the analytic plane, once, for every engine.

The analytic plane has x to the right, y up and angles counter-clockwise (a
column's angle *is* its ``theta``: ``theta > 0`` leans left, on the left
corners).  The left column's bottom-left corner is at the origin, the clear gap
is ``d``, the ground's top face is ``y = 0``.  3D engines put this plane at
their x-z plane (z up) with the scene's ``depth`` along y.

A scene is a list of bodies: :func:`structure_of` turns a scene (the
parametric trilith, the single block, or one of the kinds of
:mod:`analytic.kinds`: columns of drums, unequal columns, a block on a block)
into a :class:`Structure` of :class:`Box` bodies, an optional :class:`Bob` on a
hinge, and which body stands on which; an engine folder turns that list into
its world.  The numbers come from :func:`rest_poses` (the bodies of a trilith
tilted by ``theta0``, at rest), :func:`box_inertia`, :func:`ground_box` and
:func:`size`, and the diagnostics (:mod:`engines.diagnostics`) read the same
:func:`base_corners` (nothing typed twice).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

__all__ = ["RestPoses", "size", "column_lefts", "rest_poses", "base_corners", "box_inertia",
           "ground_box", "Box", "Bob", "Structure", "structure_of", "TRILITH_KINDS",
           "STRUCTURE_ENGINES", "RELEASE_KINDS", "MAX_KIND_TILT", "release_limit"]

# The kinds the parametric Scene describes (the analytic model's mechanism).
TRILITH_KINDS = ("trilith", "block")
# The shipped engines that build any Structure (their class sets ``structures``);
# the others build the parametric trilith only and refuse the other kinds.
STRUCTURE_ENGINES = ("pymunk", "mujoco", "pybullet", "dart", "drake")


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


# ---------------------------------------------------------------- the body list
@dataclass(frozen=True)
class Box:
    """A rigid uniform-or-not box in the analytic plane.

    Parameters
    ----------
    name : str
        Unique in its structure (engines name their bodies after it).
    b, h : float
        Width (along x) and height (along y) [m], both > 0.
    mass : float
        [kg], > 0.
    inertia : tuple of float
        Principal inertias [kg m^2] about the box's x (width), depth and height
        axes; the second one turns in the plane (3D engines need all three).
    upright : tuple of float
        Centre [m] of the box standing upright at rest (the engines' reference pose).
    start : tuple of float
        ``(x, y, angle)`` [m, m, rad] at the start of a run (an initial tilt moves it).
    """

    name: str
    b: float
    h: float
    mass: float
    inertia: tuple[float, float, float]
    upright: tuple[float, float]
    start: tuple[float, float, float]

    @property
    def alpha(self) -> float:
        """Its own overturning angle ``atan(b/h)`` [rad] (on a rigid base)."""
        return math.atan2(self.b, self.h)


@dataclass(frozen=True)
class Bob:
    """The pendulum: a point mass on a hinge under its parent body.

    ``anchor`` is the hinge in the parent's own frame [m]; ``hinge`` and
    ``start`` the hinge and the bob at the start of a run [m]; ``length`` [m];
    ``psi0`` its angle from the downward vertical [rad] at the start.
    """

    mass: float
    parent: str
    anchor: tuple[float, float]
    hinge: tuple[float, float]
    start: tuple[float, float]
    length: float
    psi0: float


@dataclass(frozen=True)
class Structure:
    """A scene as data: boxes, the bob, and which body stands on which.

    Parameters
    ----------
    kind : str
        ``'trilith'``, ``'block'`` (the parametric Scene) or a kind of
        :mod:`analytic.kinds` (``'drums'``, ``'unequal'``, ``'block_on_block'``).
    bodies : tuple of Box
        In the engines' order (for the trilith: left column, right column, lintel).
    bob : Bob or None
    supports : tuple of (str, str)
        ``(upper, lower)`` pairs: ``upper`` rests on ``lower`` (``'ground'`` for
        the ground) at rest.
    ground : tuple of float
        ``(centre x, half width, half depth, half thickness)`` [m] of the ground
        box, whose top face is ``y = 0``.
    depth, g : float
        Out-of-plane depth [m] and gravity [m/s^2].
    total_mass : float
        [kg], what a moving ground is scaled by.
    width_scale : float
        [m] the smallest width a contact rests on (Pymunk's slop is a fraction of it).
    size : float
        [m] the structure's extent, the scale of the blow-up rules.
    """

    kind: str
    bodies: tuple[Box, ...]
    bob: Bob | None
    supports: tuple[tuple[str, str], ...]
    ground: tuple[float, float, float, float]
    depth: float
    g: float
    total_mass: float
    width_scale: float
    size: float

    def body(self, name: str) -> Box:
        """The box called ``name``."""
        for box in self.bodies:
            if box.name == name:
                return box
        raise KeyError(name)

    def index(self, name: str) -> int:
        return [box.name for box in self.bodies].index(name)

    @property
    def is_trilith(self) -> bool:
        """The parametric Scene's mechanism, which the analytic model covers."""
        return self.kind in TRILITH_KINDS


def _trilith_structure(scene, theta0: float, psi0: float) -> Structure:
    # Every number is computed as the engines computed it before the body list
    # existed, operation for operation: the worlds stay bit-identical.
    b, h, depth, t_l = scene.b, scene.h, scene.depth, scene.lintel_thickness
    span = scene.lintel_length
    poses = rest_poses(scene, theta0, psi0)
    j = scene.inertia_J_G
    bodies = [Box(name, b, h, scene.m1, (j, j, j), (x_left + 0.5 * b, 0.5 * h),
                  (*centre, theta0))
              for name, x_left, centre in zip(("column_left", "column_right"),
                                              column_lefts(scene), poses.columns)]
    supports = [("column_left", "ground"), ("column_right", "ground")]
    bob = None
    if scene.mu > 0.0:
        bodies.append(Box("lintel", span, t_l, scene.m3, box_inertia(scene.m3, span, depth, t_l),
                          (0.5 * span, h + 0.5 * t_l), (*poses.lintel, 0.0)))
        supports += [("lintel", "column_left"), ("lintel", "column_right")]
        if scene.has_pendulum:
            bob = Bob(scene.m4, "lintel", (scene.hinge_x, -0.5 * t_l), poses.hinge, poses.bob,
                      scene.pendulum_length, psi0)
    half_w, half_d, half_t = ground_box(scene)
    return Structure("trilith" if scene.mu > 0.0 else "block", tuple(bodies), bob,
                     tuple(supports), (0.5 * span, half_w, half_d, half_t), depth, scene.g,
                     scene.m1 * (2.0 + scene.mu + scene.gamma), b, size(scene))


def structure_of(scene, theta0: float = 0.0, psi0: float = 0.0) -> Structure:
    """The body list of ``scene`` at the start of a run.

    A parametric :class:`~analytic.parameters.Scene` gives the trilith (``mu >
    0``) or the two free blocks (``mu = 0``) tilted by ``theta0`` [rad] with the
    bob at ``psi0`` [rad] (:func:`rest_poses`); a scene of :mod:`analytic.kinds`
    gives its boxes upright, tilted by at most :data:`MAX_KIND_TILT` (a plumb
    error), or, for the kinds of :data:`RELEASE_KINDS`, released from a tilt below
    :func:`release_limit` with ``psi0 = 0`` (free rocking).
    """
    if getattr(scene, "kind", "trilith") in TRILITH_KINDS:
        return _trilith_structure(scene, theta0, psi0)
    release = scene.kind in RELEASE_KINDS and psi0 == 0.0 and abs(theta0) < release_limit(scene)
    if (abs(theta0) > MAX_KIND_TILT or psi0 != 0.0) and not release:
        raise ValueError(f"theta0 must be in [-{MAX_KIND_TILT:g}, {MAX_KIND_TILT:g}] rad and "
                         f"psi0 0 for the {scene.kind} kind (a plumb error of the whole "
                         f"structure){_release_text(scene)}, got {theta0!r}, {psi0!r}")
    return _kind_structure(scene, theta0)


# Largest initial tilt of a structure of another kind [rad]: it is turned rigidly
# about a bottom corner, which lifts its far footing by theta0 times the footprint
# (4 um at 1e-6 rad over 4 m, the threshold search's tilt); a millirad is a plumb
# error, more would drop the far footing measurably.
MAX_KIND_TILT = 1e-3
# Kinds released from a real tilt (free rocking): a block on a block turns as one
# rigid body about its footprint's corner; each column of drums as one rigid stack
# about its own base corner, the lintel carried on the top drums' highest corners
# (the trilith's parallelogram, :func:`rest_poses`).  Whether they go on rocking as
# one is measured, not assumed.
RELEASE_KINDS = ("drums", "block_on_block")


def release_limit(scene) -> float:
    """The largest release tilt [rad] of a kind of :data:`RELEASE_KINDS`: the angle at
    which the rigidly turned part's centre of mass (the whole block on a block, one
    column of drums) passes over its pivot corner, the smaller of both sides."""
    rects = scene.layout()
    part = [r for r in rects if r.name.startswith("column_left_")] if scene.kind == "drums" \
        else list(rects)
    mass = sum(r.mass for r in part)
    x_cm = sum(r.mass * r.x for r in part) / mass
    y_cm = sum(r.mass * r.y for r in part) / mass
    left = min(r.x - 0.5 * r.b for r in part if abs(r.y - 0.5 * r.h) < 1e-12)
    right = max(r.x + 0.5 * r.b for r in part if abs(r.y - 0.5 * r.h) < 1e-12)
    return min(math.atan2(x_cm - left, y_cm), math.atan2(right - x_cm, y_cm))


def _release_text(scene) -> str:
    """The release a kind allows, for the refusal's message."""
    if scene.kind not in RELEASE_KINDS:
        return f"; the {scene.kind} kind has no free-rocking release"
    return (f", or a free-rocking release below {release_limit(scene):.4g} rad with psi0 0 "
            f"(its release limit)")


def _parallelogram(rects, theta0: float) -> dict:
    """``{name: (move, angle)}`` of a column of drums released from ``theta0``: each
    column's drums turned rigidly about its bottom drum's pivot corner, the lintel
    translated with the top drum's corner diagonally opposite the pivot."""
    c, s = math.cos(theta0), math.sin(theta0)

    def rotation(px: float):
        return lambda x, y: (px + c * (x - px) - s * y, s * (x - px) + c * y)
    moves = {}
    for side in ("left", "right"):
        column = [r for r in rects if r.name.startswith(f"column_{side}_")]
        bottom, top = column[0], column[-1]
        turn = rotation(bottom.x - 0.5 * bottom.b if theta0 >= 0.0 else bottom.x + 0.5 * bottom.b)
        moves.update({r.name: (turn, theta0) for r in column})
        corner = (top.x + 0.5 * top.b if theta0 >= 0.0 else top.x - 0.5 * top.b, top.y + 0.5 * top.h)
        moved = turn(*corner)
        shift = (moved[0] - corner[0], moved[1] - corner[1])
    for r in rects:
        if r.name not in moves:  # the lintel: carried, not turned
            moves[r.name] = ((lambda x, y: (x + shift[0], y + shift[1])), 0.0)
    return moves


def _kind_structure(scene, theta0: float = 0.0) -> Structure:
    """The Structure of a scene of :mod:`analytic.kinds` (its layout of rectangles),
    turned rigidly by ``theta0`` [rad] about the footprint's bottom-left corner
    (``theta0 > 0``, the trilith's sign) or bottom-right one."""
    depth = scene.depth
    rects = scene.layout()
    left = min(r.x - 0.5 * r.b for r in rects)
    right = max(r.x + 0.5 * r.b for r in rects)
    pivot = left if theta0 >= 0.0 else right
    c, s = math.cos(theta0), math.sin(theta0)

    def turn(x: float, y: float) -> tuple[float, float]:
        return pivot + c * (x - pivot) - s * y, s * (x - pivot) + c * y

    moves = {r.name: (turn, theta0) for r in rects}
    if scene.kind == "drums" and abs(theta0) > MAX_KIND_TILT:  # a release: the parallelogram
        moves = _parallelogram(rects, theta0)
    bodies = tuple(Box(r.name, r.b, r.h, r.mass, box_inertia(r.mass, r.b, depth, r.h),
                       (r.x, r.y), (*moves[r.name][0](r.x, r.y), moves[r.name][1]))
                   for r in rects)
    bob = None
    hinge = scene.hinge()
    if hinge is not None:
        parent, anchor, mass, length = hinge
        box = next(x for x in bodies if x.name == parent)
        at = moves[parent][0](box.upright[0] + anchor[0], box.upright[1] + anchor[1])
        # The bob hangs plumb (psi0 = 0) from the turned hinge.
        bob = Bob(mass, parent, anchor, at, (at[0], at[1] - length), length, 0.0)
    top = max(x.upright[1] + 0.5 * x.h for x in bodies)
    extent = max(right - left, top)
    tallest = max(x.h for x in bodies)
    # As ground_box: room for bodies lying on their sides, thick enough not to tunnel.
    ground = (0.5 * (left + right), 0.5 * (right - left) + 2.5 * tallest, depth + tallest,
              max(0.5 * min(x.b for x in bodies), 0.1))
    total = sum(x.mass for x in bodies) + (bob.mass if bob is not None else 0.0)
    return Structure(scene.kind, bodies, bob, tuple(scene.supports()), ground, depth, scene.g,
                     total, min(x.b for x in bodies), extent)
