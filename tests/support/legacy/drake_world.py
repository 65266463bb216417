"""LEGACY COPY (tests only) of the pre-body-list builder.

The trilith in Drake: a discrete MultibodyPlant of planar bodies with compliant contact.

Bodies (all sizes read from :class:`analytic.parameters.Scene`):

* the ground, a box welded to the world whose top face is ``z = 0``;
* each column and the lintel, a body on a :class:`PlanarJoint` whose plane is
  the vertical x-z plane (coordinates ``x``, ``z`` of the centre and the angle
  about ``-y``, the analytic CCW one);
* the pendulum, a revolute joint (axis ``-y``) on the lintel at the hinge, the
  point mass ``m4`` at ``l`` below it, with no collision geometry.

Contact (``contact_model``):

* ``'point'``: each column touches the ground and the lintel through eight
  small spheres at its corners (inset so that they are tangent to the box
  faces); the ground and the lintel are boxes.  Box-on-box point contact is
  poorer (its contact point jumps between corners) and slower.
* ``'hydroelastic'``: compliant column and lintel boxes (pressure field of
  modulus ``hydroelastic_modulus``) on a rigid ground box.

Drake 1.51 cannot change gravity during a run, so the base excitation enters
as applied forces ``-m xg_ddot(t + dt/2)`` at every body's centre of mass
(the d'Alembert load of a rigid translating base, as the other engines' horizontal
gravity component).
"""
from __future__ import annotations

import math

import numpy as np
from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial,
                              AddRigidHydroelasticProperties, Box, ProximityProperties, Sphere)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction,
                                     ExternallyAppliedSpatialForce, MultibodyPlantConfig)
from pydrake.multibody.tree import (FixedOffsetFrame, PlanarJoint, RevoluteJoint,
                                    RotationalInertia, SpatialInertia)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from trilith_xval.engines import geometry

__all__ = ["DrakeWorld", "CONTACT_MODELS", "SOLVERS", "NEGLIGIBLE_INERTIA_FRACTION"]

CONTACT_MODELS = ("point", "hydroelastic")
SOLVERS = ("sap", "lagged", "similar")  # TAMSI is deprecated in 1.51
NEGLIGIBLE_INERTIA_FRACTION = 1e-6
# The plane frame: its x-y plane is the world's x-z plane, its z axis the world's -y.
_PLANE = RollPitchYaw(0.5 * math.pi, 0.0, 0.0).ToRotationMatrix()


