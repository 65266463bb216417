"""A scene in Drake: a discrete MultibodyPlant of planar bodies with compliant contact.

The plant is built from the scene's body list (:class:`~engines.geometry.Structure`:
the trilith, the block, or another kind of :mod:`analytic.kinds`).  Bodies of the
trilith (all sizes read from :class:`analytic.parameters.Scene` through its
Structure; the other kinds' boxes the same way):

* the ground, a box welded to the world whose top face is ``z = 0``;
* each column and the lintel, a body on a :class:`PlanarJoint` whose plane is
  the vertical x-z plane (coordinates ``x``, ``z`` of the centre and the angle
  about ``-y``, the analytic CCW one);
* the pendulum, a revolute joint (axis ``-y``) on the lintel at the hinge, the
  point mass ``m4`` at ``l`` below it, with no collision geometry.

Contact (``contact_model``):

* ``'point'``: at every support the narrower body (the upper one if equal)
  touches the wider one through eight small spheres at its corners (inset so
  that they are tangent to the box faces), the wider one through its box:
  each column touches the ground and the lintel by its corner spheres, the
  ground and the lintel are boxes; a drum resting on a drum has both, and
  the pairs that would double a contact (box on box, sphere on sphere, the
  wider body's spheres on the narrower's box, a drum's box on the ground)
  are filtered out.  Box-on-box point contact is poorer (its contact point
  jumps between corners) and slower.
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
                              AddRigidHydroelasticProperties, Box, CollisionFilterDeclaration,
                              GeometrySet, ProximityProperties, Sphere)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction,
                                     ExternallyAppliedSpatialForce, MultibodyPlantConfig)
from pydrake.multibody.tree import (FixedOffsetFrame, PlanarJoint, RevoluteJoint,
                                    RotationalInertia, SpatialInertia)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder


__all__ = ["DrakeWorld", "CONTACT_MODELS", "SOLVERS", "NEGLIGIBLE_INERTIA_FRACTION"]

CONTACT_MODELS = ("point", "hydroelastic")
SOLVERS = ("sap", "lagged", "similar")  # TAMSI is deprecated in 1.51
NEGLIGIBLE_INERTIA_FRACTION = 1e-6
# The plane frame: its x-y plane is the world's x-z plane, its z axis the world's -y.
_PLANE = RollPitchYaw(0.5 * math.pi, 0.0, 0.0).ToRotationMatrix()


class DrakeWorld:
    """A fresh Drake diagram holding one scene (nothing shared between runs).

    Parameters
    ----------
    structure : engines.geometry.Structure
        The scene's body list at the start of the run
        (:func:`~engines.geometry.structure_of` at ``theta0``, ``psi0``).
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

    The planar joints hang from one frame at the world origin, so a body's
    coordinates are its centre ``(x, z)`` and CCW angle in the analytic plane.
    Bodies are added in the structure's order, with the calls of the trilith's
    builder before the body list, in its order (the trilith's plant is unchanged
    bit for bit, ``tests/engines/test_structure_3d.py``).
    """

    def __init__(self, structure, dt: float, friction: float, contact_model: str, solver: str,
                 stiffness: float, relaxation_time: float, dissipation: float,
                 sphere_radius: float, hydroelastic_modulus: float):
        self.structure = structure
        builder = DiagramBuilder()
        config = MultibodyPlantConfig(time_step=dt, contact_model=contact_model,
                                      discrete_contact_approximation=solver)
        self.plant, self.scene_graph = plant, scene_graph = AddMultibodyPlant(config, builder)
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -structure.g])

        def props(rigid_hydro: bool = False) -> ProximityProperties:
            p = ProximityProperties()
            AddContactMaterial(dissipation, 2.0 * stiffness,
                               CoulombFriction(friction, friction), p)
            p.AddProperty("material", "relaxation_time", 0.5 * relaxation_time)
            if contact_model == "hydroelastic":
                if rigid_hydro:
                    AddRigidHydroelasticProperties(p)
                else:
                    AddCompliantHydroelasticProperties(0.1 * structure.width_scale,
                                                       hydroelastic_modulus, p)
            return p

        depth = structure.depth
        centre_x, *g_half = structure.ground
        world = plant.world_body()
        ground_id = plant.RegisterCollisionGeometry(
            world, RigidTransform([centre_x, 0.0, -g_half[2]]), Box(*(2.0 * v for v in g_half)),
            "ground", props(rigid_hydro=True))
        spheres, boxes = _contact_shapes(structure, contact_model)
        plane = plant.AddFrame(FixedOffsetFrame("plane", world, RigidTransform(_PLANE)))
        self.bodies, self.joints, self.masses = [], [], []
        ids: dict[str, dict[str, list]] = {}
        r = sphere_radius
        for box in structure.bodies:
            name, size = box.name, (box.b, depth, box.h)
            # Only the inertia about y enters a planar motion (a column's: J_G of
            # the scene, which the structure gives on all three axes).
            inertia = RotationalInertia(*box.inertia)
            body = plant.AddRigidBody(name, SpatialInertia.MakeFromCentralInertia(
                box.mass, np.zeros(3), inertia))
            own = plant.AddFrame(FixedOffsetFrame(f"{name}_plane", body.body_frame(),
                                                  RigidTransform(_PLANE)))
            joint = plant.AddJoint(PlanarJoint(f"{name}_joint", plane, own))
            x, z, angle = box.start
            joint.set_default_pose([x, z], angle)
            ids[name] = {"box": [], "spheres": []}
            if name in boxes:
                ids[name]["box"].append(plant.RegisterCollisionGeometry(
                    body, RigidTransform(), Box(*size), name, props()))
            if name in spheres:  # eight corner spheres, tangent to the box faces
                hx, hy, hz = (0.5 * v - r for v in size)
                for k, (sx, sy, sz) in enumerate(np.ndindex(2, 2, 2)):
                    corner = [(2 * sx - 1) * hx, (2 * sy - 1) * hy, (2 * sz - 1) * hz]
                    ids[name]["spheres"].append(plant.RegisterCollisionGeometry(
                        body, RigidTransform(corner), Sphere(r), f"{name}_corner{k}", props()))
            self.bodies.append(body)
            self.joints.append(joint)
            self.masses.append(box.mass)
        self.pendulum = None
        spec = structure.bob
        if spec is not None:
            l, m4 = spec.length, spec.mass
            bob_i = NEGLIGIBLE_INERTIA_FRACTION * m4 * l * l
            bob = plant.AddRigidBody("pendulum", SpatialInertia.MakeFromCentralInertia(
                m4, [0.0, 0.0, -l], RotationalInertia(bob_i, bob_i, bob_i)))
            self.parent_index = k = structure.index(spec.parent)
            hinge = plant.AddFrame(FixedOffsetFrame("hinge", self.bodies[k].body_frame(),
                                                    RigidTransform([spec.anchor[0], 0.0,
                                                                    spec.anchor[1]])))
            self.pendulum = plant.AddJoint(RevoluteJoint("pendulum_psi", hinge, bob.body_frame(),
                                                         [0.0, -1.0, 0.0]))
            # Relative to the parent, turned by its start angle.
            self.pendulum.set_default_angle(spec.psi0 - structure.bodies[k].start[2])
            self.bob = bob
        plant.Finalize()
        _filter_doubled_contacts(scene_graph, structure, ids, ground_id)
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
            spec = self.structure.bob
            forces.append(_force(self.bob, [0.0, 0.0, -spec.length], spec.mass * load))
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
        """``[x, z, angle, vx, vz, omega]`` of each box in the structure's order."""
        q = self.plant.GetPositions(self.plant_context).tolist()
        v = self.plant.GetVelocities(self.plant_context).tolist()
        return [q[iq:iq + 3] + v[iv:iv + 3] for iq, iv in self._q]

    def pendulum_state(self) -> tuple[float, float]:
        """Relative hinge angle and rate (add the parent's for the absolute)."""
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


