"""A throwaway engine written through the template: Pymunk's world under a new name.

It measures what a new engine costs: this folder and one registry line
(``tests/engines/test_toy_engine.py`` adds it the way ``engines.ENGINE_CLASSES`` would
list it).  The world is :func:`engines.pymunk_.world.build_space`; everything
else (checks, loop, verdicts, diagnostics, the base-motion load) is the base
class's.
"""
from __future__ import annotations

from dataclasses import dataclass

import pymunk

from trilith_xval.engines.base import Engine, EngineSettings
from trilith_xval.engines.diagnostics import PlaneState, Pose
from trilith_xval.engines.pymunk_.world import build_space, state_reader

__all__ = ["ToyEngine", "Settings"]


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Pymunk's calibrated values (see :class:`engines.pymunk_.Settings`)."""

    iterations: int = 30
    slop_fraction: float = 1e-4
    collision_bias: float | None = None
    pendulum_radius_fraction: float = 1e-2


class ToyEngine(Engine):
    """Pymunk stepped through the hooks of :class:`engines.base.Engine`."""

    name = "toy"
    label = "Toy (Pymunk)"
    color = "tab:gray"
    marker = "D"
    capabilities = frozenset({"time_step", "initial_tilt", "trajectory"})
    default_friction = 10.0
    Settings = Settings

    @classmethod
    def version(cls) -> str:
        return f"toy on pymunk {pymunk.version}"

    def build(self) -> None:
        self.world = build_space(self.scene, self.settings, self.friction)
        self.state = state_reader(self.world)

    def advance(self, steps: int) -> None:
        space, dt, minus_g = self.world.space, self.settings.dt, -self.scene.g
        for k in range(self.step_index, self.step_index + steps):
            space.gravity = (self.base_load(k), minus_g)
            space.step(dt)
        self.step_index += steps

    def read(self) -> PlaneState:
        st = self.state()  # x, y, angle, vx, vy, omega per body: columns, lintel, bob
        lintel = Pose(*st[12:18]) if self.world.lintel is not None else None
        psi = psi_dot = 0.0
        if self.world.bob is not None:
            i = 6 * (2 + (lintel is not None))
            psi, psi_dot = self.settings.psi0 + st[i + 2], st[i + 5]
        return PlaneState((Pose(*st[0:6]), Pose(*st[6:12])), lintel, psi, psi_dot)
