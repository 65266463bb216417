"""Backends behind one contract, selected by name (like scipy's ``solve_ivp`` methods).

Every backend module exposes

* ``NAME``: its registry name,
* ``Settings``: a frozen dataclass of its numerical settings, calibrated defaults,
  with at least ``criterion`` (:class:`analytic.OverturnCriterion`) and ``t_max``,
* ``simulate(scene, excitation, settings=None) -> Trajectory``,
* ``version() -> str``: the engine's version, carried into every report.

Adding MuJoCo is one new module ``engines/mujoco_engine.py`` and one line below.
Modules are imported lazily, so the analytic model never imports an engine.
"""
from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["BACKENDS", "ENGINES", "get_backend", "simulate", "backend_names"]

BACKENDS: dict[str, str] = {
    "analytic": "analytic.simulate",
    "analytic-fast": "analytic.fast",
    "pybullet": "engines.pybullet_engine",
    "pymunk": "engines.pymunk_engine",
    "mujoco": "engines.mujoco_engine",
}

# The physics engines proper (what the comparison layer validates).
ENGINES: tuple[str, ...] = ("pybullet", "pymunk", "mujoco")


def backend_names() -> tuple[str, ...]:
    return tuple(BACKENDS)


def get_backend(name: str) -> ModuleType:
    """The backend module registered under ``name``; ``ValueError`` if unknown."""
    if name not in BACKENDS:
        raise ValueError(f"unknown engine {name!r}; allowed: {', '.join(BACKENDS)}")
    return importlib.import_module(BACKENDS[name])


def simulate(name: str, scene, excitation, settings=None):
    """Run ``scene`` under ``excitation`` in backend ``name``; returns a Trajectory."""
    return get_backend(name).simulate(scene, excitation, settings)
