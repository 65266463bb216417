"""``trilith calibrate``: the cheapest settings of an engine that agree with the model."""
from __future__ import annotations

import argparse
import math

from trilith_xval.analytic.options import MAX_ENGINE_DT

from trilith_xval.compare.cli import options as _common
from trilith_xval.compare.cli.excitation_args import check_run_budget
from trilith_xval.compare.cli.options import (PLOT_SUFFIXES, add_scene_args, add_settings_arg,
                                 add_store_args, add_workers_arg, check_output_path, envelope,
                                 file_options, info, resolve_workers,
                                 settings_from_args, settings_line, sig, use_store)
from trilith_xval.compare.cli.calibrate_kinds import (check_kind_calibration, kind_tables,
                                                     print_self_reference)
from trilith_xval.compare.cli.model_options import add_restitution_arg, restitution_factor
from trilith_xval.compare.run.jsonable import plain


def add_parser(subparsers) -> argparse.ArgumentParser:
    from trilith_xval.compare.campaign.calibrate import DT_FACTORS, METRICS
    from trilith_xval.engines import engine_names
    parser = subparsers.add_parser(
        "calibrate",
        help="the cheapest engine settings meeting a tolerance on a validation set: "
             "Pareto front of CPU cost against worst error",
        description="Evaluate every combination of the varied settings on a validation set "
                    "(restitution: free rocking vs Eq. 19/20; thresholds: first-overturning "
                    "amplitudes vs the model; histories: theta(t) at the paper's points A-D), "
                    "measure each one's CPU time with the run store bypassed, and recommend "
                    "the cheapest within the tolerance. On a scene of another kind (no model): "
                    "thresholds only, each candidate against the engine's own thresholds at its "
                    "reference step (the finest --dt, or the engine's reference step).")
    parser.add_argument("--engine", required=True, metavar="NAME",
                        help=f"the engine to calibrate: {', '.join(engine_names())}")
    add_scene_args(parser, several=True)
    parser.add_argument("--metric", choices=METRICS, default="thresholds",
                        help="what must agree")
    parser.add_argument("--tolerance", type=float, default=None, metavar="X",
                        help="largest acceptable worst error, in (0, 1] (default: the report's "
                             "own: 0.005 restitution, 0.02 thresholds, 1e-3 alpha histories)")
    parser.add_argument("--dt", default=None, metavar="S[,S...]",
                        help="time steps [s] to try (default: the engine's calibrated step x "
                             + ", ".join(f"{f:g}" for f in DT_FACTORS) + ")")
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=V1,V2,...",
                        help="another setting of the engine to try at these values (repeat "
                             "for several; every combination is evaluated); replaces the "
                             "engine's own declared range for that setting")
    parser.add_argument("--step-only", action="store_true",
                        help="search the time step only: leave out the engine's declared "
                             "ranges of its other settings (docs/calibrate.md)")
    parser.add_argument("--omega", default=None, metavar="W1,W2,...",
                        help="pulse frequencies [rad/s] of the thresholds set (default: 6,12,18; "
                             "with --design each scene's own band)")
    parser.add_argument("--design", default=None, metavar="N,M",
                        help="thresholds over a sampled design instead of --scene: N training "
                             "triliths (the settings are chosen on them) and M held-out ones "
                             "(the chosen settings' worst error is reported on them), Latin "
                             "hypercube over lam, b, mu, gamma, l/h, gap/h, lintel height/b "
                             "(compare/campaign/design.py); the ranges become the settings' "
                             "domain in --settings-out")
    parser.add_argument("--seed", type=int, default=None, metavar="S",
                        help="the design's seed (default 34; the held-out set uses S + 1)")
    add_settings_arg(parser)
    add_restitution_arg(parser)
    add_workers_arg(parser)
    add_store_args(parser)
    parser.add_argument("--json", metavar="FILE", help="write every evaluation as JSON")
    parser.add_argument("--csv", metavar="FILE", help="write every evaluation as CSV")
    parser.add_argument("--plot", metavar="FILE.png", help="write the Pareto front plot")
    parser.add_argument("--settings-out", metavar="FILE.toml",
                        help="write the recommended settings as a settings file")
    return parser


def _number(text: str, option: str) -> float | int:
    try:
        value = int(text)
    except ValueError:
        try:
            value = float(text)
        except ValueError:
            raise ValueError(f"{option}: {text!r} is not a number") from None
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{option}: {text!r} is not finite")
    return value


def _omegas(text: str) -> tuple[float, ...]:
    """``--omega W1,W2,...``: at least one frequency."""
    omegas = tuple(float(_number(v.strip(), "--omega")) for v in text.split(",") if v.strip())
    if not omegas:
        raise ValueError(f"--omega must be a comma-separated list of frequencies [rad/s], "
                         f"got {text!r}")
    return omegas


