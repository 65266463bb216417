"""``trilith view``: watch a run in a window (see ``compare/show/view.py``).

Without a display it exits with code 2 and a message pointing at ``trilith record``.
"""
from __future__ import annotations

import argparse

from trilith_xval.compare.show.view import view

from trilith_xval.compare.cli.record import add_watch_args, watch_inputs


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "view", help="watch a run in a window (PyBullet GUI or matplotlib animation)",
        description="Simulate a scene and show it live. Needs a display; otherwise use "
                    "'trilith record' (exit code 2).")
    add_watch_args(parser)


def run(args: argparse.Namespace) -> int:
    scene, excitation, settings = watch_inputs(args)
    engines = (args.engine if getattr(scene, "kind", "trilith") == "trilith"
               else ",".join(r.backend for r in settings.runs))  # "all" resolved for the kind
    view(scene, excitation, engines, fps=args.fps, duration=args.duration,
         scene_arg=args.scene, runs=settings.runs)
    return 0
