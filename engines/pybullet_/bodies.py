"""Building a scene's bodies in a PyBullet client, for :mod:`engines.pybullet_`.

:func:`build_scene` turns the scene's body list (:class:`~engines.geometry.Structure`:
the trilith, the block, or another kind of :mod:`analytic.kinds`) into
PyBullet multibodies.  Geometry and signs are described in
:mod:`engines.pybullet_.world` (the analytic plane is PyBullet's x-z plane,
``theta = -pitch``); the numbers come from :mod:`engines.geometry`.
"""
from __future__ import annotations

from dataclasses import dataclass

from trilith_xval.engines import geometry
from trilith_xval.engines._quiet_pybullet import pybullet as pb

__all__ = ["Bodies", "build_scene", "initial_poses", "contact_levels", "NEGLIGIBLE_MASS_FRACTION",
           "GROUND_MASS_FACTOR"]

# Own inertia of the pendulum bob relative to m4 l^2: negligible (the analytic
# bob is a point; 1e-6 relative error) but non-zero so the link's inertia is regular.
NEGLIGIBLE_MASS_FRACTION = 1e-6
# The heavy moving ground ("ground" base motion) weighs this many trilith masses,
# so contact impulses change its reset velocity by < 1e-6 within a step.
GROUND_MASS_FACTOR = 1e6


@dataclass
class Bodies:
    """PyBullet ids of one built scene, and the numbers needed to read it.

    ``boxes`` are the structure's bodies in its order (for the trilith: left
    column, right column, lintel if ``mu > 0``); ``parent`` is the body the
    pendulum hangs on (a multibody base), ``pendulum_joint`` the bob's joint
    (= link) index on it, ``hinge_local`` the hinge in the parent's frame.
    """

    client: int
    ground: int
    ground_link: int  # -1: static box base; 0: the prismatic link of a moving ground
    boxes: tuple[int, ...]
    structure: geometry.Structure
    parent: int | None  # the bob's parent body, or None without a pendulum
    pendulum_joint: int | None
    hinge_local: tuple[float, float, float]
    length: float  # pendulum length l (0 without one)

    @property
    def dynamic(self) -> tuple[int, ...]:
        return self.boxes

    @property
    def columns(self) -> tuple[int, int]:
        """The trilith's columns (the first two boxes)."""
        return self.boxes[0], self.boxes[1]

    @property
    def lintel(self) -> int | None:
        """The trilith's lintel, None for ``mu = 0``."""
        return self.boxes[2] if len(self.boxes) > 2 else None


def _quat_theta(theta: float) -> tuple[float, float, float, float]:
    """Quaternion of an analytic CCW rotation ``theta``: a rotation about -y."""
    return pb.getQuaternionFromEuler((0.0, -theta, 0.0))


def initial_poses(scene, theta0: float, psi0: float, sink: float = 0.0) -> dict:
    """World poses of the columns, lintel and pendulum bob for a trilith tilted by
    ``theta0`` (about the left corners if > 0, the right ones if < 0), at rest.

    The columns rotate rigidly about their pivot corners; the lintel translates
    with the column tops (the parallelogram of Eq. 5-6); the bob hangs at
    ``psi0`` from the hinge.  ``sink`` [m] lowers the columns by ``sink`` and the
    lintel by ``2 sink``: every contact then starts at that penetration (the
    contact slop, where Bullet's resting contacts settle, see :func:`build_scene`).
    """
    poses = geometry.rest_poses(scene, theta0, psi0)
    centres = [(cx, cz - sink) for cx, cz in poses.columns]
    lintel = (poses.lintel[0], poses.lintel[1] - 2.0 * sink)
    return {"columns": centres, "lintel": lintel, "quat": _quat_theta(theta0)}


