"""``trilith record``: write a GIF/MP4 of a run, headless (see ``scenes/record.py``)."""
from __future__ import annotations

import argparse

from scenes.record import (ALL_ENGINES, DEFAULT_AMPLITUDE, DEFAULT_OMEGA, RecordSettings,
                           check_output, record)

from ._common import add_pulse_args, add_scene_args, pulse_from_args, scene_from_args


def add_watch_args(parser: argparse.ArgumentParser) -> None:
    """Options shared by ``view`` and ``record``."""
    add_scene_args(parser)
    parser.add_argument("--engine", default="analytic",
                        help="backend: analytic, analytic-fast, pybullet, pymunk, or all "
                             f"({', '.join(ALL_ENGINES)} side by side) [analytic]")
    add_pulse_args(parser, required=False)
    parser.set_defaults(amplitude=DEFAULT_AMPLITUDE, omega=DEFAULT_OMEGA)
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second [30]")
    parser.add_argument("--duration", type=float, default=None,
                        help="seconds to show [ten pulse periods, the paper's t_max]")


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "record", help="record a run to a GIF or MP4 (no display needed)",
        description="Simulate a scene in one backend (or all, side by side on the same "
                    "time base) and write an animation. GIF needs only Pillow; MP4 needs "
                    "ffmpeg on PATH.")
    add_watch_args(parser)
    parser.add_argument("--out", required=True, help="output file, .gif or .mp4")
    parser.add_argument("--width", type=int, default=480, help="pixels per panel [480]")
    parser.add_argument("--height", type=int, default=360, help="pixels per panel [360]")


def run(args: argparse.Namespace) -> int:
    scene = scene_from_args(args)
    pulse = pulse_from_args(args)
    settings = RecordSettings(fps=args.fps, duration=args.duration, panel_width=args.width,
                              panel_height=args.height)
    check_output(args.out)
    result = record(scene, pulse, args.engine, args.out, settings)
    verdicts = ", ".join(f"{name}: {traj.verdict.status}"
                         + (f" at {traj.verdict.time:.3f} s" if traj.overturned else "")
                         for name, traj in result.trajectories.items())
    print(f"wrote {result.path}: {result.n_frames} frames at {result.fps:g} fps "
          f"({result.duration:.3f} s); {verdicts}")
    return 0
