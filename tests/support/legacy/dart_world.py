"""LEGACY COPY (tests only) of the pre-body-list builder.

The trilith in DART (dartpy): planar rigid boxes on a box ground, rigid LCP contact.

Bodies (all sizes read from :class:`analytic.parameters.Scene`):

* the ground, a welded box whose top face is ``z = 0`` (a separate skeleton);
* each column and the lintel, one skeleton each with a :class:`PlanarJoint` in
  the vertical x-z plane (coordinates ``x``, ``z`` of the centre and the angle
  about ``-y``, so the angle is the analytic CCW one): 3D box contacts, bodies
  kept in the plane as the model is (as MuJoCo's slide-slide-hinge);
* the pendulum, a revolute joint (axis ``-y``) on the lintel at the hinge, the
  point mass ``m4`` at ``l`` below it, with no collision shape: it collides with
  nothing, like the analytic pendulum.

Contact is DART's own: its box-box collision detector and the boxed LCP
(Dantzig) of the constraint solver, an impulse-based rigid contact, so a
corner impact is plastic without any tuning (restitution coefficients 0; at
these impact speeds DART's coefficient had no effect anyway).

The base excitation enters as the d'Alembert load ``-xg_ddot(t + dt/2)``, a
horizontal gravity component in the base frame (DART lets gravity change
between steps).
"""
from __future__ import annotations

import dartpy as dart
import numpy as np

from trilith_xval.engines import geometry

__all__ = ["DartWorld", "COLLISION_DETECTORS", "NEGLIGIBLE_INERTIA_FRACTION"]

COLLISION_DETECTORS = ("dart", "fcl", "bullet", "ode")
# Own inertia of the bob relative to m4 l^2: a point mass to 1e-6, yet a regular
# (positive definite) body inertia.
NEGLIGIBLE_INERTIA_FRACTION = 1e-6


def _placed(x: float, z: float) -> "dart.math.Isometry3":
    tf = dart.math.Isometry3()
    tf.set_translation([x, 0.0, z])
    return tf


def _detector(name: str):
    return {"dart": dart.collision.DARTCollisionDetector,
            "fcl": dart.collision.FCLCollisionDetector,
            "bullet": dart.collision.BulletCollisionDetector,
            "ode": dart.collision.OdeCollisionDetector}[name]()


class DartWorld:
    """A fresh DART world holding one trilith at rest (nothing shared between runs).

    Parameters
    ----------
    scene : analytic.parameters.Scene
    dt : float
        Time step [s].
    friction : float
        Coulomb coefficient given to every shape; DART takes the smaller of two
        shapes' values, so every contact gets exactly this one.
    detector : {'dart', 'fcl', 'bullet', 'ode'}
        Collision detector.
    theta0, psi0 : float
        Initial tilt of the columns and absolute pendulum angle [rad], at rest.

    The planar joints hang from the world origin, so a body's coordinates are
    its centre ``(x, z)`` and CCW angle in the analytic plane.
    """

    def __init__(self, scene, dt: float, friction: float, detector: str,
                 theta0: float, psi0: float):
        self.scene = scene
        self.world = w = dart.simulation.World()
        w.setTimeStep(dt)
        w.setGravity([0.0, 0.0, -scene.g])
        w.getConstraintSolver().setCollisionDetector(_detector(detector))
        self.friction = friction
        b, h, depth = scene.b, scene.h, scene.depth
        span, t_l = scene.lintel_length, scene.lintel_thickness
        g_half = geometry.ground_box(scene)
        ground = dart.dynamics.Skeleton("ground")
        joint, body = ground.createWeldJointAndBodyNodePair()
        joint.setTransformFromParentBodyNode(_placed(0.5 * span, -g_half[2]))
        self._shape(body, [2.0 * v for v in g_half])
        w.addSkeleton(ground)
        poses = geometry.rest_poses(scene, theta0, psi0)
        bodies = [("column_left", poses.columns[0], theta0, scene.m1, (b, depth, h)),
                  ("column_right", poses.columns[1], theta0, scene.m1, (b, depth, h))]
        if scene.mu > 0.0:
            bodies.append(("lintel", poses.lintel, 0.0, scene.m3, (span, depth, t_l)))
        self.skeletons = []
        for name, (x, z), angle, mass, size in bodies:
            skel = dart.dynamics.Skeleton(name)
            joint, body = skel.createPlanarJointAndBodyNodePair()
            # Translations along x and z, rotation about x cross z = -y: CCW angle.
            joint.setArbitraryPlane([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
            if name == "lintel":
                moment = np.diag(geometry.box_inertia(mass, *size))
            else:  # only the inertia about y enters a planar motion: J_G of the scene
                moment = np.diag([scene.inertia_J_G] * 3)
            body.setInertia(dart.dynamics.Inertia(mass, [0.0, 0.0, 0.0], moment))
            self._shape(body, size)
            skel.setPositions([x, z, angle])
            w.addSkeleton(skel)
            self.skeletons.append(skel)
        self.pendulum = None
        if scene.has_pendulum:
            lintel = self.skeletons[2]
            hinge, bob = lintel.createRevoluteJointAndBodyNodePair(lintel.getBodyNode(0))
            hinge.setAxis([0.0, -1.0, 0.0])
            hinge.setTransformFromParentBodyNode(_placed(scene.hinge_x, -0.5 * t_l))
            l, m4 = scene.pendulum_length, scene.m4
            bob.setInertia(dart.dynamics.Inertia(
                m4, [0.0, 0.0, -l], np.eye(3) * (NEGLIGIBLE_INERTIA_FRACTION * m4 * l * l)))
            hinge.setPosition(0, psi0)  # relative to the lintel, which starts unrotated
            self.pendulum = hinge

    def _shape(self, body, size) -> None:
        node = body.createShapeNode(dart.dynamics.BoxShape(list(size)))
        node.createCollisionAspect()
        dyn = node.createDynamicsAspect()
        dyn.setFrictionCoeff(self.friction)
        dyn.setRestitutionCoeff(0.0)

    def steps(self, loads) -> None:
        """One step per horizontal base-frame load [m/s^2] in ``loads``."""
        w, g = self.world, -self.scene.g
        set_gravity, step = w.setGravity, w.step
        for a in loads:
            set_gravity([a, 0.0, g])
            step()

    def planar_states(self) -> list[list[float]]:
        """``[x, z, angle, vx, vz, omega]`` of each column and the lintel (the
        lintel's skeleton carries the pendulum hinge as a fourth coordinate)."""
        return [[*skel.getPositions()[:3], *skel.getVelocities()[:3]] for skel in self.skeletons]

    def pendulum_state(self) -> tuple[float, float]:
        """Relative hinge angle and rate (add the lintel's for the absolute)."""
        return float(self.pendulum.getPosition(0)), float(self.pendulum.getVelocity(0))

    def close(self) -> None:
        self.world.removeAllSkeletons()
        self.world = None
