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


def parse_range(spec: str, option: str, unit: str = "rad/s", lo: float = 0.0,
                hi: float = 1e4, max_count: int = 100_000):
    """``'START:STOP:STEP'`` (STOP included) or ``'V1,V2,...'`` -> a sorted-as-given
    float array, every value in ``(lo, hi]``; ValueError naming ``option`` otherwise.
    Used for ``--omega`` (frequencies) and ``--amplitude`` (``trilith map``)."""
    import numpy as np
    text = str(spec).strip()
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) != 3:
                raise ValueError
            start, stop, step = parts
            if not all(math.isfinite(p) for p in parts) or step <= 0 or stop < start:
                raise ValueError
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            if n > max_count:
                raise ValueError(f"{option} must give 1 to {max_count} values, got {n}")
            values = np.round(start + step * np.arange(n), 12)
        else:
            values = np.array([float(p) for p in text.split(",")])
    except ValueError as exc:
        if str(exc).startswith(option):
            raise
        raise ValueError(f"{option} expects START:STOP:STEP with {lo:g} < START <= STOP, "
                         f"STEP > 0 (or a comma list), got {spec!r}") from None
    if values.size == 0 or values.size > max_count:
        raise ValueError(f"{option} must give 1 to {max_count} values, got {values.size}")
    if not np.all(np.isfinite(values)) or np.any(values <= lo) or np.any(values > hi):
        raise ValueError(f"{option}: every value must be in ({lo:g}, {hi:g}] {unit}, "
                         f"got {spec!r}")
    return values


def parse_omega_range(spec: str, option: str = "--omega"):
    """``'START:STOP:STEP'`` (STOP included) or ``'W1,W2,...'`` -> frequencies in
    (0, 1e4] rad/s."""
    return parse_range(spec, option, "rad/s", 0.0, 1e4)
