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
free block needs ``x, z, th`` and their rates set at once, so each replaying
engine has a small world for it (``Engine.free_block``, capability
``free_block``: ``engines/pymunk_/free_block.py``, ``engines/mujoco_/free_block.py``).

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

def _replaying() -> tuple[str, ...]:
    from trilith_xval.engines import engine_names, supports
    return tuple(e for e in engine_names() if supports(e, "free_block"))


# The engines whose class can start a free block in flight (capability free_block).
ENGINES = _replaying()
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
        """After every engine step: the block's height ``z`` [m], angle [rad] and
        rates [rad/s] now and before the step."""
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


def _replay_in(engine: str, impact: Impact, friction: float, flt: Filter) -> dict:
    """Replay ``impact`` in the world of ``engine``'s ``free_block``."""
    from trilith_xval.engines import get_backend
    scene = square_scene()
    cls = get_backend(engine)
    dt = cls.Settings().dt
    watch = _Landing(impact, dt)
    thetas, warnings = cls.free_block(SIDE, scene.m1, scene.inertia_J_G, scene.g, impact.state,
                                      friction, _frames_to_run(impact, flt), FRAME_RATE,
                                      watch.step)
    out = _post_ratio(impact, thetas, watch.result(), flt)
    if warnings is not None:
        out["warnings"] = warnings
    return out


def replay_pymunk(impact: Impact, friction: float = DEFAULT_FRICTION,
                  flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in Pymunk; ``{'rate_after', 'ratio', 'residual', ...}``."""
    return _replay_in("pymunk", impact, friction, flt)


def replay_mujoco(impact: Impact, friction: float = DEFAULT_FRICTION,
                  flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in MuJoCo (planar joints, 3D box on a plane)."""
    return _replay_in("mujoco", impact, friction, flt)


def replay(engine: str, impact: Impact, friction: float = DEFAULT_FRICTION,
           flt: Filter = Filter()) -> dict:
    """Replay ``impact`` in ``engine`` (one of :data:`ENGINES`)."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    return _replay_in(engine, impact, friction, flt)


def engine_versions() -> dict:
    """Each replaying engine's version string (``Engine.version()``)."""
    from trilith_xval.engines import get_backend
    return {engine: get_backend(engine).version() for engine in ENGINES}
