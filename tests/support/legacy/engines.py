"""Pymunk, MuJoCo, PyBullet, DART and Drake engines whose build and read hooks
are the pre-body-list code, verbatim (builders in :mod:`.pymunk_world`,
:mod:`.mujoco_world`, :mod:`.pybullet_bodies` / :mod:`.pybullet_world`,
:mod:`.dart_world` and :mod:`.drake_world`)."""
from __future__ import annotations

import math

import mujoco

from trilith_xval.engines import geometry
from trilith_xval.engines.dart_ import DartEngine
from trilith_xval.engines.diagnostics import PlaneState, Pose, joint_plane_state
from trilith_xval.engines.drake_ import DrakeEngine
from trilith_xval.engines.mujoco_ import MujocoEngine
from trilith_xval.engines.pybullet_ import PyBulletEngine
from trilith_xval.engines.pymunk_ import PymunkEngine
from trilith_xval.engines._quiet_pybullet import pybullet as pb

from . import dart_world, drake_world, mujoco_world, pybullet_world, pymunk_world
from .pybullet_bodies import build_scene as pybullet_build_scene


class LegacyPymunk(PymunkEngine):
    def build(self) -> None:
        self.world = pymunk_world.build_space(self.scene, self.settings, self.friction)
        self._read_state = pymunk_world.state_reader(self.world)

    def read(self) -> PlaneState:
        st = self._read_state()
        columns = (Pose(*st[0:6]), Pose(*st[6:12]))
        lintel = Pose(*st[12:18]) if self.world.lintel is not None else None
        psi = psi_dot = 0.0
        if self.world.bob is not None:
            i = 6 * (2 + (lintel is not None))
            psi, psi_dot = self.settings.psi0 + st[i + 2], st[i + 5]
        gx = (0.0 if self.settings.base_motion == "gravity"
              else self.excitation.displacement(self.step_index * self.settings.dt))
        return PlaneState(columns, lintel, psi, psi_dot, gx)


class LegacyMujoco(MujocoEngine):
    def build(self) -> None:
        scene, s = self.scene, self.settings
        self.xml = mujoco_world.mjcf(scene, s, self.friction)
        self.model = m = mujoco.MjModel.from_xml_string(self.xml)
        self.data = d = mujoco.MjData(m)
        self.moving = s.base_motion == "ground"

        def adr(joint: str) -> int:
            return int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)])

        self.columns = (adr("column_left_x"), adr("column_right_x"))
        self.lintel = adr("lintel_x") if scene.mu > 0.0 else None
        self.pendulum = adr("pendulum_psi") if scene.has_pendulum else None
        self.ground = adr("ground_x") if self.moving else None
        b, h, t_l = scene.b, scene.h, scene.lintel_thickness
        self.centres0 = [(x + 0.5 * b, 0.5 * h) for x in geometry.column_lefts(scene)]
        self.centres0.append((0.5 * scene.lintel_length, h + 0.5 * t_l))
        poses = geometry.rest_poses(scene, s.theta0, s.psi0)
        for a, (x, y), (x0, y0), angle in zip(
                self.columns + ((self.lintel,) if self.lintel is not None else ()),
                poses.columns + (poses.lintel,), self.centres0, (s.theta0, s.theta0, 0.0)):
            d.qpos[a:a + 3] = (x - x0, y - y0, angle)
        if self.pendulum is not None:
            d.qpos[self.pendulum] = s.psi0
        if self.moving:
            self._set_ground(0)
        mujoco.mj_forward(m, d)
        self._warnings = [int(getattr(mujoco.mjtWarning, w)) for w in mujoco_world.BAD_WARNINGS]

    def read(self) -> PlaneState:
        d = self.data
        qpos, qvel = d.qpos.tolist(), d.qvel.tolist()
        problem = None
        for w in self._warnings:
            if d.warning[w].number:
                problem = f"MuJoCo warning {mujoco.mjtWarning(w).name} (state reset or invalid)"
                break

        def pose(a: int, k: int) -> Pose:
            return Pose(self.centres0[k][0] + qpos[a], self.centres0[k][1] + qpos[a + 1],
                        qpos[a + 2], qvel[a], qvel[a + 1], qvel[a + 2])

        (al, ar), li, pe = self.columns, self.lintel, self.pendulum
        lintel = pose(li, 2) if li is not None else None
        psi = psi_dot = 0.0
        if pe is not None:
            psi, psi_dot = qpos[pe] + qpos[li + 2], qvel[pe] + qvel[li + 2]
        gx = float(qpos[self.ground]) if self.moving else 0.0
        return PlaneState((pose(al, 0), pose(ar, 1)), lintel, psi, psi_dot, gx, problem=problem)