def _space(args, engine: str, base: dict) -> dict:
    from trilith_xval.compare.campaign.calibrate import MAX_CANDIDATES, default_space
    space = default_space(engine, step_only=args.step_only, base=base)
    if args.dt is not None:
        space["dt"] = [float(_number(v.strip(), "--dt")) for v in args.dt.split(",") if v.strip()]
    for item in args.vary:
        name, sep, values = item.partition("=")
        name = name.strip()
        if not sep or not name or not values.strip():
            raise ValueError(f"--vary must be NAME=V1,V2,..., got {item!r}")
        if name == "dt":
            raise ValueError("--vary: give the steps with --dt")
        space[name] = [_number(v.strip(), f"--vary {name}") for v in values.split(",")
                       if v.strip()]
    if any(not v for v in space.values()):
        raise ValueError("--dt/--vary: give at least one value")
    n = math.prod(len(v) for v in space.values())
    if n > MAX_CANDIDATES:
        raise ValueError(f"--dt/--vary: {n} combinations; at most {MAX_CANDIDATES} per "
                         "calibration")
    return space


def _check_budget(engine: str, space: dict, vs, base: dict, source: str = "--dt",
                  scenes=()) -> None:
    """Refuse before any work a step that is not positive or whose longest run
    (the lowest validation frequency's pulse) is over the run budget; ``source``
    names where the steps came from (``--dt``, or the ``--settings`` file whose
    step the default search multiplies)."""
    import dataclasses

    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.engines import configure

    settings = configure(engine, **base)
    for dt in space.get("dt", [settings.dt]):
        if not 0.0 < dt <= MAX_ENGINE_DT:
            raise ValueError(f"{source}: each step must be in (0, {MAX_ENGINE_DT:g}] s, "
                             f"got {dt!r}")
        check_run_budget(engine, dataclasses.replace(settings, dt=dt),
                         Pulse(1.0, _lowest_omega(vs, scenes)), option=source)


def _lowest_omega(vs, scenes) -> float:
    """The lowest validation frequency (the longest pulse) [rad/s]."""
    from trilith_xval.compare.campaign.design import scene_omegas
    if vs.omegas:
        return min(vs.omegas)
    return min(w for sc in scenes for w in scene_omegas(sc))


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.campaign.calibrate import ValidationSet, calibrate
    from trilith_xval.compare.campaign.settings_file import settings_toml
    from trilith_xval.compare.run import atomic

    engine = _common.parse_engine_list(args.engine)
    if len(engine) != 1:
        raise ValueError("--engine: calibrate one engine at a time")
    engine = engine[0]
    rf = restitution_factor(args)
    design = _design(args)
    scenes = design[0] if design else _common.scenes_from_args(args)
    kind = check_kind_calibration(args, scenes, rf)
    loaded = settings_from_args(args, (engine,))
    for sc in scenes if loaded is not None and loaded.options(engine) else ():
        loaded.check_scene(sc)
    base = file_options(loaded, engine)
    space = _space(args, engine, base)
    dt_ref = None
    if kind != "trilith":  # the engine's own reference: the finest step asked, or its own
        from trilith_xval.engines.calibration import reference_dt
        dt_ref = min(space["dt"]) if args.dt is not None else reference_dt(engine)
    names = tuple(sc.name for sc in scenes)
    name = names[0] if len(names) == 1 else names
    vs = (ValidationSet(scene=name, omegas=_omegas(args.omega)) if args.omega is not None
          else ValidationSet(scene=name, omegas=()) if design else ValidationSet(scene=name))
    if args.tolerance is not None and not (math.isfinite(args.tolerance)
                                           and 0.0 < args.tolerance <= 1.0):
        raise ValueError(f"--tolerance must be in (0, 1], got {args.tolerance!r}")
    if args.dt is not None:
        source = "--dt"
    elif "dt" in base:  # the default search multiplies the file's step
        source = f"--settings {loaded.path!r} (dt = {base['dt']!r}, times the search factors)"
    else:
        source = f"{engine}'s calibrated step (times the search factors)"
    _check_budget(engine, space, vs, base, source, scenes)
    if dt_ref is not None:
        _check_budget(engine, {"dt": [dt_ref]}, vs, base, "the reference step", scenes)
    workers = resolve_workers(args.workers)
    outputs = {"--json": args.json, "--csv": args.csv, "--settings-out": args.settings_out}
    for option, path in outputs.items():
        if path is not None:
            check_output_path(path, option)
    if args.plot is not None:
        check_output_path(args.plot, "--plot", suffixes=PLOT_SUFFIXES)
    use_store(args)
    if loaded is not None:
        info(settings_line(loaded, engine) + " (every candidate starts from them)")
    bar = None
    if _common.VERBOSITY >= 0:
        from trilith_xval.compare.run.progress import bar as progress_bar
        bar = progress_bar(math.prod(len(v) for v in space.values()), "calibrate", "candidates")

    def progress(done, total, ev):
        if bar is not None:
            bar.update(1)

    cal = calibrate(engine, args.metric, validation=vs, space=space, tolerance=args.tolerance,
                    workers=workers, progress=progress, scene=scenes, base=base,
                    restitution_factor=rf, reference_dt=dt_ref)
    if bar is not None:
        bar.close()
    _print(cal)
    if kind != "trilith":
        print_self_reference(cal)
    held = None
    if design and cal.recommended is not None:
        held = _held_out(engine, args, cal, design[1], vs, base, workers)
    body = plain(cal.to_dict())
    if args.json is not None:
        import json
        inputs = {"engine": engine, "metric": args.metric,
                  "scene": [sc.to_dict() for sc in scenes] if len(scenes) > 1
                  else scenes[0].to_dict()}
        if rf != 1.0:
            inputs["restitution_factor"] = rf
        atomic.write_text(args.json, json.dumps(envelope("calibrate", inputs, body, {}),
                                                indent=1) + "\n")
        info(f"wrote {args.json}")
    if args.csv is not None:
        atomic.write_text(args.csv, _csv(cal))
        info(f"wrote {args.csv}")
    if args.plot is not None:
        from trilith_xval.compare.report.calibration_plot import pareto_plot
        pareto_plot(cal, args.plot)
        info(f"wrote {args.plot}")
    rec = cal.recommended
    if args.settings_out is not None:
        if rec is None:
            info(f"no candidate met the tolerance: {args.settings_out} not written")
        else:
            text = settings_toml(engine, {**base, **rec.options}, (
                f"{_command(args, engine)}\nworst error {rec.worst_error:.3g} "
                f"(tolerance {cal.tolerance:g}), {rec.engine_cpu_s:.3g} engine CPU s on the "
                f"{'training' if design else 'validation'} set"))
            if design:
                text += _domain_tables(args, cal, design, held)
            if kind != "trilith":
                text += kind_tables(cal, scenes)
            atomic.write_text(args.settings_out, text)
            info(f"wrote {args.settings_out}")
    return 0 if rec is not None else 1


