"""A free planar block in MuJoCo, started from a given state: the world of a
measured impact's replay (:mod:`compare.peers.impact_replay`).

A 3D box on planar joints (x, z slides and a hinge about -y) over a plane, with
the calibrated contact of :class:`~engines.mujoco_.Settings` (step, integrator,
cone, impratio, iterations, solver, solref, solimp); the trilith's world
(:mod:`.world`) starts at rest, this one in flight.
"""
from __future__ import annotations

__all__ = ["free_block", "free_block_mjcf"]


def free_block_mjcf(side: float, mass: float, inertia: float, g: float, friction: float,
                    s) -> str:
    """The model: the block of ``side`` [m], ``mass`` [kg], ``inertia`` [kg m^2]
    on planar joints over a plane, gravity ``g`` [m/s^2], ``s`` the Settings."""
    half = 0.5 * side
    timeconst = s.timeconst if s.timeconst is not None else s.timeconst_steps * s.dt
    j = inertia
    return (
        '<mujoco model="square"><compiler angle="radian" inertiafromgeom="false"/>'
        f'<option timestep="{s.dt!r}" gravity="0 0 {-g!r}" integrator="{s.integrator}" '
        f'cone="{s.cone}" impratio="{s.impratio!r}" iterations="{s.iterations}" '
        f'solver="{s.solver}"/>'
        f'<default><geom condim="3" margin="0" gap="0" friction="{friction!r} 0 0" '
        f'solref="{timeconst!r} {s.dampratio!r}" solimp="{" ".join(map(repr, s.solimp))}"/>'
        '</default><worldbody><geom name="ground" type="plane" size="10 10 1"/>'
        '<body name="block" pos="0 0 0">'
        '<joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>'
        '<joint name="th" type="hinge" axis="0 -1 0"/>'
        f'<inertial pos="0 0 0" mass="{mass!r}" diaginertia="{j!r} {j!r} {j!r}"/>'
        f'<geom type="box" size="{half!r} {half!r} {half!r}"/></body></worldbody></mujoco>')


def free_block(side: float, mass: float, inertia: float, g: float, state, friction: float,
               n_frames: int, frame_rate: float, on_step, settings) -> tuple[list, int]:
    """As :func:`engines.pymunk_.free_block.free_block`; returns ``(thetas,
    warnings)``: ``theta`` [rad] at each frame and MuJoCo's warning count."""
    import mujoco

    s = settings
    model = mujoco.MjModel.from_xml_string(free_block_mjcf(side, mass, inertia, g, friction, s))
    data = mujoco.MjData(model)
    x, z, th, vx, vz, w = state
    data.qpos[:] = (x, z, th)
    data.qvel[:] = (vx, vz, w)
    mujoco.mj_forward(model, data)
    steps = int(round(1.0 / (frame_rate * s.dt)))
    thetas = [th]
    for _ in range(n_frames - 1):
        for _ in range(steps):
            w0 = float(data.qvel[2])
            mujoco.mj_step(model, data)
            on_step(float(data.qpos[1]), float(data.qpos[2]), float(data.qvel[2]), w0)
        thetas.append(float(data.qpos[2]))
    warnings = int(sum(data.warning[i].number for i in range(len(data.warning))))
    return thetas, warnings
