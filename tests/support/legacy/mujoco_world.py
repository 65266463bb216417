"""LEGACY COPY (tests only) of the pre-body-list builder.

The MJCF model of the trilith, generated from a :class:`~analytic.parameters.Scene`
and :mod:`engines.geometry`, for :mod:`engines.mujoco_`.

The model is an MJCF string generated from the Scene's fields (:func:`mjcf`);
nothing is typed twice.  The analytic plane (x right, y up) is MuJoCo's x-z
plane (z up); the depth ``scene.depth`` runs along y.  Every body moves in that
plane through three joints at its centre of mass, ``slide x``, ``slide z`` and a
``hinge`` about **-y**: a positive hinge angle is then a counter-clockwise
rotation in the analytic plane, so a column's hinge coordinate *is* its
``theta`` (and the pendulum's is ``psi`` relative to the lintel).  Out-of-plane
motion is impossible by construction (the collision geometry stays 3D boxes).

Bodies:

* ground: a static plane ``z = 0`` ("gravity" base motion), or a heavy box on a
  slide joint whose position and velocity are set to the ground's motion before
  every step ("ground" base motion);
* two columns ``b x depth x h``, mass ``m1``, inertia ``J_G`` about the hinge
  axis, the left one's left bottom corner at ``x = 0``, clear gap ``d``;
* the lintel (``mu > 0`` only), ``lintel_length x depth x lintel_thickness``,
  mass ``m3``, resting on both column tops;
* the pendulum (``gamma > 0`` only): a child body of the lintel, hinged on its
  underside at ``hinge_x`` from its middle, the point mass ``m4`` at ``l`` below
  the hinge (negligible own inertia), with no geom at all, so it collides with
  nothing, like the analytic pendulum.
"""
from __future__ import annotations

import logging

import mujoco

from trilith_xval.engines import geometry

# MuJoCo appends its warnings to MUJOCO_LOG.TXT in the working directory; the
# World reads the same warnings from its counters (d.warning) and reports them,
# so send the text to logging instead of the user's folder.
mujoco.set_mju_user_warning(logging.getLogger("engines.mujoco").debug)

__all__ = ["mjcf", "NEGLIGIBLE_INERTIA_FRACTION", "GROUND_MASS_FACTOR", "BAD_WARNINGS"]

# Own inertia of the bob relative to m4 l^2: a point mass to 1e-6, yet a regular
# (positive definite) body inertia for MuJoCo.
NEGLIGIBLE_INERTIA_FRACTION = 1e-6
# The moving ground ("ground" base motion) weighs this many trilith masses, so
# contact impulses change its prescribed velocity by < 1e-6 within a step.
GROUND_MASS_FACTOR = 1e6
# MuJoCo's warnings that mean the state was reset or is garbage.
BAD_WARNINGS = ("mjWARN_BADQACC", "mjWARN_BADQPOS", "mjWARN_BADQVEL", "mjWARN_CONTACTFULL",
                 "mjWARN_CNSTRFULL")


def _f(x: float) -> str:
    return repr(float(x))  # round-trips exactly through MuJoCo's parser


def _vec(*xs: float) -> str:
    return " ".join(_f(x) for x in xs)


def _planar_body(name: str, pos: tuple[float, float], mass: float, inertia, geom: str,
                 inner: str = "") -> str:
    x, z = pos
    return (f'<body name="{name}" pos="{_vec(x, 0.0, z)}">'
            f'<joint name="{name}_x" type="slide" axis="1 0 0"/>'
            f'<joint name="{name}_z" type="slide" axis="0 0 1"/>'
            f'<joint name="{name}_theta" type="hinge" axis="0 -1 0"/>'
            f'<inertial pos="0 0 0" mass="{_f(mass)}" diaginertia="{_vec(*inertia)}"/>'
            f'{geom}{inner}</body>')