def build_scene(client: int, structure, friction: float, moving_ground: bool,
                friction_anchor: bool = True, slop: float = 0.0,
                under_load: bool = False) -> Bodies:
    """Create every body of ``structure`` (:func:`engines.geometry.structure_of`)
    in ``client``, each box with Bullet's per-body ``friction`` (the pair's
    product is the run's coefficient); see :mod:`engines.pybullet_.world`.

    Bodies are created in the structure's order after the ground, with the
    calls of the trilith's builder before the body list, in its order, so the
    trilith's world is unchanged bit for bit (``tests/engines/test_structure.py``).

    ``slop``: Bullet's ``contactSlop`` [m].  Each box starts sunk by it times
    the number of contacts below it (:func:`contact_levels`: a column by one
    slop, the lintel on it by two), where a resting contact settles: penetrations below
    the slop are left to close freely, so bodies placed at zero gap fall through
    ``slop`` without any contact force, ~4.5 ms for 1e-4 m.  Under a pulse starting
    at t = 0 they slid frictionless meanwhile and landed with a sideways velocity
    whose friction impulse kicked them into rocking: uplift 3-4 ms early at the
    paper's points A and D (theta error ~1e-2 alpha before the first impact).

    An upright start (no box turned) and any start ``under_load`` (a pulse or a
    record moves the ground from t = 0) are sunk.  At zero gap a tilted start under
    a pulse fell through the slop for ~4.5 ms while the ground accelerated and
    landed sliding: with a 1e-6 rad tilt at Omega = 20 rad/s, A = 46.6 m/s^2 (Fig. 5)
    a pivot slid 33.5 mm, where the upright start slides 4e-8 m.  A tilted release
    (free rocking, under :class:`~analytic.excitation.Still`) has no load to slide
    under while it settles, and keeps the zero-gap start its restitution
    calibration was measured with: sinking it too gave the same statistics
    (107 impacts, lam 3/5/7 x mu 0.5/1/2 x release 0.3/0.5/0.8 alpha: 5.6 % beyond
    0.5 % either way, median 0.039 % vs 0.034 %) but moved the column-step
    outliers (see ``engines.pybullet_.Settings``) onto other releases.
    """
    b_vis = structure.width_scale  # the scale of the bob's drawing (visual only)
    depth = structure.depth
    tilted = any(box.start[2] != 0.0 for box in structure.bodies)
    sink = slop if not tilted or under_load else 0.0
    levels = contact_levels(structure)

    # Ground: wide enough for bodies lying on their sides, thick enough that a
    # corner cannot tunnel through it; a box, not a GEOM_PLANE (DESIGN.md: the
    # plane makes top and bottom impacts resolve one step apart).
    centre_x, *g_half = structure.ground
    g_shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=g_half, physicsClientId=client)
    g_pos = (centre_x, 0.0, -g_half[2])
    if moving_ground:
        total = structure.total_mass
        ground = pb.createMultiBody(
            baseMass=0.0, basePosition=(0.0, 0.0, 0.0),
            linkMasses=[GROUND_MASS_FACTOR * total], linkCollisionShapeIndices=[g_shape],
            linkVisualShapeIndices=[-1], linkPositions=[g_pos], linkOrientations=[(0, 0, 0, 1)],
            linkInertialFramePositions=[(0, 0, 0)], linkInertialFrameOrientations=[(0, 0, 0, 1)],
            linkParentIndices=[0], linkJointTypes=[pb.JOINT_PRISMATIC],
            linkJointAxis=[(1.0, 0.0, 0.0)], physicsClientId=client)
        pb.setJointMotorControl2(ground, 0, pb.VELOCITY_CONTROL, force=0.0,
                                 physicsClientId=client)
        ground_link = 0
    else:
        ground = pb.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=g_shape,
                                    basePosition=g_pos, physicsClientId=client)
        ground_link = -1

    bob = structure.bob
    shapes: dict[tuple, tuple[int, int]] = {}  # equal boxes share their shapes
    boxes, parent, joint, hinge_local = [], None, None, (0.0, 0.0, 0.0)
    for box in structure.bodies:
        half = (0.5 * box.b, 0.5 * depth, 0.5 * box.h)
        if half not in shapes:
            rgba = (0.6, 0.55, 0.5, 1.0) if box.name == "lintel" else (0.75, 0.7, 0.6, 1.0)
            shapes[half] = (
                pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=client),
                pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=rgba,
                                     physicsClientId=client))
        shape, vis = shapes[half]
        x, z, angle = box.start
        hangs = bob is not None and bob.parent == box.name
        link_kw = {}
        if hangs:
            l = bob.length
            hinge_local = (bob.anchor[0], 0.0, bob.anchor[1])
            # Visual only (no collision shape, inertia set below): a rod and the
            # bob, drawn in the link frame (hinge at its origin).
            bob_vis = pb.createVisualShapeArray(
                shapeTypes=[pb.GEOM_SPHERE, pb.GEOM_CYLINDER], radii=[0.15 * b_vis, 0.02 * b_vis],
                lengths=[0.0, l], visualFramePositions=[(0.0, 0.0, -l), (0.0, 0.0, -0.5 * l)],
                rgbaColors=[(0.8, 0.1, 0.1, 1.0), (0.3, 0.3, 0.3, 1.0)], physicsClientId=client)
            # Link frame at the hinge; its centre of mass (the bob) l below it.
            # Axis -y: a positive joint angle is a CCW (analytic) swing.
            link_kw = dict(
                linkMasses=[bob.mass], linkCollisionShapeIndices=[-1],
                linkVisualShapeIndices=[bob_vis], linkPositions=[hinge_local],
                linkOrientations=[(0, 0, 0, 1)], linkInertialFramePositions=[(0.0, 0.0, -l)],
                linkInertialFrameOrientations=[(0, 0, 0, 1)], linkParentIndices=[0],
                linkJointTypes=[pb.JOINT_REVOLUTE], linkJointAxis=[(0.0, -1.0, 0.0)])
        body = pb.createMultiBody(baseMass=box.mass, baseCollisionShapeIndex=shape,
                                  baseVisualShapeIndex=vis,
                                  basePosition=(x, 0.0, z - levels[box.name] * sink),
                                  baseOrientation=_quat_theta(angle), physicsClientId=client,
                                  **link_kw)
        # In the plane the structure's inertia (a column's J_G, which may differ
        # from the uniform box's); out of it, the uniform box's (the structure
        # gives J_G on all three axes for planar engines, where they never turn).
        ix, _, iz = geometry.box_inertia(box.mass, box.b, depth, box.h)
        pb.changeDynamics(body, -1, mass=box.mass, localInertiaDiagonal=(ix, box.inertia[1], iz),
                          physicsClientId=client)
        if hangs:
            joint, parent = 0, body
            # The joint is free: no default velocity motor (it would lock it).
            pb.setJointMotorControl2(body, joint, pb.VELOCITY_CONTROL, force=0.0,
                                     physicsClientId=client)
            bob_i = NEGLIGIBLE_MASS_FRACTION * bob.mass * l * l
            pb.changeDynamics(body, joint, mass=bob.mass,
                              localInertiaDiagonal=(bob_i, bob_i, bob_i), physicsClientId=client)
            # The analytic pendulum passes through everything.
            pb.setCollisionFilterGroupMask(body, joint, 0, 0, physicsClientId=client)
            # Joint angle = psi relative to the parent, turned by its start angle.
            pb.resetJointState(body, joint, bob.psi0 - angle, 0.0, physicsClientId=client)
        boxes.append(body)

    bodies = Bodies(client, ground, ground_link, tuple(boxes), structure, parent, joint,
                    hinge_local, bob.length if bob is not None else 0.0)
    for body in bodies.boxes:
        # DESIGN.md: no damping (default 0.04 costs 0.8 % restitution),
        # plastic contacts, friction anchors against creeping.
        pb.changeDynamics(body, -1, lateralFriction=friction, restitution=0.0,
                          linearDamping=0.0, angularDamping=0.0,
                          frictionAnchor=int(friction_anchor),
                          rollingFriction=0.0, spinningFriction=0.0,
                          physicsClientId=client)
    pb.changeDynamics(ground, ground_link, lateralFriction=friction, restitution=0.0,
                      frictionAnchor=int(friction_anchor), linearDamping=0.0, angularDamping=0.0,
                      physicsClientId=client)
    return bodies


def contact_levels(structure) -> dict[str, float]:
    """How many contacts stand between each box and the ground (1.0 on the ground,
    one more than its highest support above it), as a float: a box starts sunk by
    that many contact slops, each contact below it settled at one slop."""
    below: dict[str, list[str]] = {}
    for upper, lower in structure.supports:
        below.setdefault(upper, []).append(lower)
    levels: dict[str, float] = {"ground": 0.0}

    def level(name: str) -> float:
        if name not in levels:
            levels[name] = 1.0 + max(level(lower) for lower in below[name])
        return levels[name]

    return {box.name: level(box.name) for box in structure.bodies}
