"""Engines replaying a measured impact (:mod:`.impact_data`): a free planar square
block started from the measured state one frame before the impact, its
``theta_dot`` after the impact measured as the data's was.

Each engine gets one square block (side :data:`~.impact_data.SIDE`, mass
:data:`~.impact_data.MASS`, uniform inertia ``m s^2 / 6``) on a flat ground at
``z = 0``, in the plane ``x`` right, ``z`` up, ``th`` counter-clockwise, and the
project's contact settings for that engine (the calibrated defaults of
:class:`engines.pymunk_.Settings` and :class:`engines.mujoco_.Settings`: step,
solver iterations, Pymunk's plastic contact and slop, MuJoCo's overdamped soft
contact).  The engines' own scene builders are for the trilith on its base; the
free block needs ``x, z, th`` and their rates set at once, so it has a small
builder here.

The start (:attr:`.impact_data.Impact.state`) is frame ``j - 1``: the fitted
angle and rate, the pivot corner on the ground with the measured slip.  The run
is sampled at the data's frame times; the rate after the impact comes from the
same fit over the same ``window`` frames after ``j`` (:func:`.impact_data.impact_rate`),
and is divided by the measured rate before, which the engine was given.

Friction: the project's default coefficient (10, no sliding: Housner's
assumption) unless given; the measured pivots do slide (``Impact.slip``), so a
run with a low coefficient is the other end of the same question.
"""
from __future__ import annotations

import math

import numpy as np

from .impact_data import CORNERS, FRAME_RATE, SIDE, Filter, Impact, impact_rate, square_scene

__all__ = ["ENGINES", "DEFAULT_FRICTION", "replay", "replay_pymunk", "replay_mujoco",
           "engine_versions"]

ENGINES = ("pymunk", "mujoco")
DEFAULT_FRICTION = 10.0  # the project's engines' default (engines.base): no sliding


def _frames_to_run(impact: Impact, flt: Filter) -> int:
    """Frames from ``j - 1`` to the last one of the post-impact window."""
    return flt.window + 2


def _post_ratio(impact: Impact, thetas: list[float], direct: tuple, flt: Filter) -> dict:
    """The engine's rate after the impact by the data's estimator and its ratio
    to the measured rate before; ``ratio_direct``: the engine's own
    ``omega(t_land + 1 ms) / omega(t_land-)`` at its step resolution (None when
    the landing corner touched at the start), the estimator's check."""
    th = np.array(thetas[2:])  # samples at frames j+1 .. j+window
    t = np.arange(1, flt.window + 1) / FRAME_RATE
    after, resid = impact_rate(t, th, 0.0)
    return {"rate_after": after, "ratio": after / impact.rate_before, "residual": resid,
            "ratio_direct": direct[0], "t_land": direct[1]}


class _Landing:
    """Watches the landing corner, step by step, for :func:`_post_ratio`'s direct ratio."""

    SETTLE = 1e-3  # s: after the landing, MuJoCo's overdamped contact (0.3 ms) has settled

    def __init__(self, impact: Impact, dt: float):
        self.ox, self.oz = CORNERS[impact.landing]
        self.dt, self.k, self.k_land = dt, 0, None
        self.before = self.after = None

    def step(self, z: float, th: float, omega: float, omega_prev: float) -> None:
        self.k += 1
        if self.k_land is None:
            if z + self.ox * math.sin(th) + self.oz * math.cos(th) <= 0.0:
                self.k_land, self.before = self.k, (omega_prev if self.k > 1 else None)
        elif self.after is None and (self.k - self.k_land) * self.dt >= self.SETTLE:
            self.after = omega

    def result(self) -> tuple:
        if self.before is None or self.after is None:
            return None, None
        return self.after / self.before, self.k_land * self.dt


