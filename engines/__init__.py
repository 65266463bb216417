"""Backends behind one contract, selected by name (like scipy's ``solve_ivp`` methods).

A physics engine is a subclass of :class:`engines.base.Engine` (its rules are in
that class's docstring), registered by one line in :data:`ENGINE_CLASSES` or, from
a separately installed package, by an entry point of the group
``trilith_xval.engines`` (``name = "package.module:Class"``).  The analytic model
(``analytic``, ``analytic-fast``) is selectable the same way through small
adapters (:mod:`engines.analytic_`); it never imports this package.  Everywhere
else (help texts, reports, recordings, tests, benchmarks) the engine list comes
from :func:`engine_names`, display metadata from the class (``label``, ``color``,
``marker``).  Classes are imported only when a backend is asked for.

Examples
--------
>>> from trilith_xval import engines
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
from functools import lru_cache

__all__ = ["BACKENDS", "ENGINES", "ENGINE_CLASSES", "ENTRY_POINT_GROUP", "get_backend",
           "simulate", "backend_names", "engine_names", "default_engines", "configure",
           "supports", "engine_list"]

# The physics engines under validation: name -> "module:Class".
ENGINE_CLASSES: dict[str, str] = {
    "pybullet": "trilith_xval.engines.pybullet_:PyBulletEngine",
    "pymunk": "trilith_xval.engines.pymunk_:PymunkEngine",
    "mujoco": "trilith_xval.engines.mujoco_:MujocoEngine",
    "dart": "trilith_xval.engines.dart_:DartEngine",
    "drake": "trilith_xval.engines.drake_:DrakeEngine",
}
BACKENDS: dict[str, str] = {
    "analytic": "trilith_xval.engines.analytic_:Analytic",
    "analytic-fast": "trilith_xval.engines.analytic_:AnalyticFast",
    **ENGINE_CLASSES,
}
ENGINES: tuple[str, ...] = tuple(ENGINE_CLASSES)
ENTRY_POINT_GROUP = "trilith_xval.engines"


@lru_cache(maxsize=None)
def _installed() -> dict[str, str]:
    """Engines registered by other installed packages (entry points)."""
    from importlib.metadata import entry_points
    found = {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}
    clash = sorted(set(found) & set(BACKENDS))
    if clash:  # silently preferring one would measure another engine than asked for
        raise ValueError(f"installed engine(s) {', '.join(clash)} (entry point group "
                         f"{ENTRY_POINT_GROUP}) clash with built-in backends of the same "
                         f"name; rename them in their package")
    return found


def engine_names() -> tuple[str, ...]:
    """Every physics engine: the built-in ones, then those installed as entry points."""
    return ENGINES + tuple(_installed())


def default_engines() -> tuple[str, ...]:
    """The engines a command runs when none are named for a multi-engine sweep
    (atlas, trust): those whose class says ``affordable``."""
    return tuple(e for e in engine_names() if getattr(get_backend(e), "affordable", True))


def backend_names() -> tuple[str, ...]:
    """Every registered backend name, analytic ones first."""
    return tuple(BACKENDS) + tuple(_installed())


def get_backend(name_or_class):
    """The backend class registered under a name (or the class itself, checked);
    ``ValueError`` if unknown or not importable in this checkout."""
    from .base import Engine
    if isinstance(name_or_class, type):
        from .analytic_ import AnalyticBackend
        if not issubclass(name_or_class, (Engine, AnalyticBackend)):
            raise TypeError(f"engine: a class must subclass engines.base.Engine, "
                            f"got {name_or_class.__name__}")
        return name_or_class
    target = BACKENDS.get(name_or_class) if isinstance(name_or_class, str) else None
    if target is None and isinstance(name_or_class, str):
        target = _installed().get(name_or_class)
    if target is None:
        raise ValueError(f"unknown engine {name_or_class!r}; allowed: "
                         f"{', '.join(backend_names())}")
    module_name, _, attr = target.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and module_name.startswith(exc.name):
            raise ValueError(f"backend {name_or_class!r} is not available in this checkout "
                             f"(module {module_name} is missing)") from None
        raise
    return getattr(module, attr)


def supports(name, capability: str) -> bool:
    """Whether backend ``name`` (or class) declares ``capability`` (see
    ``engines.base.CAPABILITIES``)."""
    from .base import CAPABILITIES
    if capability not in CAPABILITIES:
        raise ValueError(f"unknown capability {capability!r}; allowed: {', '.join(CAPABILITIES)}")
    return capability in get_backend(name).capabilities


def engine_list(spec: str | list | tuple) -> tuple[str, ...]:
    """``'pybullet,pymunk'`` / ``'all'`` / a sequence -> engine names, checked
    against :func:`engine_names` (``ValueError`` naming the unknown one)."""
    known = engine_names()
    items = spec.split(",") if isinstance(spec, str) else list(spec)
    names = [str(x).strip() for x in items if str(x).strip()]
    if names == ["all"]:
        return known
    if not names:
        raise ValueError(f"engine: name at least one of {', '.join(known)} (or 'all')")
    for n in names:
        if n not in known:
            raise ValueError(f"engine: unknown engine {n!r}; allowed: {', '.join(known)}, all")
    return tuple(dict.fromkeys(names))


def configure(name_or_class, settings=None, **options):
    """A backend's settings: its calibrated defaults (or ``settings``) with
    ``options`` replaced.

    Parameters
    ----------
    name_or_class : str or Engine subclass
        A registered backend.
    settings : the backend's Settings, optional
        Start from these instead of the defaults.
    **options
        Field values.  ``criterion`` may be given as ``'topple'``/``'alpha'`` (the
        backend's topple angle is kept); ``monitor`` (engines) as a dict of
        :class:`engines.monitor.MonitorSettings` fields to change.

    Returns
    -------
    The backend's frozen ``Settings``, validated.

    Raises
    ------
    ValueError
        Unknown backend, an option the backend does not have (naming its options),
        or a value out of range.
    """
    backend = get_backend(name_or_class)
    name = backend.name
    base = settings if settings is not None else backend.Settings()
    if not isinstance(base, backend.Settings):
        raise TypeError(f"settings must be a {name} Settings, got {type(base).__name__}")
    known = {f.name for f in dataclasses.fields(base)}
    for key in options:
        if key not in known:
            raise ValueError(f"{name} has no option {key!r}; its options: "
                             f"{', '.join(sorted(known))}")
    crit = options.get("criterion")
    if isinstance(crit, str):
        from trilith_xval.analytic.trajectory import OverturnCriterion
        options["criterion"] = OverturnCriterion(crit, base.criterion.topple_angle)
    if isinstance(options.get("monitor"), dict):
        options["monitor"] = dataclasses.replace(base.monitor, **options["monitor"])
    return dataclasses.replace(base, **options) if options else base


def simulate(name_or_class, scene, excitation, settings=None, **options):
    """Run ``scene`` under ``excitation`` in a backend; returns a Trajectory.

    ``options`` are applied to ``settings`` (or the defaults) by :func:`configure`.
    """
    if options:
        settings = configure(name_or_class, settings, **options)
    return get_backend(name_or_class).simulate(scene, excitation, settings)
