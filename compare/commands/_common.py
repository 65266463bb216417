"""Options shared by the subcommands: scene, overrides, pulse, engine."""
from __future__ import annotations

import argparse
import json
import math
import sys

from analytic.excitation import PULSE_KINDS, Pulse
from analytic.parameters import Scene
from scenes import load_scene

from ..jsonable import plain

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
    """``obj`` as strict JSON on stdout (:func:`compare.jsonable.plain`)."""
    json.dump(plain(obj), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


clean_nan = plain  # the one JSON cleaner (compare.jsonable); old name kept for callers