def _command(args, engine: str) -> str:
    """The calibrate command that regenerates a settings file (what it varied)."""
    import shlex
    words = [f"trilith calibrate --engine {engine} --metric {args.metric}"]
    if args.design is None:
        words += [f"--scene {shlex.quote(item)}" for item in args.scene or ["fig5"]]
    words += [f"--set {shlex.quote(item)}" for item in args.overrides]
    if args.no_pendulum:
        words.append("--no-pendulum")
    if args.settings is not None:
        words.append(f"--settings {shlex.quote(args.settings)}")
    words += [f"--{k} {getattr(args, k)}" for k in ("dt", "omega", "tolerance", "design",
                                                    "seed")
              if getattr(args, k) is not None]
    words += [f"--vary {v}" for v in args.vary]
    if args.step_only:
        words.append("--step-only")
    if restitution_factor(args) != 1.0:  # these settings match the scaled model only
        words.append(f"--restitution-factor {restitution_factor(args)!r}")
    return " ".join(words)


def _design(args):
    """``(training scenes, held-out scenes)`` of ``--design N,M``, or None."""
    if args.design is None:
        if args.seed is not None:
            raise ValueError("--seed: only with --design")
        return None
    from trilith_xval.compare.campaign.design import SEED, design_scenes
    if args.metric != "thresholds":
        raise ValueError("--design: only for --metric thresholds")
    if args.scene or args.overrides or args.no_pendulum:
        raise ValueError("--design: the design gives the scenes; leave out --scene, --set "
                         "and --no-pendulum")
    parts = [p.strip() for p in args.design.split(",")]
    if len(parts) != 2 or not all(p.isdigit() for p in parts):
        raise ValueError(f"--design must be N,M (training and held-out scene counts), got "
                         f"{args.design!r}")
    n, m = int(parts[0]), int(parts[1])
    if not (1 <= n <= 50 and 1 <= m <= 50):
        raise ValueError(f"--design: N and M must be in [1, 50], got {n},{m}")
    seed = SEED if args.seed is None else args.seed
    if not 0 <= seed < 2 ** 32 - 1:
        raise ValueError(f"--seed must be in [0, 2^32 - 2], got {seed}")
    return (design_scenes(n, seed, prefix="train"), design_scenes(m, seed + 1, prefix="held"),
            seed)


