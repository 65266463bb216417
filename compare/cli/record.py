"""``trilith record``: write a GIF/MP4 of a run, headless (see ``compare/show/record.py``)."""
from __future__ import annotations

import argparse

from trilith_xval.engines import backend_names

from trilith_xval.compare.show.record import (ALL_ENGINES, DEFAULT_AMPLITUDE, DEFAULT_OMEGA, FORMATS,
                           RecordSettings, check_output, default_duration, record,
                           resolve_engines)

from trilith_xval.compare.cli.excitation_args import (add_pulse_args, add_record_arg, check_run_budget,
                                         excitation_from_args)
from trilith_xval.compare.cli.options import add_scene_args, check_output_path, scene_from_args
from trilith_xval.compare.cli.options import add_settings_arg, run_spec, settings_from_args


def add_watch_args(parser: argparse.ArgumentParser) -> None:
    """Options shared by ``view`` and ``record``."""
    add_scene_args(parser)
    parser.add_argument("--engine", default="analytic", metavar="NAME[,NAME...]",
                        help="backends side by side on one time base "
                             f"({', '.join(backend_names())}), or all "
                             f"({', '.join(ALL_ENGINES)})")
    add_pulse_args(parser, required=False)
    parser.set_defaults(amplitude=None, omega=None)
    for action in parser._actions:  # the defaults live in compare.show.record: show them
        if action.dest == "amplitude":
            action.help += f" (default: {DEFAULT_AMPLITUDE:g}, the paper's case A)"
        elif action.dest == "omega":
            action.help += f" (default: {DEFAULT_OMEGA:g})"
    add_record_arg(parser)
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second")
    parser.add_argument("--duration", type=float, default=None, metavar="S",
                        help="seconds to show (default: ten pulse periods, the paper's t_max)")
    add_settings_arg(parser)


def watch_inputs(args: argparse.Namespace) -> tuple:
    """``(scene, excitation, settings)``, all checked, and the run budget of each
    backend over the recorded span."""
    from trilith_xval.engines import engine_names

    scene = scene_from_args(args)
    excitation = excitation_from_args(args, default=(DEFAULT_AMPLITUDE, DEFAULT_OMEGA))
    names = resolve_engines(args.engine)
    if getattr(scene, "kind", "trilith") != "trilith":
        names = kind_engines(scene, args.engine, names)
    loaded = settings_from_args(args, tuple(n for n in names if n in engine_names()))
    runs = tuple(run_spec(n, scene, excitation, loaded) for n in names)
    settings = RecordSettings(fps=args.fps, duration=args.duration,
                              panel_width=getattr(args, "width", 480),
                              panel_height=getattr(args, "height", 360), runs=runs)
    duration = args.duration if args.duration is not None else default_duration(excitation)
    for run in runs:
        check_run_budget(run.backend, run.settings, excitation, option="--duration",
                         length=duration)
    return scene, excitation, settings


def kind_engines(scene, given: str, names: tuple[str, ...]) -> tuple[str, ...]:
    """The engines of a recording of another kind: ``all`` is every engine that
    builds it (:data:`engines.geometry.STRUCTURE_ENGINES`); the model is refused,
    as an engine that runs the trilith only."""
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    if given.strip() == "all":
        return STRUCTURE_ENGINES
    for name in names:
        if name.startswith("analytic"):
            raise ValueError(f"--engine {name}: there is no model of the {scene.kind} kind; "
                             f"give engines from {', '.join(STRUCTURE_ENGINES)} (default "
                             f"analytic)")
        if name not in STRUCTURE_ENGINES:
            raise ValueError(f"--engine {name}: runs the parametric trilith only, not the "
                             f"{scene.kind} kind (engines that run it: "
                             f"{', '.join(STRUCTURE_ENGINES)})")
    return names


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "record", help="record a run to a GIF or MP4 (no display needed)",
        description="Simulate a scene in one backend (or all, side by side on the same "
                    "time base) and write an animation. GIF needs only Pillow; MP4 needs "
                    "ffmpeg on PATH.")
    add_watch_args(parser)
    parser.add_argument("--out", required=True, metavar="FILE",
                        help="output file, .gif or .mp4 (its directory must exist)")
    parser.add_argument("--width", type=int, default=480, help="pixels per panel")
    parser.add_argument("--height", type=int, default=360, help="pixels per panel")


def run(args: argparse.Namespace) -> int:
    scene, excitation, settings = watch_inputs(args)
    check_output_path(args.out, "--out", suffixes=FORMATS)
    check_output(args.out)  # the encoder (ffmpeg for .mp4)
    engines = (args.engine if getattr(scene, "kind", "trilith") == "trilith"
               else ",".join(r.backend for r in settings.runs))  # "all" resolved for the kind
    result = record(scene, excitation, engines, args.out, settings)
    kind = getattr(scene, "kind", "trilith") != "trilith"
    verdicts = ", ".join(f"{name}: {traj.verdict.status}"
                         + (f", overturn_time = {traj.overturn_time:.3f} s"
                            if traj.overturned else "")
                         + (f", at {traj.verdict.time:.3f} s" if kind and not traj.overturned
                            and traj.verdict.time is not None else "")
                         for name, traj in result.trajectories.items())
    print(f"wrote {result.path}: {result.n_frames} frames at {result.fps:g} fps "
          f"({result.duration:.3f} s); {verdicts}")
    return 0
