"""Building the trilith in a PyBullet world, stepping it and reading its state back.

The bodies themselves are built in :mod:`engines.pybullet_bodies`.

The analytic plane (x right, y up) is PyBullet's x-z plane (z up); the depth
``scene.depth`` runs along y.  A counter-clockwise rotation in the analytic plane
(``theta > 0``, x towards up) is a rotation about PyBullet's **-y** axis, so
``theta = -pitch`` and ``theta_dot = -omega_y``.

Bodies (all from the :class:`~analytic.parameters.Scene`, nothing typed twice):

* ground: a static box whose top face is ``z = 0`` ("gravity" base motion), or a
  very heavy box on a prismatic joint along x whose state is reset to the
  ground's motion before every step ("ground" base motion);
* two columns ``b x depth x h``, mass ``m1``, inertia ``J_G`` about y, the left
  one's left bottom corner at ``x = 0``, clear gap ``d``;
* the lintel (``mu > 0`` only), ``lintel_length x depth x lintel_thickness``,
  mass ``m3``, resting on both column tops;
* the pendulum (``gamma > 0`` only): a revolute link of the lintel multibody,
  hinge on the lintel's underside at ``hinge_x`` from its middle, the point mass
  ``m4`` at distance ``l`` (the link's centre of mass), negligible own inertia,
  no collision shape and collision filter mask 0, joint motor disabled.

With ``mu = 0`` there is no lintel (a zero-mass PyBullet body is static): the
columns rock independently, which is the ``mu = 0`` rocking frame of Eq. 8.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from engines._quiet_pybullet import pybullet as pb

# Body construction lives in engines.pybullet_bodies; re-exported here because
# the adapter, tests and benchmarks import it through this module.
from engines.pybullet_bodies import (GROUND_MASS_FACTOR, NEGLIGIBLE_MASS_FRACTION,  # noqa: F401
                                     Bodies, build_scene, initial_poses)

if TYPE_CHECKING:  # annotation only: the adapter imports this module
    from engines.pybullet_engine import Settings

__all__ = ["Bodies", "World", "build_scene", "initial_poses", "column_angle",
           "pendulum_state", "lintel_state", "effective_slop", "effective_friction_erp",
           "effective_residual_threshold", "DT_CALIBRATED"]

# The step [s] the per-step solver settings were calibrated at; below it they are
# scaled so that they mean the same in time (docs/engine-trust.md, "PyBullet at
# small steps"); at and above it they are used as calibrated.
DT_CALIBRATED = 1e-4


def _step_ratio(settings) -> float:
    """``min(1, dt / DT_CALIBRATED)``: exactly 1.0 at the calibrated step."""
    return min(1.0, settings.dt / DT_CALIBRATED)


def effective_slop(settings) -> float:
    """Bullet's ``contactSlop`` [m] for ``settings``: the given value, else
    ``min(1e-4, dt * 1 m/s)`` (calibrated 1e-4 m at the default step; a smaller
    step needs a proportionally smaller slop, see ``pybullet_engine.Settings``)."""
    if settings.contact_slop is not None:
        return settings.contact_slop
    return min(1e-4, settings.dt * 1.0)


def effective_friction_erp(settings) -> float:
    """Bullet's ``frictionERP`` for ``settings``: the given ``friction_erp``, else
    ``contact_erp * min(1, dt / 1e-4)``.  With friction anchors Bullet pulls a
    drifted anchor back at ``frictionERP * drift / dt`` (btMultiBodyConstraintSolver):
    a fixed fraction per step is a relaxation time ``dt / erp`` that shrinks with
    the step; scaled, it stays the calibrated 0.5 ms."""
    if settings.friction_erp is not None:
        return settings.friction_erp
    return settings.contact_erp * _step_ratio(settings)


def effective_residual_threshold(settings) -> float:
    """Bullet's ``solverResidualThreshold`` [(m/s)^2] for ``settings``: the given
    ``solver_residual_threshold``, else ``1e-7 * min(1, dt / 1e-4)^2``.  The
    solver stops iterating when the largest squared velocity change of an
    iteration falls below it; a step's velocity changes scale with ``dt``, so a
    fixed threshold stops a small step's solver after fewer iterations."""
    if settings.solver_residual_threshold is not None:
        return settings.solver_residual_threshold
    return 1e-7 * _step_ratio(settings) ** 2


