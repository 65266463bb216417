"""LEGACY COPY (tests only) of the pre-body-list builder.

Building the trilith's bodies in a PyBullet client, for :mod:`engines.pybullet_`.

Geometry and signs are described in :mod:`engines.pybullet_.world` (the analytic
plane is PyBullet's x-z plane, ``theta = -pitch``); the numbers come from
:mod:`engines.geometry`.
"""
from __future__ import annotations

from dataclasses import dataclass

from trilith_xval.engines import geometry
from trilith_xval.engines._quiet_pybullet import pybullet as pb

__all__ = ["Bodies", "build_scene", "initial_poses", "NEGLIGIBLE_MASS_FRACTION",
           "GROUND_MASS_FACTOR"]

# Own inertia of the pendulum bob relative to m4 l^2: negligible (the analytic
# bob is a point; 1e-6 relative error) but non-zero so the link's inertia is regular.
NEGLIGIBLE_MASS_FRACTION = 1e-6
# The heavy moving ground ("ground" base motion) weighs this many trilith masses,
# so contact impulses change its reset velocity by < 1e-6 within a step.
GROUND_MASS_FACTOR = 1e6



@dataclass
class Bodies:
    """PyBullet ids of one built scene, and the numbers needed to read it."""

    client: int
    ground: int
    ground_link: int  # -1: static box base; 0: the prismatic link of a moving ground
    columns: tuple[int, int]
    lintel: int | None
    lintel_link: int  # -1: the lintel is a multibody base
    pendulum_joint: int | None  # joint (= link) index on the lintel, or None
    hinge_local: tuple[float, float, float]  # hinge in the lintel's frame
    length: float  # pendulum length l

    @property
    def dynamic(self) -> tuple[int, ...]:
        return self.columns + ((self.lintel,) if self.lintel is not None else ())


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


