"""Building the trilith in MuJoCo from a :class:`~analytic.parameters.Scene`,
stepping it and reading its state back, for :mod:`engines.mujoco_engine`.

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
import math
from typing import TYPE_CHECKING

import mujoco

# MuJoCo appends its warnings to MUJOCO_LOG.TXT in the working directory; the
# World reads the same warnings from its counters (d.warning) and reports them,
# so send the text to logging instead of the user's folder.
mujoco.set_mju_user_warning(logging.getLogger("engines.mujoco").debug)

if TYPE_CHECKING:  # annotation only: the adapter imports this module
    from engines.mujoco_engine import Settings

__all__ = ["World", "mjcf", "initial_offsets", "NEGLIGIBLE_INERTIA_FRACTION",
           "GROUND_MASS_FACTOR"]

# Own inertia of the bob relative to m4 l^2: a point mass to 1e-6, yet a regular
# (positive definite) body inertia for MuJoCo.
NEGLIGIBLE_INERTIA_FRACTION = 1e-6
# The moving ground ("ground" base motion) weighs this many trilith masses, so
# contact impulses change its prescribed velocity by < 1e-6 within a step.
GROUND_MASS_FACTOR = 1e6
# Blow-up rules (as PyBullet's): a body farther than DRIFT_SIZES trilith sizes
# from its start, or faster than SPEED_FACTOR sqrt(2 g size) + 10 |ground
# speed| (a toppling column's tip never exceeds ~2 sqrt(g size)).
DRIFT_SIZES = 10.0
SPEED_FACTOR = 20.0
# MuJoCo's warnings that mean the state was reset or is garbage.
_BAD_WARNINGS = ("mjWARN_BADQACC", "mjWARN_BADQPOS", "mjWARN_BADQVEL", "mjWARN_CONTACTFULL",
                 "mjWARN_CNSTRFULL")


def _f(x: float) -> str:
    return repr(float(x))  # round-trips exactly through MuJoCo's parser


def _vec(*xs: float) -> str:
    return " ".join(_f(x) for x in xs)


def _box_inertia(mass: float, sx: float, sy: float, sz: float) -> tuple[float, float, float]:
    """Principal inertia of a uniform box with full side lengths sx, sy, sz."""
    return (mass * (sy * sy + sz * sz) / 12.0, mass * (sx * sx + sz * sz) / 12.0,
            mass * (sx * sx + sy * sy) / 12.0)


def _planar_body(name: str, pos: tuple[float, float], mass: float, inertia, geom: str,
                 inner: str = "") -> str:
    x, z = pos
    return (f'<body name="{name}" pos="{_vec(x, 0.0, z)}">'
            f'<joint name="{name}_x" type="slide" axis="1 0 0"/>'
            f'<joint name="{name}_z" type="slide" axis="0 0 1"/>'
            f'<joint name="{name}_theta" type="hinge" axis="0 -1 0"/>'
            f'<inertial pos="0 0 0" mass="{_f(mass)}" diaginertia="{_vec(*inertia)}"/>'
            f'{geom}{inner}</body>')


def mjcf(scene, s: Settings, friction: float) -> str:
    """The MJCF text of ``scene`` (upright, at rest) with the settings ``s``.

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
    g_half = (0.5 * span + 2.5 * h, 0.5 * depth + h, max(0.5 * b, 0.1))
    if s.base_motion == "ground":
        # A box, since planes must be static; its top face is z = 0.
        ground = (f'<body name="ground" pos="{_vec(0.5 * span, 0.0, -g_half[2])}">'
                  f'<joint name="ground_x" type="slide" axis="1 0 0"/>'
                  f'<inertial pos="0 0 0" mass="{_f(GROUND_MASS_FACTOR * total)}" '
                  f'diaginertia="{_vec(*_box_inertia(GROUND_MASS_FACTOR * total, *g_half))}"/>'
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
                                   _box_inertia(scene.m3, span, depth, t_l), lintel_geom,
                                   pendulum))
    return ('<mujoco model="trilith"><compiler angle="radian" inertiafromgeom="false"/>'
            f'{option}{default}<worldbody>{ground}{"".join(bodies)}</worldbody></mujoco>')