def replay_pymunk(impact: Impact, friction: float = DEFAULT_FRICTION,
                  flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in Pymunk; ``{'rate_after', 'ratio', 'residual', ...}``."""
    import pymunk

    from trilith_xval.engines.pymunk_ import Settings
    s = Settings()
    scene = square_scene()
    space = pymunk.Space()
    space.iterations = s.iterations
    space.collision_slop = s.slop_fraction * SIDE
    if s.collision_bias is not None:
        space.collision_bias = s.collision_bias
    space.gravity = (0.0, -scene.g)
    shape_friction = math.sqrt(friction)  # Pymunk multiplies the pair's values
    ground = pymunk.Body(body_type=pymunk.Body.STATIC)
    ground.position = (0.0, -0.5 * SIDE)
    floor = pymunk.Poly.create_box(ground, (1000.0 * SIDE, SIDE), radius=0.0)
    block = pymunk.Body(scene.m1, scene.inertia_J_G)
    box = pymunk.Poly.create_box(block, (SIDE, SIDE), radius=0.0)
    for shape in (floor, box):
        shape.friction, shape.elasticity = shape_friction, 0.0
    x, z, th, vx, vz, w = impact.state
    block.position, block.angle = (x, z), th
    block.velocity, block.angular_velocity = (vx, vz), w
    space.add(ground, floor, block, box)
    steps = int(round(1.0 / (FRAME_RATE * s.dt)))
    ths, watch = [th], _Landing(impact, s.dt)
    for _ in range(_frames_to_run(impact, flt) - 1):
        for _ in range(steps):
            w0 = block.angular_velocity
            space.step(s.dt)
            watch.step(block.position[1], block.angle, block.angular_velocity, w0)
        ths.append(block.angle)
    return _post_ratio(impact, ths, watch.result(), flt)


def _mjcf(friction: float, s) -> str:
    scene = square_scene()
    half = 0.5 * SIDE
    timeconst = s.timeconst if s.timeconst is not None else s.timeconst_steps * s.dt
    j = scene.inertia_J_G
    return (
        '<mujoco model="square"><compiler angle="radian" inertiafromgeom="false"/>'
        f'<option timestep="{s.dt!r}" gravity="0 0 {-scene.g!r}" integrator="{s.integrator}" '
        f'cone="{s.cone}" impratio="{s.impratio!r}" iterations="{s.iterations}" '
        f'solver="{s.solver}"/>'
        f'<default><geom condim="3" margin="0" gap="0" friction="{friction!r} 0 0" '
        f'solref="{timeconst!r} {s.dampratio!r}" solimp="{" ".join(map(repr, s.solimp))}"/>'
        '</default><worldbody><geom name="ground" type="plane" size="10 10 1"/>'
        '<body name="block" pos="0 0 0">'
        '<joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>'
        '<joint name="th" type="hinge" axis="0 -1 0"/>'
        f'<inertial pos="0 0 0" mass="{scene.m1!r}" diaginertia="{j!r} {j!r} {j!r}"/>'
        f'<geom type="box" size="{half!r} {half!r} {half!r}"/></body></worldbody></mujoco>')


def replay_mujoco(impact: Impact, friction: float = DEFAULT_FRICTION,
                  flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in MuJoCo (planar joints, 3D box on a plane)."""
    import mujoco

    from trilith_xval.engines.mujoco_ import Settings
    s = Settings()
    model = mujoco.MjModel.from_xml_string(_mjcf(friction, s))
    data = mujoco.MjData(model)
    x, z, th, vx, vz, w = impact.state
    data.qpos[:] = (x, z, th)
    data.qvel[:] = (vx, vz, w)
    mujoco.mj_forward(model, data)
    steps = int(round(1.0 / (FRAME_RATE * s.dt)))
    ths, watch = [th], _Landing(impact, s.dt)
    for _ in range(_frames_to_run(impact, flt) - 1):
        for _ in range(steps):
            w0 = float(data.qvel[2])
            mujoco.mj_step(model, data)
            watch.step(float(data.qpos[1]), float(data.qpos[2]), float(data.qvel[2]), w0)
        ths.append(float(data.qpos[2]))
    out = _post_ratio(impact, ths, watch.result(), flt)
    out["warnings"] = int(sum(data.warning[i].number for i in range(len(data.warning))))
    return out


def replay(engine: str, impact: Impact, friction: float = DEFAULT_FRICTION,
           flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in ``engine`` (one of :data:`ENGINES`)."""
    if engine == "pymunk":
        return replay_pymunk(impact, friction, flt)
    if engine == "mujoco":
        return replay_mujoco(impact, friction, flt)
    raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")


def engine_versions() -> dict:
    """``{'pymunk': ..., 'mujoco': ...}`` version strings."""
    import mujoco
    import pymunk
    return {"pymunk": f"pymunk {pymunk.version}", "mujoco": f"mujoco {mujoco.__version__}"}
