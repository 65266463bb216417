"""Options shared by the subcommands: scene, overrides, pulse, engine."""
from __future__ import annotations

import argparse
import json
import math
import sys

from analytic.excitation import PULSE_KINDS, Pulse
from analytic.parameters import Scene
from scenes import load_scene

SETTABLE = ("b", "lam", "mu", "gamma", "l", "column_mass", "J_G", "gap", "lintel_height",
            "hinge_x", "depth", "g")


def add_scene_args(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scene", default="fig5",
                        help="scene name (scenes/data/*.toml) or path to a TOML file [fig5]")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="NAME=VALUE",
                        help=f"override a scene value; NAME in {', '.join(SETTABLE)}")
    parser.add_argument("--no-pendulum", action="store_true", help="remove the pendulum (gamma = 0)")


def parse_overrides(items: list[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}")
        if name not in SETTABLE:
            raise ValueError(f"--set: unknown name {name!r}; allowed: {', '.join(SETTABLE)}")
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"--set {name}: {value!r} is not a number") from None
        if not math.isfinite(number):
            raise ValueError(f"--set {name}: must be finite, got {value!r}")
        out[name] = number
    return out


def scene_from_args(args: argparse.Namespace) -> Scene:
    overrides = parse_overrides(args.overrides)
    if getattr(args, "no_pendulum", False):
        overrides["gamma"] = 0.0
    return load_scene(args.scene, **overrides)


def add_pulse_args(parser: argparse.ArgumentParser, required: bool = True) -> None:
    parser.add_argument("--pulse", choices=PULSE_KINDS, default="sine",
                        help="one-sine (Eq. 22) or one-cosine (Eq. 23) pulse [sine]")
    parser.add_argument("--amplitude", "-A", type=float, required=required,
                        help="pulse amplitude A [m/s^2]")
    parser.add_argument("--omega", "-w", type=float, required=required,
                        help="pulse circular frequency Omega [rad/s], > 0")


def pulse_from_args(args: argparse.Namespace) -> Pulse:
    return Pulse(args.amplitude, args.omega, args.pulse)


def add_engine_arg(parser: argparse.ArgumentParser, default: str = "analytic") -> None:
    parser.add_argument("--engine", default=default,
                        help=f"backend: analytic, analytic-fast, pybullet, pymunk [{default}]")


def print_json(obj) -> None:
    json.dump(obj, sys.stdout, indent=2, default=_json_default, allow_nan=False)
    sys.stdout.write("\n")


def _json_default(value):
    import numpy as np
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if hasattr(value, "describe"):
        return value.describe()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def clean_nan(obj):
    """Replace non-finite floats by None so the JSON is strict."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: clean_nan(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean_nan(v) for v in obj]
    return obj


# --- run store, scheduler and interruption (issue 12; appended by the store12 helper) ---
def add_store_args(parser: argparse.ArgumentParser, scheduler: bool = False) -> None:
    """``--cache DIR``, ``--no-cache`` and, with ``scheduler``, ``--scheduler ADDRESS``."""
    from compare.store import default_cache_dir

    group = parser.add_mutually_exclusive_group()
    group.add_argument("--cache", metavar="DIR", default=None,
                       help="run store directory: finished runs are reused, a killed run "
                            f"resumes [$TRILITH_CACHE or {default_cache_dir()}]")
    group.add_argument("--no-cache", action="store_true",
                       help="compute everything, store nothing")
    if scheduler:
        parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                            help="run on a Dask distributed cluster, e.g. tcp://host:8786 "
                                 "(default: local processes)")


def use_store(args: argparse.Namespace):
    """Activate the run store (and scheduler) the options ask for; returns the store
    (None with ``--no-cache``).  Call before any work: a bad ``--cache`` or
    ``--scheduler`` is a usage error."""
    from compare import runs
    from compare.store import RunStore, default_cache_dir

    address = getattr(args, "scheduler", None)
    if address is not None and not (address.startswith(("tcp://", "tls://", "inproc://",
                                                        "ucx://")) and "://" in address):
        raise ValueError(f"--scheduler must be an address like tcp://host:8786, got {address!r}")
    runs.set_scheduler(address)
    runs.STATS.clear()
    store = None if getattr(args, "no_cache", False) else RunStore(
        args.cache if getattr(args, "cache", None) else default_cache_dir())
    runs.activate(store)
    return store