class DrakeWorld:
    """A fresh Drake diagram holding one trilith (nothing shared between runs).

    Parameters
    ----------
    scene : analytic.parameters.Scene
    dt : float
        Discrete time step [s] of the plant.
    friction : float
        Coulomb coefficient (static = dynamic) of every geometry; Drake combines
        two values ``2 f1 f2 / (f1 + f2)``, so equal values give exactly this one.
    contact_model, solver : str
        See :data:`CONTACT_MODELS`, :data:`SOLVERS` (Drake's discrete contact
        approximations).
    stiffness : float
        Point-contact stiffness [N/m] of one contact pair.  Drake puts two
        geometries' stiffnesses in series, so each geometry gets ``2 stiffness``.
    relaxation_time : float
        SAP's dissipation time scale [s] of one contact pair; Drake adds the two
        geometries' values, so each gets half.
    dissipation : float
        Hunt-Crossley dissipation [s/m] (the non-SAP approximations).
    sphere_radius : float
        Radius [m] of the corner spheres (point contact).
    hydroelastic_modulus : float
        Pressure-field modulus [Pa] of the compliant boxes (hydroelastic contact).
    theta0, psi0 : float
        Initial tilt of the columns and absolute pendulum angle [rad], at rest.

    The planar joints hang from one frame at the world origin, so a body's
    coordinates are its centre ``(x, z)`` and CCW angle in the analytic plane.
    """

    def __init__(self, scene, dt: float, friction: float, contact_model: str, solver: str,
                 stiffness: float, relaxation_time: float, dissipation: float,
                 sphere_radius: float, hydroelastic_modulus: float, theta0: float, psi0: float):
        self.scene = scene
        builder = DiagramBuilder()
        config = MultibodyPlantConfig(time_step=dt, contact_model=contact_model,
                                      discrete_contact_approximation=solver)
        self.plant, self.scene_graph = plant, _ = AddMultibodyPlant(config, builder)
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -scene.g])

        def props(rigid_hydro: bool = False) -> ProximityProperties:
            p = ProximityProperties()
            AddContactMaterial(dissipation, 2.0 * stiffness,
                               CoulombFriction(friction, friction), p)
            p.AddProperty("material", "relaxation_time", 0.5 * relaxation_time)
            if contact_model == "hydroelastic":
                if rigid_hydro:
                    AddRigidHydroelasticProperties(p)
                else:
                    AddCompliantHydroelasticProperties(0.1 * scene.b, hydroelastic_modulus, p)
            return p

        b, h, depth = scene.b, scene.h, scene.depth
        span, t_l = scene.lintel_length, scene.lintel_thickness
        g_half = geometry.ground_box(scene)
        world = plant.world_body()
        plant.RegisterCollisionGeometry(
            world, RigidTransform([0.5 * span, 0.0, -g_half[2]]), Box(*(2.0 * v for v in g_half)),
            "ground", props(rigid_hydro=True))
        poses = geometry.rest_poses(scene, theta0, psi0)
        bodies = [("column_left", poses.columns[0], theta0, scene.m1, (b, depth, h)),
                  ("column_right", poses.columns[1], theta0, scene.m1, (b, depth, h))]
        if scene.mu > 0.0:
            bodies.append(("lintel", poses.lintel, 0.0, scene.m3, (span, depth, t_l)))
        plane = plant.AddFrame(FixedOffsetFrame("plane", world, RigidTransform(_PLANE)))
        self.bodies, self.joints, self.masses = [], [], []
        r = sphere_radius
        for name, (x, z), angle, mass, size in bodies:
            if name == "lintel":
                inertia = RotationalInertia(*geometry.box_inertia(mass, *size))
            else:  # only the inertia about y enters a planar motion: J_G of the scene
                inertia = RotationalInertia(*(scene.inertia_J_G,) * 3)
            body = plant.AddRigidBody(name, SpatialInertia.MakeFromCentralInertia(
                mass, np.zeros(3), inertia))
            own = plant.AddFrame(FixedOffsetFrame(f"{name}_plane", body.body_frame(),
                                                  RigidTransform(_PLANE)))
            joint = plant.AddJoint(PlanarJoint(f"{name}_joint", plane, own))
            joint.set_default_pose([x, z], angle)
            if name == "lintel" or contact_model == "hydroelastic":
                plant.RegisterCollisionGeometry(body, RigidTransform(), Box(*size), name,
                                                props())
            else:  # eight corner spheres, tangent to the box faces
                hx, hy, hz = (0.5 * v - r for v in size)
                for k, (sx, sy, sz) in enumerate(np.ndindex(2, 2, 2)):
                    corner = [(2 * sx - 1) * hx, (2 * sy - 1) * hy, (2 * sz - 1) * hz]
                    plant.RegisterCollisionGeometry(body, RigidTransform(corner), Sphere(r),
                                                    f"{name}_corner{k}", props())
            self.bodies.append(body)
            self.joints.append(joint)
            self.masses.append(mass)
        self.pendulum = None
        if scene.has_pendulum:
            l, m4 = scene.pendulum_length, scene.m4
            bob_i = NEGLIGIBLE_INERTIA_FRACTION * m4 * l * l
            bob = plant.AddRigidBody("pendulum", SpatialInertia.MakeFromCentralInertia(
                m4, [0.0, 0.0, -l], RotationalInertia(bob_i, bob_i, bob_i)))
            hinge = plant.AddFrame(FixedOffsetFrame("hinge", self.bodies[2].body_frame(),
                                                    RigidTransform([scene.hinge_x, 0.0, -0.5 * t_l])))
            self.pendulum = plant.AddJoint(RevoluteJoint("pendulum_psi", hinge, bob.body_frame(),
                                                         [0.0, -1.0, 0.0]))
            self.pendulum.set_default_angle(psi0)
            self.bob = bob
        plant.Finalize()
        self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self.force_port = plant.get_applied_spatial_force_input_port()
        self._load = None
        self._set_load(0.0)
        self.simulator.Initialize()
        self.dt = dt
        self._q = [(j.position_start(), j.velocity_start()) for j in self.joints]

    def _set_load(self, load: float) -> None:
        """Horizontal base-frame load ``load`` [m/s^2] as forces on every mass."""
        self._load = load
        forces = []
        for body, mass in zip(self.bodies, self.masses):
            forces.append(_force(body, np.zeros(3), mass * load))
        if self.pendulum is not None:
            forces.append(_force(self.bob, [0.0, 0.0, -self.scene.pendulum_length],
                                 self.scene.m4 * load))
        self.force_port.FixValue(self.plant_context, forces)

    def steps(self, first: int, loads) -> None:
        """Steps ``first, first + 1, ...``, one per horizontal base-frame load
        [m/s^2] in ``loads``; runs of equal loads (0 after the pulse) are
        advanced in one call."""
        sim, dt, k = self.simulator, self.dt, first
        for a in loads:
            if a != self._load:
                sim.AdvanceTo(k * dt)  # the steps before, at the previous load
                self._set_load(a)
            k += 1
        sim.AdvanceTo(k * dt)

    def planar_states(self) -> list[tuple[float, float, float, float, float, float]]:
        """``[x, z, angle, vx, vz, omega]`` of each column and the lintel."""
        q = self.plant.GetPositions(self.plant_context).tolist()
        v = self.plant.GetVelocities(self.plant_context).tolist()
        return [q[iq:iq + 3] + v[iv:iv + 3] for iq, iv in self._q]

    def pendulum_state(self) -> tuple[float, float]:
        """Relative hinge angle and rate (add the lintel's for the absolute)."""
        return (float(self.pendulum.get_angle(self.plant_context)),
                float(self.pendulum.get_angular_rate(self.plant_context)))

    def close(self) -> None:
        self.simulator = self.context = self.plant_context = self.diagram = None


def _force(body, point, fx: float) -> ExternallyAppliedSpatialForce:
    f = ExternallyAppliedSpatialForce()
    f.body_index = body.index()
    f.p_BoBq_B = np.asarray(point, dtype=float)
    f.F_Bq_W = SpatialForce(np.zeros(3), np.array([fx, 0.0, 0.0]))
    return f
