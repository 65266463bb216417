"""``trilith map``: the overturn map (amplitude x frequency) of the analytic model,
and of an engine on a coarser grid beside it (Zhang & Makris 2001 style)."""
from __future__ import annotations

import argparse
import math

from trilith_xval.engines import engine_names

from trilith_xval.compare.cli import options as _options
from trilith_xval.compare.cli.options import (PLOT_SUFFIXES, add_pulse_kind_arg, add_scene_args,
                                 add_store_args, add_workers_arg, check_output_path, parse_engine_list,
                                 parse_omega_range, parse_range, print_json, resolve_workers,
                                 scene_from_args)
from trilith_xval.compare.cli.map_cells import ENGINE_POINTS, EngineRun
from trilith_xval.compare.cli.map_text import print_map_summary, subsample
from trilith_xval.compare.report.map_plot import plot_maps
from trilith_xval.compare.cli.model_options import add_restitution_arg, restitution_factor
from trilith_xval.compare.measure.map_thresholds import LEAST_RUNS
from trilith_xval.compare.run.jsonable import plain

DEFAULT_OMEGA = "3:30:0.5"
DEFAULT_AMPLITUDE = "0.5:100:0.5"


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "map", help="overturn map: verdict per (Omega, A), with the first-overturning curve",
        description="Verdict of every pulse on an amplitude x frequency grid (overturned "
                    "without / after impact, survived, or an engine's other statuses), the "
                    "first-overturning curve on it, as a PNG, JSON or CSV.")
    add_scene_args(parser)
    add_pulse_kind_arg(parser)
    parser.add_argument("--omega", default=DEFAULT_OMEGA, metavar="START:STOP:STEP",
                        help="frequencies [rad/s], STOP included")
    parser.add_argument("--amplitude", default=DEFAULT_AMPLITUDE, metavar="A0:A1:dA",
                        help="amplitudes [m/s^2], A1 included")
    parser.add_argument("--engine", default=None, metavar="NAME[,NAME...]",
                        help=f"also map these engines ({', '.join(engine_names())}, or all), "
                             "each on a coarser grid beside the analytic map")
    parser.add_argument("--engine-omega", default=None, metavar="START:STOP:STEP",
                        help=f"engine frequencies (default: {ENGINE_POINTS} of --omega)")
    parser.add_argument("--engine-amplitude", default=None, metavar="A0:A1:dA",
                        help=f"engine amplitudes (default: {ENGINE_POINTS} of --amplitude)")
    parser.add_argument("--t-max", type=float, default=None, metavar="S",
                        help="fixed window of every engine run [s], no early stop (default: "
                             "each run stops when its verdict is certain)")
    _options.add_settings_arg(parser)
    add_restitution_arg(parser)
    parser.add_argument("--max-engine-runs", type=int, default=200, metavar="N",
                        help="refuse engine work of more runs than this in all: every grid "
                             f"cell, and at least {LEAST_RUNS} runs per robust threshold "
                             "point (one per engine frequency; more where the engine "
                             "disagrees)")
    parser.add_argument("--consensus", action="store_true",
                        help="where the model cannot judge an engine's threshold (cause "
                             "'model'), the engines against each other (two engines or more; "
                             "docs/atlas.md)")
    parser.add_argument("--convergence", action="store_true",
                        help="rerun disagreeing engine threshold points at dt/2, dt/4 and "
                             "doubled solver iterations to classify the cause")
    add_workers_arg(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    parser.add_argument("--csv", metavar="FILE",
                        help="write the cells and the engines' robust thresholds as CSV")
    parser.add_argument("--plot", metavar="FILE.png", help="write the map as a PNG")
    from trilith_xval.compare.cli.record_map import add_record_map_args
    add_record_map_args(parser)
    add_store_args(parser)
    return parser


def _engine_grid(args, omegas, amps, n_engines: int):
    w = (parse_omega_range(args.engine_omega, "--engine-omega") if args.engine_omega
         else subsample(omegas, ENGINE_POINTS))
    a = (parse_range(args.engine_amplitude, "--engine-amplitude", "m/s^2")
         if args.engine_amplitude else subsample(amps, ENGINE_POINTS))
    need = n_engines * w.size * (a.size + LEAST_RUNS)
    if need > args.max_engine_runs:
        raise ValueError(f"the engine grids need at least {need} runs ({w.size * a.size} cells "
                         f"and {LEAST_RUNS} per threshold point at {w.size} frequencies, per "
                         f"engine), more than --max-engine-runs {args.max_engine_runs}: coarsen "
                         f"--engine-omega/--engine-amplitude or raise --max-engine-runs")
    return w, a


CSV_COLUMNS = ("backend", "omega", "amplitude", "verdict", "model_valid_at_first_overturning",
               "a_survives", "a_reference", "rel_error", "rel_resolution", "cause", "valid",
               "isolated", "cpu_s")
THRESHOLD_COLUMNS = CSV_COLUMNS[5:]  # empty on the cells' rows


def _threshold_row(name: str, p) -> str:
    """A robust threshold as a CSV row: ``amplitude`` is where it overturns."""
    d = p.to_dict()
    iso = "; ".join(f"{i['amplitude']:.6g}" for i in d["isolated"])
    return (f"{name},{p.omega:.12g},{p.a_engine:.12g},first overturning (robust),,"
            f"{p.a_survives:.12g},{p.a_reference:.12g},{p.rel_error:.6g},"
            f"{p.point.rel_resolution:.6g},{p.cause},{p.valid},{iso},{p.cpu_s:.6g}")


def _print_thresholds(name: str, points) -> None:
    from trilith_xval.compare.measure.map_thresholds import threshold_cost
    cost = threshold_cost(points)
    print(f"{name}: robust thresholds at {cost['points']} frequencies, {cost['runs']} runs, "
          f"{cost['cpu_s']:.1f} CPU s when computed ({cost['cpu_s_spent']:.1f} spent now)")
    print(f"{'Omega':>7} {'A_model':>8} {'survives':>9} {'overturns':>9} {'error':>8}  cause")
    for p in points:
        res = 100 * p.point.rel_resolution
        print(f"{p.omega:7.3g} {p.a_reference:8.3f} {p.a_survives:9.3f} {p.a_engine:9.3f} "
              f"{100 * p.rel_error:+7.2f}% (bracket {res:.2g} %)  {p.cause}"
              + (f" [{len(p.isolated)} isolated]" if p.isolated else ""))


def run(args: argparse.Namespace) -> int:
    scene = scene_from_args(args)
    omegas = parse_omega_range(args.omega, "--omega")
    amps = parse_range(args.amplitude, "--amplitude", "m/s^2")
    workers = resolve_workers(args.workers)
    if args.t_max is not None and not (math.isfinite(args.t_max) and 0 < args.t_max <= 1e5):
        raise ValueError(f"--t-max must be a time in (0, 1e5] s, got {args.t_max!r}")
    if not (1 <= args.max_engine_runs <= 100_000):
        raise ValueError(f"--max-engine-runs must be in [1, 100000], got {args.max_engine_runs}")
    if args.csv:
        check_output_path(args.csv, "--csv")
    if args.plot:
        check_output_path(args.plot, "--plot", suffixes=PLOT_SUFFIXES)
    from trilith_xval.compare.cli.pulse_shape import shape_from_args
    shape = shape_from_args(args)
    engines, eng_grid = (), None
    rf = restitution_factor(args)
    if getattr(scene, "kind", "trilith") != "trilith":  # no model: the engines' own map
        if rf != 1.0:
            raise ValueError(f"--restitution-factor scales the model's impacts; there is no "
                             f"model of the {scene.kind} kind")
        from trilith_xval.compare.cli.map_kinds import kind_map
        return kind_map(args, scene, omegas, amps, workers, shape)
    if args.record is not None:
        if rf != 1.0:  # the record map runs the exact impact
            raise ValueError("--restitution-factor is not supported with --record yet")
        from trilith_xval.compare.cli.record_map import record_map
        return record_map(args, scene, workers,
                          parse_engine_list(args.engine) if args.engine is not None else ())
    if args.engine is not None:
        engines = parse_engine_list(args.engine)  # unknown name: refused before any work
    if args.consensus and len(engines) < 2:
        raise ValueError("--consensus compares engines with each other: give --engine with "
                         f"two or more, got {', '.join(engines) or 'none'}")
    if args.engine is not None:
        eng_grid = _engine_grid(args, omegas, amps, len(engines))
    loaded = _options.settings_from_args(args, engines)
    from trilith_xval.analytic.overturn_map import MAX_ACCURATE_CELLS, MAX_CELLS, analytic_map, verdict_map
    from trilith_xval.analytic.spectrum import SpectrumSettings
    settings = SpectrumSettings(pulse=shape)
    if rf != 1.0:  # at 1 the settings (and so every stored key) stay the defaults
        from trilith_xval.analytic.first_overturn import search_run_settings
        settings = SpectrumSettings(pulse=shape, fast=search_run_settings(restitution_factor=rf))
    top = MAX_CELLS if settings.compiled else MAX_ACCURATE_CELLS
    if omegas.size * amps.size > top:
        why = "" if settings.compiled else (f" for a {shape} pulse (the accurate model, "
                                            "~20 ms a cell)")
        raise ValueError(f"--omega x --amplitude gives {omegas.size * amps.size} cells, "
                         f"more than {top}{why}")
    from trilith_xval.analytic.excitation import Still
    window = None if args.t_max is None else {"t_max": args.t_max, "early_stop": False}
    # Each engine's runs, resolved once here (a bad value stops the command before
    # any run): the cells at its defaults, the threshold searches from its
    # calibration; the --settings table and --t-max over both.
    cells = {n: _options.run_spec(n, scene, Still(), loaded, overrides=window) for n in engines}
    searches = {n: _options.run_spec(n, scene, Still(), loaded, calibrated=True,
                                     overrides=window) for n in engines}
    if engines:  # a friction given below a cell's bound: refused here, not mid-map
        from trilith_xval.analytic.pulses import pulse_of
        for n in engines:
            for w in eng_grid[0]:
                cells[n].at(excitation=pulse_of(shape, float(max(eng_grid[1])), float(w)))
    maps = [analytic_map(scene, omegas, amps, settings, workers=workers)]
    for name in engines:
        maps.append(verdict_map(EngineRun(cells[name], settings.pulse), scene, *eng_grid,
                                backend=name, pulse=settings.pulse, workers=workers))
    thresholds = {}
    if engines:
        from trilith_xval.compare.measure.map_thresholds import map_thresholds, model_thresholds
        reference = model_thresholds(scene, eng_grid[0], settings.pulse, workers,
                                     restitution_factor=rf)
        _options.step_notes(engines, [scene])
        for name in engines:  # as spectrum --engine: calibrated threshold step, then the file
            thresholds[name] = map_thresholds(name, scene, eng_grid[0], settings.pulse,
                                              workers=workers, convergence=args.convergence,
                                              reference=reference, spec=searches[name])
    agreed = None
    if args.consensus:
        from trilith_xval.compare.cli.spectrum_engines import consensus_where_model_cannot_judge
        case = "pendulum" if scene.has_pendulum else "no_pendulum"
        agreed = consensus_where_model_cannot_judge(
            scene, searches, [(case, pts) for pts in thresholds.values()], settings.pulse)
    from trilith_xval.analytic.threshold_validity import curve_validity
    validity = curve_validity(scene, maps[0].omega, maps[0].first, settings.pulse, workers,
                              restitution_factor=rf)
    valid_at = {round(float(w), 9): v["model_valid"] for w, v in zip(maps[0].omega, validity)}

    def valid_text(w):
        v = valid_at.get(round(float(w), 9))
        return "" if v is None else str(v)

    if args.csv:
        from trilith_xval.compare.run.atomic import write_text
        blank = "," * (len(THRESHOLD_COLUMNS) - 1)
        rows = [",".join(CSV_COLUMNS)] + [
            f"{m.backend},{w:.12g},{a:.12g},{lab},{valid_text(w)},{blank}"
            for m in maps for w, a, lab in m.csv_rows()] + [
            _threshold_row(name, p) for name, pts in thresholds.items() for p in pts]
        write_text(args.csv, "\n".join(rows) + "\n")
    if args.plot:
        plot_maps(maps, args.plot, validity, thresholds)
    if args.json:
        from trilith_xval.compare.measure.map_thresholds import threshold_cost
        first = {**maps[0].to_dict(), "model_validity_first_overturning": validity}
        engine_maps = [{**m.to_dict(),
                        "thresholds": [p.to_dict() for p in thresholds[m.backend]],
                        "threshold_cost": threshold_cost(thresholds[m.backend])}
                       for m in maps[1:]]
        doc = {"maps": [first] + engine_maps}
        if rf != 1.0:  # absent at 1: the documents of exact-impact maps stay as they were
            doc["restitution_factor"] = rf
        if agreed is not None:  # engine against engine, apart from the model's comparison
            doc["consensus"] = agreed
        print_json(plain(doc))
        return 0
    if rf != 1.0:
        from trilith_xval.compare.cli.model_options import restitution_text
        print(f"model: {restitution_text(rf, scene.has_pendulum)}")
    for m in maps:
        print_map_summary(m, f"scene {scene.name}, {m.pulse} pulse, {m.omega.size} "
                             f"frequencies x {m.amplitude.size} amplitudes")
    for name, pts in thresholds.items():
        _print_thresholds(name, pts)
    if agreed is not None:
        from trilith_xval.compare.cli.spectrum_engines import print_consensus
        print_consensus(agreed)
    bad = [float(w) for w, v in zip(maps[0].omega, validity) if v["model_valid"] is False]
    if bad:
        print(f"note: the model is invalid at the first overturning for {len(bad)} "
              f"frequencies (Omega {min(bad):g} to {max(bad):g} rad/s; hatched in --plot)")
    first = maps[0].first
    n_miss = int(sum(1 for a in first if not math.isfinite(a)))
    if n_miss:
        print(f"note: {n_miss} frequencies do not overturn up to the grid's top amplitude")
    return 0
