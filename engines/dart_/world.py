"""A scene in DART (dartpy): planar rigid boxes on a box ground, rigid LCP contact.

The world is built from the scene's body list (:class:`~engines.geometry.Structure`:
the trilith, the block, or another kind of :mod:`analytic.kinds`, each box a
planar skeleton the same way).  Bodies of the trilith (all sizes read from
:class:`analytic.parameters.Scene` through its Structure):

* the ground, a welded box whose top face is ``z = 0`` (a separate skeleton);
* each column and the lintel, one skeleton each with a :class:`PlanarJoint` in
  the vertical x-z plane (coordinates ``x``, ``z`` of the centre and the angle
  about ``-y``, so the angle is the analytic CCW one): 3D box contacts, bodies
  kept in the plane as the model is (as MuJoCo's slide-slide-hinge);
* the pendulum, a revolute joint (axis ``-y``) on the lintel (its parent box) at the hinge, the
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
    """A fresh DART world holding one scene at rest (nothing shared between runs).

    Parameters
    ----------
    structure : engines.geometry.Structure
        The scene's body list at the start of the run
        (:func:`~engines.geometry.structure_of` at ``theta0``, ``psi0``).
    dt : float
        Time step [s].
    friction : float
        Coulomb coefficient given to every shape; DART takes the smaller of two
        shapes' values, so every contact gets exactly this one.
    detector : {'dart', 'fcl', 'bullet', 'ode'}
        Collision detector.
    deactivation : bool
        Keep dartpy's body deactivation (its default, True) or switch it off.

    The planar joints hang from the world origin, so a body's coordinates are
    its centre ``(x, z)`` and CCW angle in the analytic plane.  Skeletons are
    added in the structure's order after the ground, with the calls of the
    trilith's builder before the body list, in its order (the trilith's world is
    unchanged bit for bit, ``tests/engines/test_structure_3d.py``).
    """

    def __init__(self, structure, dt: float, friction: float, detector: str,
                 deactivation: bool = True):
        self.structure = structure
        self.world = w = dart.simulation.World()
        if not deactivation:
            # dartpy 6.20 puts bodies to sleep by default (slower than 0.01 m/s and
            # 0.05 rad/s for 0.5 s: every velocity set to 0); docs/dart.md.
            options = w.getDeactivationOptions()
            options.mEnabled = False
            w.setDeactivationOptions(options)
        w.setTimeStep(dt)
        w.setGravity([0.0, 0.0, -structure.g])
        w.getConstraintSolver().setCollisionDetector(_detector(detector))
        self.friction = friction
        depth = structure.depth
        centre_x, *g_half = structure.ground
        ground = dart.dynamics.Skeleton("ground")
        joint, body = ground.createWeldJointAndBodyNodePair()
        joint.setTransformFromParentBodyNode(_placed(centre_x, -g_half[2]))
        self._shape(body, [2.0 * v for v in g_half])
        w.addSkeleton(ground)
        self.skeletons = []
        for box in structure.bodies:
            skel = dart.dynamics.Skeleton(box.name)
            joint, body = skel.createPlanarJointAndBodyNodePair()
            # Translations along x and z, rotation about x cross z = -y: CCW angle.
            joint.setArbitraryPlane([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
            # Only the inertia about y enters a planar motion (a column's: J_G of
            # the scene, which the structure gives on all three axes).
            body.setInertia(dart.dynamics.Inertia(box.mass, [0.0, 0.0, 0.0],
                                                  np.diag(box.inertia)))
            self._shape(body, (box.b, depth, box.h))
            skel.setPositions(list(box.start))
            w.addSkeleton(skel)
            self.skeletons.append(skel)
        self.pendulum = self.parent_index = None
        spec = structure.bob
        if spec is not None:
            self.parent_index = k = structure.index(spec.parent)
            parent = self.skeletons[k]
            hinge, bob = parent.createRevoluteJointAndBodyNodePair(parent.getBodyNode(0))
            hinge.setAxis([0.0, -1.0, 0.0])
            hinge.setTransformFromParentBodyNode(_placed(*spec.anchor))
            l, m4 = spec.length, spec.mass
            bob.setInertia(dart.dynamics.Inertia(
                m4, [0.0, 0.0, -l], np.eye(3) * (NEGLIGIBLE_INERTIA_FRACTION * m4 * l * l)))
            # Relative to the parent, turned by its start angle.
            hinge.setPosition(0, spec.psi0 - structure.bodies[k].start[2])
            self.pendulum = hinge

    def _shape(self, body, size) -> None:
        node = body.createShapeNode(dart.dynamics.BoxShape(list(size)))
        node.createCollisionAspect()
        dyn = node.createDynamicsAspect()
        dyn.setFrictionCoeff(self.friction)
        dyn.setRestitutionCoeff(0.0)

    def steps(self, loads) -> None:
        """One step per horizontal base-frame load [m/s^2] in ``loads``."""
        w, g = self.world, -self.structure.g
        set_gravity, step = w.setGravity, w.step
        for a in loads:
            set_gravity([a, 0.0, g])
            step()

    def planar_states(self) -> list[list[float]]:
        """``[x, z, angle, vx, vz, omega]`` of each box in the structure's order
        (the bob's parent skeleton carries its hinge as a fourth coordinate)."""
        return [[*skel.getPositions()[:3], *skel.getVelocities()[:3]] for skel in self.skeletons]

    def pendulum_state(self) -> tuple[float, float]:
        """Relative hinge angle and rate (add the parent's for the absolute)."""
        return float(self.pendulum.getPosition(0)), float(self.pendulum.getVelocity(0))

    def close(self) -> None:
        self.world.removeAllSkeletons()
        self.world = None
