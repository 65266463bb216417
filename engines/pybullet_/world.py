"""PyBullet's side of a scene: clients, solver parameters and state reading.

The bodies are built in :mod:`engines.pybullet_.bodies` from the scene's body
list (:class:`~engines.geometry.Structure`).

The analytic plane (x right, y up) is PyBullet's x-z plane (z up); the depth
``scene.depth`` runs along y.  A counter-clockwise rotation in the analytic plane
(``theta > 0``, x towards up) is a rotation about PyBullet's **-y** axis, so
``theta = -pitch`` and ``theta_dot = -omega_y``.

Bodies of the trilith (all from the :class:`~analytic.parameters.Scene` through
its Structure, nothing typed twice; the other kinds of :mod:`analytic.kinds`:
each box a multibody the same way, the drums' bob a link of the lintel):

* ground: a static box whose top face is ``z = 0`` ("gravity" base motion), or a
  very heavy box on a prismatic joint along x whose state is reset to the
  ground's motion before every step ("ground" base motion);
* two columns ``b x depth x h``, mass ``m1``, inertia ``J_G`` about y, the left
  one's left bottom corner at ``x = 0``, clear gap ``d``;
* the lintel (``mu > 0`` only), ``lintel_length x depth x lintel_thickness``,
  mass ``m3``, resting on both column tops;
* the pendulum (``gamma > 0`` only): a revolute link of the lintel multibody (its
  parent's),
  hinge on the lintel's underside at ``hinge_x`` from its middle, the point mass
  ``m4`` at distance ``l`` (the link's centre of mass), negligible own inertia,
  no collision shape and collision filter mask 0, joint motor disabled.

With ``mu = 0`` there is no lintel (a zero-mass PyBullet body is static): the
columns rock independently, which is the ``mu = 0`` rocking frame of Eq. 8.
"""
from __future__ import annotations

import math

from trilith_xval.engines._quiet_pybullet import pybullet as pb

from .bodies import Bodies

__all__ = ["pendulum_state", "body_state", "effective_slop",
           "effective_friction_erp", "effective_residual_threshold", "configure_client",
           "acquire_client", "release_client", "DT_CALIBRATED"]

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
    step needs a proportionally smaller slop, see ``engines.pybullet_.Settings``)."""
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


def pendulum_state(client: int, bodies: Bodies, parent_read: tuple | None = None
                   ) -> tuple[float, float]:
    """``(psi, psi_dot)``: the bob's absolute angle from the downward vertical,
    CCW positive (bob at hinge + l (sin psi, -cos psi)), from world positions.
    ``parent_read``: the :func:`body_state` of the bob's parent (the lintel)
    already read at this instant, if any."""
    parent, joint = bodies.parent, bodies.pendulum_joint
    state = pb.getLinkState(parent, joint, computeLinkVelocity=1, computeForwardKinematics=1,
                           physicsClientId=client)
    bob, bob_v = state[0], state[6]
    pos, quat, vel, omega = (parent_read if parent_read is not None
                             else body_state(client, parent))
    hinge = pb.multiplyTransforms(pos, quat, bodies.hinge_local, (0, 0, 0, 1))[0]
    r = [hinge[k] - pos[k] for k in range(3)]
    # Hinge velocity = v + omega x r (rigid parent).
    hv = (vel[0] + omega[1] * r[2] - omega[2] * r[1], vel[2] + omega[0] * r[1] - omega[1] * r[0])
    rx, rz = bob[0] - hinge[0], bob[2] - hinge[2]
    vx, vz = bob_v[0] - hv[0], bob_v[2] - hv[1]
    psi = math.atan2(rx, -rz)
    psi_dot = (rx * vz - rz * vx) / (rx * rx + rz * rz)
    return psi, psi_dot


def body_state(client: int, body: int) -> tuple[tuple, tuple, tuple, tuple]:
    """World ``(position, orientation, velocity, angular velocity)`` of a box (a
    multibody base)."""
    pos, quat = pb.getBasePositionAndOrientation(body, physicsClientId=client)
    vel, omega = pb.getBaseVelocity(body, physicsClientId=client)
    return pos, quat, vel, omega


# Idle DIRECT clients kept for the next World: connecting costs 10-20 ms, about
# a tenth of a short run (benchmarks/bench_overhead.py).  Every World resets its
# client (resetSimulation, every engine parameter set again), so a reused client
# gives the same numbers, bit for bit, as a new one (tests/engines/test_pybullet_small_step.py).
_IDLE_CLIENTS: list[int] = []
_MAX_IDLE_CLIENTS = 2


def acquire_client(mode: int) -> int:
    """An idle DIRECT client if one is left, else a new connection."""
    while mode == pb.DIRECT and _IDLE_CLIENTS:
        client = _IDLE_CLIENTS.pop()
        if pb.isConnected(physicsClientId=client):
            return client
    return pb.connect(mode)


def release_client(client: int, mode: int) -> None:
    """Keep a DIRECT client for the next World (up to 2), else disconnect it."""
    if mode == pb.DIRECT and len(_IDLE_CLIENTS) < _MAX_IDLE_CLIENTS:
        _IDLE_CLIENTS.append(client)
    else:
        pb.disconnect(physicsClientId=client)


def configure_client(client: int, structure, s) -> None:
    """Reset ``client`` and set every engine parameter explicitly (some are
    process-global in Bullet, so a run must not depend on what ran before).
    ``structure``: the run's :class:`~engines.geometry.Structure` (its gravity;
    its narrowest width scales the default contact breaking threshold)."""
    pb.resetSimulation(physicsClientId=client)
    pb.setPhysicsEngineParameter(
        fixedTimeStep=s.dt, numSubSteps=0, numSolverIterations=s.solver_iterations,
        contactERP=s.contact_erp, erp=s.contact_erp, frictionERP=effective_friction_erp(s),
        useSplitImpulse=1, splitImpulsePenetrationThreshold=-0.04,
        contactBreakingThreshold=s.contact_breaking_threshold or 0.01 * structure.width_scale,
        restitutionVelocityThreshold=0.2, contactSlop=effective_slop(s), enableConeFriction=0,
        deterministicOverlappingPairs=1, globalCFM=0.0,
        solverResidualThreshold=effective_residual_threshold(s), warmStartingFactor=0.85,
        physicsClientId=client)
    pb.setGravity(0.0, 0.0, -structure.g, physicsClientId=client)