def build_scene(client: int, scene, theta0: float, psi0: float, friction: float,
                moving_ground: bool, friction_anchor: bool = True, slop: float = 0.0,
                under_load: bool = False) -> Bodies:
    """Create every body of ``scene`` in ``client`` (see the module docstring).

    ``slop``: Bullet's ``contactSlop`` [m].  The bodies start sunk by it
    (:func:`initial_poses`), where a resting contact settles: penetrations below
    the slop are left to close freely, so bodies placed at zero gap fall through
    ``slop`` without any contact force, ~4.5 ms for 1e-4 m.  Under a pulse starting
    at t = 0 they slid frictionless meanwhile and landed with a sideways velocity
    whose friction impulse kicked them into rocking: uplift 3-4 ms early at the
    paper's points A and D (theta error ~1e-2 alpha before the first impact).

    An upright start (``theta0 == 0``) and any start ``under_load`` (a pulse or a
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
    b, h, depth = scene.b, scene.h, scene.depth
    span = scene.lintel_length
    poses = initial_poses(scene, theta0, psi0,
                          sink=slop if theta0 == 0.0 or under_load else 0.0)

    # Ground: wide enough for columns lying on their sides, thick enough that a
    # corner cannot tunnel through it; a box, not a GEOM_PLANE (DESIGN.md: the
    # plane makes top and bottom impacts resolve one step apart).
    g_half = geometry.ground_box(scene)
    g_shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=g_half, physicsClientId=client)
    g_pos = (0.5 * span, 0.0, -g_half[2])
    if moving_ground:
        total = scene.m1 * (2.0 + scene.mu + scene.gamma)
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

    col_shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=(0.5 * b, 0.5 * depth, 0.5 * h),
                                        physicsClientId=client)
    col_vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=(0.5 * b, 0.5 * depth, 0.5 * h),
                                   rgbaColor=(0.75, 0.7, 0.6, 1.0), physicsClientId=client)
    columns = []
    for (x, z) in poses["columns"]:
        body = pb.createMultiBody(baseMass=scene.m1, baseCollisionShapeIndex=col_shape,
                                  baseVisualShapeIndex=col_vis, basePosition=(x, 0.0, z),
                                  baseOrientation=poses["quat"], physicsClientId=client)
        ix, _, iz = geometry.box_inertia(scene.m1, b, depth, h)
        # J_G comes from the scene (it may differ from the uniform box's value).
        pb.changeDynamics(body, -1, mass=scene.m1, localInertiaDiagonal=(ix, scene.inertia_J_G, iz),
                          physicsClientId=client)
        columns.append(body)

    lintel = None
    lintel_link = -1
    joint = None
    t_lin = scene.lintel_thickness
    hinge_local = (scene.hinge_x, 0.0, -0.5 * t_lin)
    if scene.mu > 0.0:
        half = (0.5 * span, 0.5 * depth, 0.5 * t_lin)
        l_shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=client)
        l_vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half,
                                     rgbaColor=(0.6, 0.55, 0.5, 1.0), physicsClientId=client)
        lx, lz = poses["lintel"]
        links: list[dict] = []
        if scene.has_pendulum:
            l = scene.pendulum_length
            # Visual only (no collision shape, inertia set below): a rod and the
            # bob, drawn in the link frame (hinge at its origin).
            bob_vis = pb.createVisualShapeArray(
                shapeTypes=[pb.GEOM_SPHERE, pb.GEOM_CYLINDER], radii=[0.15 * b, 0.02 * b],
                lengths=[0.0, l], visualFramePositions=[(0.0, 0.0, -l), (0.0, 0.0, -0.5 * l)],
                rgbaColors=[(0.8, 0.1, 0.1, 1.0), (0.3, 0.3, 0.3, 1.0)], physicsClientId=client)
            # Link frame at the hinge; its centre of mass (the bob) l below it.
            # Axis -y: a positive joint angle is a CCW (analytic) swing.
            links.append(dict(mass=scene.m4, col=-1, vis=bob_vis, pos=hinge_local,
                              com=(0.0, 0.0, -l), parent=lintel_link + 1,
                              type=pb.JOINT_REVOLUTE, axis=(0.0, -1.0, 0.0)))
            joint = len(links) - 1
        link_kw = {}
        if links:
            link_kw = dict(
                linkMasses=[k["mass"] for k in links],
                linkCollisionShapeIndices=[k["col"] for k in links],
                linkVisualShapeIndices=[k["vis"] for k in links],
                linkPositions=[k["pos"] for k in links],
                linkOrientations=[(0, 0, 0, 1)] * len(links),
                linkInertialFramePositions=[k["com"] for k in links],
                linkInertialFrameOrientations=[(0, 0, 0, 1)] * len(links),
                linkParentIndices=[k["parent"] for k in links],
                linkJointTypes=[k["type"] for k in links],
                linkJointAxis=[k["axis"] for k in links])
        lintel = pb.createMultiBody(baseMass=scene.m3, baseCollisionShapeIndex=l_shape,
                                    baseVisualShapeIndex=l_vis, basePosition=(lx, 0.0, lz),
                                    physicsClientId=client, **link_kw)
        pb.changeDynamics(lintel, lintel_link, mass=scene.m3,
                          localInertiaDiagonal=geometry.box_inertia(scene.m3, span, depth, t_lin),
                          physicsClientId=client)
        for k in range(len(links)):
            # Joints are free: no default velocity motor (it would lock them).
            pb.setJointMotorControl2(lintel, k, pb.VELOCITY_CONTROL, force=0.0,
                                     physicsClientId=client)
        if scene.has_pendulum:
            bob_i = NEGLIGIBLE_MASS_FRACTION * scene.m4 * l * l
            pb.changeDynamics(lintel, joint, mass=scene.m4,
                              localInertiaDiagonal=(bob_i, bob_i, bob_i), physicsClientId=client)
            # The analytic pendulum passes through everything.
            pb.setCollisionFilterGroupMask(lintel, joint, 0, 0, physicsClientId=client)
            # Joint angle = psi relative to the lintel, which starts unrotated.
            pb.resetJointState(lintel, joint, psi0, 0.0, physicsClientId=client)

    bodies = Bodies(client, ground, ground_link, (columns[0], columns[1]), lintel,
                    lintel_link if lintel is not None else -1, joint, hinge_local,
                    scene.pendulum_length)
    for body in bodies.dynamic:
        parts = [-1] if body != lintel else [bodies.lintel_link]
        for link in parts:
            # DESIGN.md: no damping (default 0.04 costs 0.8 % restitution),
            # plastic contacts, friction anchors against creeping.
            pb.changeDynamics(body, link, lateralFriction=friction, restitution=0.0,
                              linearDamping=0.0, angularDamping=0.0,
                              frictionAnchor=int(friction_anchor),
                              rollingFriction=0.0, spinningFriction=0.0,
                              physicsClientId=client)
    pb.changeDynamics(ground, ground_link, lateralFriction=friction, restitution=0.0,
                      frictionAnchor=int(friction_anchor), linearDamping=0.0, angularDamping=0.0,
                      physicsClientId=client)
    return bodies