def initial_offsets(scene, theta0: float) -> dict[str, tuple[float, float, float]]:
    """Joint coordinates ``(x, z, theta)`` of the columns and the lintel (offsets
    from the upright MJCF pose) for a trilith tilted by ``theta0`` at rest.

    The columns rotate rigidly about their pivot corners (the left ones if
    ``theta0 > 0``, the right ones if < 0); the lintel translates with the top
    corner diagonally opposite the pivot, the highest one, on which it rests
    (the parallelogram of Eq. 5-6): every contact starts at zero gap.
    """
    b, h = scene.b, scene.h
    c, s = math.cos(theta0), math.sin(theta0)

    def moved(px: float, x: float, z: float) -> tuple[float, float]:
        rx, rz = x - px, z  # rotation about the pivot (px, 0): the point's displacement
        return c * rx - s * rz - rx, s * rx + c * rz - rz

    out = {}
    for name, x_left in (("column_left", 0.0), ("column_right", b + scene.d)):
        pivot = x_left if theta0 >= 0.0 else x_left + b
        dx, dz = moved(pivot, x_left + 0.5 * b, 0.5 * h)
        out[name] = (dx, dz, theta0)
    pivot, top = (0.0, b) if theta0 >= 0.0 else (b, 0.0)
    dx, dz = moved(pivot, top, h)
    out["lintel"] = (dx, dz, 0.0)
    return out