def _contact_shapes(structure, contact_model: str) -> tuple[set[str], set[str]]:
    """The boxes that touch by corner spheres and those that touch by their box.

    Hydroelastic: every box by its box.  Point: at each support the narrower
    body (the upper one if equal) by its spheres, the wider by its box; a body
    in no such pair (none in the shipped kinds) by its box."""
    names = [box.name for box in structure.bodies]
    if contact_model == "hydroelastic":
        return set(), set(names)
    spheres, boxes = set(), set()
    for upper, lower in structure.supports:
        if lower == "ground":
            spheres.add(upper)
            continue
        narrow, wide = ((upper, lower) if structure.body(upper).b <= structure.body(lower).b
                        else (lower, upper))
        spheres.add(narrow)
        boxes.add(wide)
    boxes |= set(names) - spheres - boxes
    return spheres, boxes


def _filter_doubled_contacts(scene_graph, structure, ids, ground_id) -> None:
    """Exclude the geometry pairs that would double a support's point contact
    (see the module docstring).  In the trilith no body has both a box and
    spheres, and hydroelastic contact has no spheres, so nothing is excluded
    there and the plant is the one built before the body list."""
    pairs = []
    for upper, lower in structure.supports:
        if lower == "ground":
            if ids[upper]["spheres"]:  # its box, if any, is for the body above it
                pairs.append((ids[upper]["box"], [ground_id]))
            continue
        narrow, wide = ((upper, lower) if structure.body(upper).b <= structure.body(lower).b
                        else (lower, upper))
        if not ids[narrow]["spheres"]:
            continue  # hydroelastic: box on box is the contact
        pairs += [(ids[wide]["spheres"], ids[narrow]["box"]),
                  (ids[wide]["box"], ids[narrow]["box"]),
                  (ids[wide]["spheres"], ids[narrow]["spheres"])]
    pairs = [(a, b) for a, b in pairs if a and b]
    if not pairs:
        return
    declaration = CollisionFilterDeclaration()
    for a, b in pairs:
        declaration.ExcludeBetween(GeometrySet(a), GeometrySet(b))
    scene_graph.collision_filter_manager().Apply(declaration)
