"""Backends behind one contract, selected by name (like scipy's ``solve_ivp`` methods).

The contract is code, in :mod:`engines.base`: every backend module has ``NAME``,
``CAPABILITIES``, a frozen ``Settings`` derived from
:class:`analytic.options.RunOptions` (criterion, t_max, theta0, psi0,
early_stop; engines add dt, base_motion, sample_every, monitor through
:class:`engines.base.EngineSettings`), ``simulate(scene, excitation, settings)
-> Trajectory`` and ``version()``.  :func:`configure` is the one way to build a
backend's settings; :func:`supports` reads its declared capabilities.

Adding an engine is one module ``engines/<name>_engine.py`` and one line in
:data:`BACKENDS` (and :data:`ENGINES`); see ``docs/adding-an-engine.md``.
Modules are imported lazily, so the analytic model never imports an engine.

Examples
--------
>>> import engines
>>> s = engines.configure("pymunk", dt=5e-5, t_max=1.0)
>>> (s.dt, s.t_max, s.iterations)
(5e-05, 1.0, 30)
>>> engines.supports("pybullet", "render"), engines.supports("pymunk", "render")
(True, False)
>>> engines.configure("analytic", dt=1e-4)
Traceback (most recent call last):
...
ValueError: analytic has no option 'dt'; its options: atol, criterion, early_stop, ...
"""
from __future__ import annotations

import dataclasses
import importlib
from types import ModuleType

__all__ = ["BACKENDS", "ENGINES", "get_backend", "simulate", "backend_names", "configure",
           "supports", "engine_list"]

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
    """Every registered backend name, analytic ones first."""
    return tuple(BACKENDS)


def get_backend(name: str) -> ModuleType:
    """The backend module registered under ``name``; ``ValueError`` if unknown."""
    if not isinstance(name, str) or name not in BACKENDS:
        raise ValueError(f"unknown engine {name!r}; allowed: {', '.join(BACKENDS)}")
    try:
        return importlib.import_module(BACKENDS[name])
    except ModuleNotFoundError as exc:
        if exc.name and BACKENDS[name].startswith(exc.name):
            raise ValueError(f"backend {name!r} is not available in this checkout "
                             f"(module {BACKENDS[name]} is missing)") from None
        raise


def supports(name: str, capability: str) -> bool:
    """Whether backend ``name`` declares ``capability`` (see ``engines.base.CAPABILITIES``)."""
    from .base import CAPABILITIES
    if capability not in CAPABILITIES:
        raise ValueError(f"unknown capability {capability!r}; allowed: {', '.join(CAPABILITIES)}")
    return capability in get_backend(name).CAPABILITIES


def engine_list(spec: str | list | tuple) -> tuple[str, ...]:
    """``'pybullet,pymunk'`` / ``'all'`` / a sequence -> engine names, checked
    against :data:`ENGINES` (``ValueError`` naming the unknown one)."""
    items = spec.split(",") if isinstance(spec, str) else list(spec)
    names = [str(x).strip() for x in items if str(x).strip()]
    if names == ["all"]:
        return ENGINES
    if not names:
        raise ValueError(f"engine: name at least one of {', '.join(ENGINES)} (or 'all')")
    for n in names:
        if n not in ENGINES:
            raise ValueError(f"engine: unknown engine {n!r}; allowed: {', '.join(ENGINES)}, all")
    return tuple(dict.fromkeys(names))


def configure(name: str, settings=None, **options):
    """Backend ``name``'s settings: its calibrated defaults (or ``settings``) with
    ``options`` replaced.

    Parameters
    ----------
    name : str
        A registered backend.
    settings : the backend's Settings, optional
        Start from these instead of the defaults.
    **options
        Field values.  ``criterion`` may be given as ``'topple'``/``'alpha'`` (the
        backend's topple angle is kept); ``monitor`` (engines) as a dict of
        :class:`engines._common.MonitorSettings` fields to change.

    Returns
    -------
    The backend's frozen ``Settings``, validated.

    Raises
    ------
    ValueError
        Unknown backend, an option the backend does not have (naming its options),
        or a value out of range.
    """
    backend = get_backend(name)
    base = settings if settings is not None else backend.Settings()
    if not isinstance(base, backend.Settings):
        raise TypeError(f"settings must be a {backend.__name__}.Settings, "
                        f"got {type(base).__name__}")
    known = {f.name for f in dataclasses.fields(base)}
    for key in options:
        if key not in known:
            raise ValueError(f"{name} has no option {key!r}; its options: "
                             f"{', '.join(sorted(known))}")
    crit = options.get("criterion")
    if isinstance(crit, str):
        from analytic.trajectory import OverturnCriterion
        options["criterion"] = OverturnCriterion(crit, base.criterion.topple_angle)
    if isinstance(options.get("monitor"), dict):
        options["monitor"] = dataclasses.replace(base.monitor, **options["monitor"])
    return dataclasses.replace(base, **options) if options else base


def simulate(name: str, scene, excitation, settings=None, **options):
    """Run ``scene`` under ``excitation`` in backend ``name``; returns a Trajectory.

    ``options`` are applied to ``settings`` (or the defaults) by :func:`configure`.
    """
    if options:
        settings = configure(name, settings, **options)
    return get_backend(name).simulate(scene, excitation, settings)