def mjcf(scene, s, friction: float) -> str:
    """The MJCF text of ``scene`` (upright, at rest) with the MuJoCo Settings ``s``.

    Every geom gets ``friction`` explicitly: MuJoCo combines two geoms'
    coefficients by their maximum (PyBullet and Pymunk multiply), so equal
    values give exactly ``friction`` at every contact.
    """
    b, h, d, depth = scene.b, scene.h, scene.d, scene.depth
    span, t_l = scene.lintel_length, scene.lintel_thickness
    timeconst = s.timeconst if s.timeconst is not None else s.timeconst_steps * s.dt
    option = (f'<option timestep="{_f(s.dt)}" gravity="{_vec(0.0, 0.0, -scene.g)}" '
              f'integrator="{s.integrator}" cone="{s.cone}" impratio="{_f(s.impratio)}" '
              f'iterations="{s.iterations}" solver="{s.solver}"/>')
    # margin 0 (a margin without gap makes contacts act at a distance) and
    # condim 3 (sliding friction only, no torsional/rolling resistance).
    default = (f'<default><geom condim="3" margin="0" gap="0" '
               f'friction="{_vec(friction, 0.0, 0.0)}" '
               f'solref="{_vec(timeconst, s.dampratio)}" solimp="{_vec(*s.solimp)}"/></default>')
    total = scene.m1 * (2.0 + scene.mu + scene.gamma)
    g_half = geometry.ground_box(scene)
    if s.base_motion == "ground":
        # A box, since planes must be static; its top face is z = 0.
        ground = (f'<body name="ground" pos="{_vec(0.5 * span, 0.0, -g_half[2])}">'
                  f'<joint name="ground_x" type="slide" axis="1 0 0"/>'
                  f'<inertial pos="0 0 0" mass="{_f(GROUND_MASS_FACTOR * total)}" '
                  f'diaginertia="{_vec(*geometry.box_inertia(GROUND_MASS_FACTOR * total, *g_half))}"/>'
                  f'<geom type="box" size="{_vec(*g_half)}"/></body>')
    else:
        ground = f'<geom name="ground" type="plane" size="{_vec(g_half[0], g_half[1], 1.0)}" ' \
                 f'pos="{_vec(0.5 * span, 0.0, 0.0)}"/>'
    col_geom = f'<geom type="box" size="{_vec(0.5 * b, 0.5 * depth, 0.5 * h)}"/>'
    # J_G comes from the scene (it may differ from the uniform box's value).  Only
    # the hinge axis (y) turns, so the other two principal inertias never enter
    # the dynamics: equal to J_G, they satisfy MuJoCo's triangle inequality for any J_G.
    col_inertia = (scene.inertia_J_G,) * 3
    bodies = [_planar_body(name, (x_left + 0.5 * b, 0.5 * h), scene.m1, col_inertia, col_geom)
              for name, x_left in (("column_left", 0.0), ("column_right", b + d))]
    if scene.mu > 0.0:
        pendulum = ""
        if scene.has_pendulum:
            l, m4 = scene.pendulum_length, scene.m4
            bob_i = NEGLIGIBLE_INERTIA_FRACTION * m4 * l * l
            pendulum = (f'<body name="pendulum" pos="{_vec(scene.hinge_x, 0.0, -0.5 * t_l)}">'
                        f'<joint name="pendulum_psi" type="hinge" axis="0 -1 0"/>'
                        f'<inertial pos="{_vec(0.0, 0.0, -l)}" mass="{_f(m4)}" '
                        f'diaginertia="{_vec(bob_i, bob_i, bob_i)}"/></body>')
        lintel_geom = f'<geom type="box" size="{_vec(0.5 * span, 0.5 * depth, 0.5 * t_l)}"/>'
        bodies.append(_planar_body("lintel", (0.5 * span, h + 0.5 * t_l), scene.m3,
                                   geometry.box_inertia(scene.m3, span, depth, t_l), lintel_geom,
                                   pendulum))
    return ('<mujoco model="trilith"><compiler angle="radian" inertiafromgeom="false"/>'
            f'{option}{default}<worldbody>{ground}{"".join(bodies)}</worldbody></mujoco>')