def column_angle(client: int, body: int) -> tuple[float, float, tuple, tuple]:
    """``(theta, theta_dot, position, orientation)`` of a column (analytic signs)."""
    pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    _, omega = pb.getBaseVelocity(body, physicsClientId=client)
    m = pb.getMatrixFromQuaternion(quat)
    # The column's up axis is the third column of R: (m[2], m[5], m[8]).
    theta = math.atan2(-m[2], m[8])
    return theta, -omega[1], pos, quat


def pendulum_state(client: int, bodies: Bodies, lintel_read: tuple | None = None
                   ) -> tuple[float, float]:
    """``(psi, psi_dot)``: the bob's absolute angle from the downward vertical,
    CCW positive (bob at hinge + l (sin psi, -cos psi)), from world positions.
    ``lintel_read``: the :func:`lintel_state` already read at this instant, if any."""
    lintel, joint = bodies.lintel, bodies.pendulum_joint
    state = pb.getLinkState(lintel, joint, computeLinkVelocity=1, computeForwardKinematics=1,
                           physicsClientId=client)
    bob, bob_v = state[0], state[6]
    pos, quat, vel, omega = (lintel_read if lintel_read is not None
                             else lintel_state(client, bodies))
    hinge = pb.multiplyTransforms(pos, quat, bodies.hinge_local, (0, 0, 0, 1))[0]
    r = [hinge[k] - pos[k] for k in range(3)]
    # Hinge velocity = v + omega x r (rigid lintel).
    hv = (vel[0] + omega[1] * r[2] - omega[2] * r[1], vel[2] + omega[0] * r[1] - omega[1] * r[0])
    rx, rz = bob[0] - hinge[0], bob[2] - hinge[2]
    vx, vz = bob_v[0] - hv[0], bob_v[2] - hv[1]
    psi = math.atan2(rx, -rz)
    psi_dot = (rx * vz - rz * vx) / (rx * rx + rz * rz)
    return psi, psi_dot


def lintel_state(client: int, bodies: Bodies) -> tuple[tuple, tuple, tuple, tuple]:
    """World ``(position, orientation, velocity, angular velocity)`` of the lintel."""
    if bodies.lintel_link < 0:
        pos, quat = pb.getBasePositionAndOrientation(bodies.lintel, physicsClientId=client)
        vel, omega = pb.getBaseVelocity(bodies.lintel, physicsClientId=client)
        return pos, quat, vel, omega
    st = pb.getLinkState(bodies.lintel, bodies.lintel_link, computeLinkVelocity=1,
                         computeForwardKinematics=1, physicsClientId=client)
    return st[0], st[1], st[6], st[7]


# Idle DIRECT clients kept for the next World: connecting costs 10-20 ms, about
# a tenth of a short run (benchmarks/bench_overhead.py).  Every World resets its
# client (resetSimulation, every engine parameter set again), so a reused client
# gives the same numbers, bit for bit, as a new one (tests/test_pybullet_small_step.py).
_IDLE_CLIENTS: list[int] = []
_MAX_IDLE_CLIENTS = 2


def _acquire_client(mode: int) -> int:
    """An idle DIRECT client if one is left, else a new connection."""
    while mode == pb.DIRECT and _IDLE_CLIENTS:
        client = _IDLE_CLIENTS.pop()
        if pb.isConnected(physicsClientId=client):
            return client
    return pb.connect(mode)


def _release_client(client: int, mode: int) -> None:
    """Keep a DIRECT client for the next World (up to 2), else disconnect it."""
    if mode == pb.DIRECT and len(_IDLE_CLIENTS) < _MAX_IDLE_CLIENTS:
        _IDLE_CLIENTS.append(client)
    else:
        pb.disconnect(physicsClientId=client)