class World:
    """A fresh MjModel/MjData holding one trilith; steps it and reads its state.

    ``s`` is an :class:`engines.mujoco_engine.Settings` (validated by the
    caller), ``friction`` the Coulomb coefficient of every contact.
    """

    def __init__(self, scene, excitation, s: Settings, friction: float) -> None:
        self.scene, self.excitation, self.s = scene, excitation, s
        self.xml = mjcf(scene, s, friction)
        try:
            self.model = m = mujoco.MjModel.from_xml_string(self.xml)
        except ValueError as exc:  # e.g. a body below MuJoCo's mass/inertia floor (1e-15)
            raise ValueError(f"mujoco cannot model this scene: {str(exc).splitlines()[0]} "
                             f"(scene {scene.name!r}: column_mass, gamma and l set the "
                             f"smallest body)") from None
        self.data = d = mujoco.MjData(m)
        self.moving = s.base_motion == "ground"

        def adr(joint: str) -> int:
            return int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)])

        # Slide/hinge joints only: qpos and qvel share their addresses.
        self.columns = (adr("column_left_x"), adr("column_right_x"))
        self.lintel = adr("lintel_x") if scene.mu > 0.0 else None
        self.pendulum = adr("pendulum_psi") if scene.has_pendulum else None
        self.ground = adr("ground_x") if self.moving else None
        for name, q in initial_offsets(scene, s.theta0).items():
            if name == "lintel" and self.lintel is None:
                continue
            a = self.lintel if name == "lintel" else self.columns[name == "column_right"]
            d.qpos[a:a + 3] = q
        if self.pendulum is not None:
            d.qpos[self.pendulum] = s.psi0  # relative to the lintel, which starts unrotated
        if self.moving:
            self._set_ground(0)
        mujoco.mj_forward(m, d)
        b, h, t_l = scene.b, scene.h, scene.lintel_thickness
        self.size = max(scene.lintel_length, h + t_l)
        self.pivots0 = ((0.0, b), (b + scene.d, 2.0 * b + scene.d))
        self.centres0 = [(x0 + 0.5 * b, 0.5 * h) for x0, _ in self.pivots0]
        if self.lintel is not None:
            self.centres0.append((0.5 * scene.lintel_length, h + 0.5 * t_l))
        self._warnings = [int(getattr(mujoco.mjtWarning, w)) for w in _BAD_WARNINGS]
        self.diag = dict(lintel_rotation_max=0.0, pivot_sliding_max=0.0, penetration_max=0.0)
        self.step_index = 0
        self.standing = True  # see sample()

    def close(self) -> None:
        """Nothing to release (MuJoCo frees the model with its Python objects)."""
        self.model = self.data = None

    # ---------------------------------------------------------------- stepping
    def _set_ground(self, n: int) -> None:
        """Ground slide at x_g(t_n), moving at the mean velocity of step n."""
        dt, ex, d = self.s.dt, self.excitation, self.data
        x0, x1 = ex.displacement(n * dt), ex.displacement((n + 1) * dt)
        d.qpos[self.ground] = x0
        d.qvel[self.ground] = (x1 - x0) / dt

    def advance(self, count: int) -> None:
        """``count`` steps.  One loop with local names: stepping is the hot path."""
        n, dt, m, d = self.step_index, self.s.dt, self.model, self.data
        step = mujoco.mj_step
        if self.moving:
            for k in range(n, n + count):
                self._set_ground(k)
                step(m, d)
        else:
            gravity = m.opt.gravity
            accel = self.excitation.acceleration
            # After the pulse the load stays 0: stop setting it.
            k_end = min(n + count, max(n, math.ceil(self.excitation.end_time / dt) + 1))
            for k in range(n, k_end):
                # Mid-step load: the step's velocity change is second-order accurate.
                gravity[0] = -accel((k + 0.5) * dt)
                step(m, d)
            if k_end < n + count:
                gravity[0] = 0.0
                for _ in range(n + count - k_end):
                    step(m, d)
        self.step_index = n + count

    # ----------------------------------------------------------------- reading
    def ground_x(self) -> float:
        return float(self.data.qpos[self.ground]) if self.moving else 0.0

    def sample(self) -> tuple[float, float, float, float, float, str | None]:
        """Column angles, mean rate, pendulum state; updates the diagnostics.

        Returns ``(theta_left, theta_right, theta_dot, psi, psi_dot, problem)``
        (analytic signs) where ``problem`` names a blow-up, or None.  The
        diagnostics are taken while both columns stand (``|theta| < alpha`` at
        every sample so far): a collapse is beyond the model.
        """
        d, scene, diag = self.data, self.scene, self.diag
        qpos, qvel = d.qpos.tolist(), d.qvel.tolist()
        (al, ar), li, pe = self.columns, self.lintel, self.pendulum
        theta_l, theta_r = qpos[al + 2], qpos[ar + 2]
        theta_dot = 0.5 * (qvel[al + 2] + qvel[ar + 2])
        psi = psi_dot = 0.0
        if pe is not None:  # absolute angle: relative hinge angle plus the lintel's rotation
            psi, psi_dot = qpos[pe] + qpos[li + 2], qvel[pe] + qvel[li + 2]
        state = (theta_l, theta_r, theta_dot, psi, psi_dot)
        if not all(map(math.isfinite, qpos + qvel)):
            return (*state, "non-finite state")
        for w in self._warnings:
            if d.warning[w].number:
                return (*state, f"MuJoCo warning {mujoco.mjtWarning(w).name} "
                                f"(state reset or invalid)")
        self.standing = self.standing and max(abs(theta_l), abs(theta_r)) < scene.alpha
        gx = self.ground_x()
        v_bound = SPEED_FACTOR * math.sqrt(2.0 * scene.g * self.size) + 10.0 * abs(
            self.excitation.velocity(self.step_index * self.s.dt))
        bodies = [al, ar] + ([li] if li is not None else [])
        for a in bodies:
            drift = math.hypot(qpos[a], qpos[a + 1]) - abs(gx)
            speed = math.hypot(qvel[a], qvel[a + 1])
            if drift > DRIFT_SIZES * self.size or speed > v_bound:
                return (*state, f"a body flew away (drift {drift:.3g} m, speed {speed:.3g} m/s)")
        if pe is not None and abs(psi_dot) * scene.pendulum_length > v_bound:
            return (*state, f"pendulum speed {abs(psi_dot) * scene.pendulum_length:.3g} m/s")
        if self.standing:
            hb, hh = 0.5 * scene.b, 0.5 * scene.h
            for k, a in enumerate((al, ar)):
                theta = qpos[a + 2]
                c, s = math.cos(theta), math.sin(theta)
                cx = self.centres0[k][0] + qpos[a]
                corners = (cx - c * hb + s * hh, cx + c * hb + s * hh)  # bottom left, right
                # The pivot corner while rocking; both corners while at rest.
                idx = ((0 if theta > 0 else 1,) if abs(theta) > self.s.monitor.uplift_angle
                       else (0, 1))
                slide = max(abs(corners[i] - self.pivots0[k][i] - gx) for i in idx)
                if slide > diag["pivot_sliding_max"]:
                    diag["pivot_sliding_max"] = slide
            if li is not None and abs(qpos[li + 2]) > diag["lintel_rotation_max"]:
                diag["lintel_rotation_max"] = abs(qpos[li + 2])
            if d.ncon:  # MuJoCo's dist < 0 is penetration
                pen = -float(d.contact.dist[:d.ncon].min())
                if pen > diag["penetration_max"]:
                    diag["penetration_max"] = pen
        return (*state, None)