class LegacyPyBullet(PyBulletEngine):
    def build(self, mode: int = pb.DIRECT) -> None:
        world = pybullet_world
        s, scene = self.settings, self.scene
        self.mode = mode
        self.client = c = world.acquire_client(mode)
        world.configure_client(c, scene, s)
        self.moving = s.base_motion == "ground"
        # An excitation whose window is empty (Still) never loads the bodies.
        exc = self.excitation
        self.bodies = pybullet_build_scene(c, scene, s.theta0, s.psi0, math.sqrt(self.friction),
                                           self.moving, s.friction_anchor,
                                           slop=world.effective_slop(s),
                                           under_load=exc.end_time > exc.start_time)
        self.start_y = {body: pb.getBasePositionAndOrientation(body, physicsClientId=c)[0][1]
                        for body in self.bodies.dynamic}
        if self.moving:
            self._set_ground(0)

    def read(self) -> PlaneState:
        world = pybullet_world
        c, bodies = self.client, self.bodies
        # Each body is read once per sample: a sample's reads cost about two steps
        # (benchmarks/bench_overhead.py), so re-reading would slow every run.
        poses, drift, roll_yaw = [], 0.0, 0.0
        for body in bodies.columns:
            theta, theta_dot, pos, quat = world.column_angle(c, body)
            vel = pb.getBaseVelocity(body, physicsClientId=c)[0]
            poses.append(Pose(pos[0], pos[2], theta, vel[0], vel[2], theta_dot))
            drift, roll_yaw = self._out_of_plane(body, pos, quat, drift, roll_yaw)
        lintel = psi = psi_dot = None
        if bodies.lintel is not None:
            read = world.lintel_state(c, bodies)
            pos, quat, vel, omega = read
            m = pb.getMatrixFromQuaternion(quat)
            lintel = Pose(pos[0], pos[2], math.atan2(-m[2], m[8]), vel[0], vel[2], -omega[1])
            drift, roll_yaw = self._out_of_plane(bodies.lintel, pos, quat, drift, roll_yaw)
            if bodies.pendulum_joint is not None:
                psi, psi_dot = world.pendulum_state(c, bodies, read)
        gx = (pb.getJointState(bodies.ground, 0, physicsClientId=c)[0] if self.moving else 0.0)
        return PlaneState((poses[0], poses[1]), lintel, psi or 0.0, psi_dot or 0.0, gx, drift,
                          roll_yaw)

    def _set_ground(self, step: int) -> None:
        x, v = self.ground_motion(step)
        pb.resetJointState(self.bodies.ground, 0, x, v, physicsClientId=self.client)

    def _out_of_plane(self, body, pos, quat, drift, roll_yaw) -> tuple[float, float]:
        roll, _, yaw = pb.getEulerFromQuaternion(quat)
        return (max(drift, abs(pos[1] - self.start_y[body])),
                max(roll_yaw, abs(roll), abs(yaw)))


class LegacyDart(DartEngine):
    def build(self) -> None:
        s = self.settings
        self.world = dart_world.DartWorld(self.scene, s.dt, self.friction, s.detector, s.theta0,
                                          s.psi0)

    def read(self) -> PlaneState:
        world = self.world
        return joint_plane_state(world.planar_states(),
                                 world.pendulum_state() if world.pendulum is not None else None)


class LegacyDrake(DrakeEngine):
    def build(self) -> None:
        s, scene = self.settings, self.scene
        self.world = drake_world.DrakeWorld(scene, s.dt, self.friction, s.contact_model,
                                            s.solver, s.stiffness(scene),
                                            s.sap_relaxation_time(scene), s.dissipation,
                                            s.sphere_fraction * scene.b, s.hydroelastic_modulus,
                                            s.theta0, s.psi0)

    def read(self) -> PlaneState:
        world = self.world
        return joint_plane_state(world.planar_states(),
                                 world.pendulum_state() if world.pendulum is not None else None)