def _held_out(engine, args, cal, held, vs, base, workers):
    """The recommended settings' worst error on the held-out scenes (one candidate)."""
    from trilith_xval.compare.campaign.calibrate import ValidationSet, calibrate
    names = tuple(sc.name for sc in held)
    ev = calibrate(engine, "thresholds", validation=ValidationSet(scene=names, omegas=vs.omegas),
                   space={k: [v] for k, v in cal.recommended.options.items()},
                   tolerance=cal.tolerance, workers=workers, scene=held,
                   base=base, restitution_factor=restitution_factor(args)).evaluations[0]
    worst = max(ev.errors, key=lambda e: e[1]) if ev.errors else ("-", math.nan)
    print(f"held-out ({len(held)} scenes, {len(ev.errors)} points): worst error "
          f"{ev.worst_error:.3g} at {worst[0]} (tolerance {cal.tolerance:g}, "
          f"{'met' if ev.worst_error <= cal.tolerance else 'NOT met'}); "
          f"{ev.engine_cpu_s:.3g} engine CPU s")
    return ev


def _domain_tables(args, cal, design, held) -> str:
    """The ``[domain]`` and ``[calibration]`` tables of a design's settings file."""
    from trilith_xval.compare.campaign.design import OMEGA_OVER_P, domain_table
    rec = cal.recommended
    lines = ["", "# The ranges the design sampled: a scene uses these settings only inside",
             "# every one (engines/calibration.py); outside, the reference step runs.",
             "[domain]"]
    for key, value in domain_table().items():
        lines.append(f"{key} = " + ("true" if value is True else repr(value)))
    train, test, seed = design
    lines += ["", "[calibration]", f"seed = {seed}", f"training_scenes = {len(train)}",
              f"training_points = {len(rec.errors)}",
              f"training_worst_error = {rec.worst_error!r}",
              f"held_out_scenes = {len(test)}", f"held_out_seed = {seed + 1}",
              f"held_out_points = {len(held.errors) if held else 0}",
              f"held_out_worst_error = {(held.worst_error if held else math.nan)!r}",
              f"tolerance = {cal.tolerance!r}",
              f"omega_over_p = {list(OMEGA_OVER_P)!r}"]
    return "\n".join(lines) + "\n"


def _label(options: dict) -> str:
    return ", ".join(f"{k} {sig(v)}" for k, v in options.items())


def _print(cal) -> None:
    rec, front = cal.recommended, {id(e) for e in cal.front}
    load = ", ".join(f"{x:.2f}" for x in cal.load_average)
    print(f"{cal.engine} ({cal.version}), metric {cal.metric}, tolerance {cal.tolerance:g}, "
          f"load average {load}")
    width = max([30] + [len(_label(e.options)) for e in cal.evaluations])
    print(f"{'settings':<{width}} {'worst error':>11} {'engine CPU [s]':>14} {'CPU/sim s':>9} "
          f"{'all CPU [s]':>11} {'runs':>5}")
    for e in sorted(cal.evaluations, key=lambda e: e.engine_cpu_s):
        mark = ("<- recommended" if e is rec else "front" if id(e) in front else "")
        rtf = e.real_time_factor
        print(f"{_label(e.options):<{width}} {e.worst_error:11.3g} {e.engine_cpu_s:14.3g} "
              f"{(f'{rtf:.3g}' if math.isfinite(rtf) else '-'):>9} {e.cpu_s:11.3g} "
              f"{e.runs:5d}  {mark}")
    served = sum(e.from_store for e in cal.evaluations)
    if served:
        print(f"{served} of {len(cal.evaluations)} candidates served by the run store (whole, "
              "or the scenes finished before a kill), with the costs measured when they ran "
              "(--no-cache measures every one now)")
    if rec is None:
        print(f"no candidate meets {cal.tolerance:g}: widen the search (--dt, --vary) "
              f"or the tolerance")


def _csv(cal) -> str:
    names = list(cal.evaluations[0].options) if cal.evaluations else []
    front = {id(e) for e in cal.front}
    lines = [",".join([*names, "worst_error", "engine_cpu_s", "cpu_s", "simulated_s",
                       "engine_cpu_per_simulated_s", "runs", "on_front", "recommended",
                       "from_store"])]
    for e in cal.evaluations:
        lines.append(",".join([*(repr(e.options[n]) for n in names), repr(e.worst_error),
                               repr(e.engine_cpu_s), repr(e.cpu_s), repr(e.simulated_s),
                               repr(e.real_time_factor),
                               str(e.runs), str(id(e) in front).lower(),
                               str(e is cal.recommended).lower(),
                               str(e.from_store).lower()]))
    return "\n".join(lines) + "\n"