class World:
    """One PyBullet client with the scene built; steps it and reads its state.

    ``s`` is an :class:`engines.pybullet_engine.Settings` (validated by the
    caller); ``friction`` the contact coefficient (each body gets its square
    root: Bullet multiplies the two bodies' values).  A DIRECT client is taken
    from the idle ones left by closed Worlds when there is one, and reset.
    """

    def __init__(self, scene, excitation, s: Settings, friction: float, mode: int = pb.DIRECT):
        self.scene, self.excitation, self.s = scene, excitation, s
        self.mode = mode
        self.client = _acquire_client(mode)
        c = self.client
        cbt = s.contact_breaking_threshold or 0.01 * scene.b
        # Every parameter set explicitly: some are process-global in Bullet.
        pb.resetSimulation(physicsClientId=c)
        pb.setPhysicsEngineParameter(
            fixedTimeStep=s.dt, numSubSteps=0, numSolverIterations=s.solver_iterations,
            contactERP=s.contact_erp, erp=s.contact_erp, frictionERP=effective_friction_erp(s),
            useSplitImpulse=1, splitImpulsePenetrationThreshold=-0.04,
            contactBreakingThreshold=cbt, restitutionVelocityThreshold=0.2,
            contactSlop=effective_slop(s), enableConeFriction=0, deterministicOverlappingPairs=1,
            globalCFM=0.0,
            solverResidualThreshold=effective_residual_threshold(s), warmStartingFactor=0.85,
            physicsClientId=c)

        self.moving = s.base_motion == "ground"
        pb.setGravity(0.0, 0.0, -scene.g, physicsClientId=c)
        self.bodies = build_scene(c, scene, s.theta0, s.psi0, math.sqrt(friction), self.moving,
                                  s.friction_anchor, slop=effective_slop(s))
        self.size = max(scene.lintel_length, scene.h)
        self.start = {bid: self._pose(bid)[0] for bid in self.bodies.dynamic}
        # Bottom corners of the upright columns (the scene's geometry, not the
        # possibly tilted start).
        b, d = scene.b, scene.d
        self.pivots0 = [(0.0, b), (b + d, 2.0 * b + d)]
        self.diag = dict(lintel_rotation_max=0.0, pivot_sliding_max=0.0, penetration_max=0.0,
                         out_of_plane_max=0.0, out_of_plane_rotation_max=0.0, friction=friction)
        self.step_index = 0
        self.standing = True  # see sample()
        if self.moving:
            self._set_ground(0)

    def close(self) -> None:
        """Hand the client back (idempotent): kept for the next World or disconnected."""
        if self.client is not None:
            client, self.client = self.client, None
            _release_client(client, self.mode)

    # ---------------------------------------------------------------- stepping
    def _set_ground(self, n: int) -> None:
        """Reset the ground link to x_g(t_n), moving at the mean velocity of step n."""
        dt, ex = self.s.dt, self.excitation
        x0, x1 = ex.displacement(n * dt), ex.displacement((n + 1) * dt)
        pb.resetJointState(self.bodies.ground, 0, x0, (x1 - x0) / dt, physicsClientId=self.client)

    def step(self) -> None:
        self.advance(1)

    def advance(self, count: int) -> None:
        """``count`` steps.  One loop with local names: stepping is the hot path
        (a call through ``step`` per step costs ~3 % of the run,
        ``benchmarks/bench_overhead.py``)."""
        n, dt, c = self.step_index, self.s.dt, self.client
        accel, minus_g = self.excitation.acceleration, -self.scene.g
        set_gravity, step = pb.setGravity, pb.stepSimulation
        if self.moving:
            for k in range(n, n + count):
                self._set_ground(k)
                step(physicsClientId=c)
                self.step_index = k + 1
            return
        try:
            for k in range(n, n + count):
                # Mid-step load: the step's velocity change is then second-order accurate.
                set_gravity(-accel((k + 0.5) * dt), 0.0, minus_g, physicsClientId=c)
                step(physicsClientId=c)
        finally:  # the steps taken, even if one raised
            self.step_index = k + 1 if count > 0 else n

    # ----------------------------------------------------------------- reading
    def _pose(self, body: int) -> tuple[tuple, tuple, tuple]:
        if body == self.bodies.lintel:
            return lintel_state(self.client, self.bodies)[:3]
        pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=self.client)
        return pos, quat, pb.getBaseVelocity(body, physicsClientId=self.client)[0]

    def _bottom_corners(self, body: int, pos=None, quat=None,
                        which: tuple[int, ...] = (0, 1)) -> tuple[float, ...]:
        """World x of a column's bottom-left (0) and bottom-right (1) edge
        midpoints, those in ``which`` (``pos``, ``quat``: its pose if already
        read at this instant)."""
        if pos is None:
            pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=self.client)
        hb, hh = 0.5 * self.scene.b, 0.5 * self.scene.h
        return tuple(pb.multiplyTransforms(pos, quat, ((-hb, hb)[i], 0.0, -hh), (0, 0, 0, 1))[0][0]
                     for i in which)

    def ground_x(self) -> float:
        if not self.moving:
            return 0.0
        return pb.getJointState(self.bodies.ground, 0, physicsClientId=self.client)[0]

    def sample(self) -> tuple[float, float, float, float, float, str | None]:
        """Column angles, mean rate, pendulum state; updates the diagnostics.

        Returns ``(theta_left, theta_right, theta_dot, psi, psi_dot, problem)``
        where ``problem`` names a blow-up, or None.  The rocking diagnostics
        (sliding, penetration, lintel rotation, out-of-plane motion) are taken
        while both columns stand (``|theta| < alpha`` at every sample so far): a
        collapse, with the lintel falling off, is beyond the model and not a
        numerical problem.
        """
        c, bodies, scene, diag = self.client, self.bodies, self.scene, self.diag
        cols = [column_angle(c, body) for body in bodies.columns]
        theta_l, theta_r = cols[0][0], cols[1][0]
        # Standing until a column first passes alpha: past it the columns may hop
        # and part (the model's vertical reaction turns negative in the fall), and
        # one swinging back below alpha is still the collapse, beyond the model.
        self.standing = self.standing and max(abs(theta_l), abs(theta_r)) < scene.alpha
        standing = self.standing
        psi = psi_dot = 0.0
        # Each body is read once per sample: a sample's reads cost about two steps
        # (benchmarks/bench_overhead.py), so re-reading would slow every run.
        lintel = lintel_state(c, bodies) if bodies.lintel is not None else None
        if bodies.pendulum_joint is not None:
            psi, psi_dot = pendulum_state(c, bodies, lintel)
        problem = None
        gx = self.ground_x()
        v_bound = 20.0 * math.sqrt(2.0 * scene.g * self.size) + 10.0 * abs(
            self.excitation.velocity(self.step_index * self.s.dt))
        poses = {body: (col[2], col[3], pb.getBaseVelocity(body, physicsClientId=c)[0])
                 for body, col in zip(bodies.columns, cols)}
        if lintel is not None:
            poses[bodies.lintel] = lintel[:3]
        for body in bodies.dynamic:
            pos, quat, vel = poses[body]
            if not all(map(math.isfinite, pos + vel + quat)):
                return theta_l, theta_r, 0.0, psi, psi_dot, "non-finite body state"
            drift = math.dist(pos, self.start[body]) - abs(gx)
            speed = math.hypot(*vel)
            if drift > 10.0 * self.size or speed > v_bound:
                problem = f"body {body} flew away (drift {drift:.3g} m, speed {speed:.3g} m/s)"
            if standing:
                roll, pitch, yaw = pb.getEulerFromQuaternion(quat)
                diag["out_of_plane_max"] = max(diag["out_of_plane_max"],
                                               abs(pos[1] - self.start[body][1]))
                diag["out_of_plane_rotation_max"] = max(diag["out_of_plane_rotation_max"],
                                                        abs(roll), abs(yaw))
                if body == bodies.lintel:
                    diag["lintel_rotation_max"] = max(diag["lintel_rotation_max"], abs(pitch))
        if abs(psi_dot) * bodies.length > v_bound:
            problem = f"pendulum speed {abs(psi_dot) * bodies.length:.3g} m/s"
        if standing:
            for k, body in enumerate(bodies.columns):
                theta = cols[k][0]
                # The pivot corner while rocking; both corners while at rest.
                idx = ((0 if theta > 0 else 1,) if abs(theta) > self.s.monitor.uplift_angle
                       else (0, 1))
                corners = self._bottom_corners(body, cols[k][2], cols[k][3], idx)
                slide = max(abs(x - self.pivots0[k][i] - gx) for x, i in zip(corners, idx))
                diag["pivot_sliding_max"] = max(diag["pivot_sliding_max"], slide)
            points = pb.getContactPoints(physicsClientId=c)
            if points:  # max of -distance = -(min distance), exactly
                diag["penetration_max"] = max(diag["penetration_max"],
                                              -min(point[8] for point in points))
            if diag["out_of_plane_max"] > self.s.out_of_plane_limit * self.size:
                problem = f"out-of-plane drift {diag['out_of_plane_max']:.3g} m"
        return theta_l, theta_r, 0.5 * (cols[0][1] + cols[1][1]), psi, psi_dot, problem
