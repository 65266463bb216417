"""``trilith spectrum``: overturning spectra with and without the pendulum (Fig. 5)."""
from __future__ import annotations

import argparse
import math
import sys

from trilith_xval.analytic.options import MAX_ENGINE_DT
from trilith_xval.engines import engine_names

from trilith_xval.compare.cli import options as _common
from trilith_xval.compare.cli.fragility import add_ida_args, record_spectrum
from trilith_xval.compare.cli.options import (PLOT_SUFFIXES, add_pulse_kind_arg, add_scene_args, add_store_args,
                                 add_workers_arg, check_output_path, parse_engine_list, envelope,
                                 info, parse_omega_range, print_json,
                                 resolve_workers, scene_from_args, settings_from_args,
                                 use_store)
from trilith_xval.compare.cli.spectrum_engines import (check_engine_budget, engine_runs,
                                                       run_engines)
from trilith_xval.compare.cli.model_options import (add_restitution_arg, restitution_factor,
                                                    restitution_text)
from trilith_xval.compare.report.spectrum_plot import plot_spectrum
from trilith_xval.compare.run.jsonable import plain

DEFAULT_OMEGA = "3:30:1"  # the range of the paper's Fig. 5
ENGINE = "analytic-fast"  # the spectra's backend (compiled model, same verdicts)


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "spectrum",
        help="overturning spectrum: first overturning amplitude per frequency, with and "
             "without pendulum, and the gain Delta (Fig. 5)",
        description="For each pulse frequency, raise the amplitude from the uplift "
                    "acceleration until the first overturning, then bisect to --tol. Both "
                    "curves (with and without the pendulum), the gain "
                    "Delta = 100 (A_yp - A_np)/A_np and the overturning modes.")
    add_scene_args(parser)
    add_pulse_kind_arg(parser)
    parser.add_argument("--omega", default=DEFAULT_OMEGA, metavar="START:STOP:STEP",
                        help="frequencies [rad/s] in [0.1, 1e4], STOP included, or a comma "
                             "list; at most 100000")
    parser.add_argument("--tol", type=float, default=None, metavar="A",
                        help="bisection resolution of the amplitude [m/s^2], in (1e-6, 10] "
                             "(default: 0.01)")
    parser.add_argument("--scan-step", type=float, default=None, metavar="A",
                        help="scan step floor [m/s^2], in (1e-4, 100]; windows narrower than "
                             "the step can be missed (default: 0.1)")
    add_workers_arg(parser)
    parser.add_argument("--criterion", choices=("topple", "alpha"), default="topple",
                        help="overturned at |theta| = 1.5 rad (topple) or at alpha")
    parser.add_argument("--t-max", type=float, default=None, metavar="S",
                        help="fixed run length [s] (default: exact survival rules)")
    add_restitution_arg(parser)
    parser.add_argument("--engine", default="analytic", metavar="NAME[,NAME...]",
                        help="analytic (the model's spectrum), or engines to bisect on the same "
                             f"grid around it: {', '.join(engine_names())}, or all")
    parser.add_argument("--dt", type=float, default=None, metavar="S",
                        help=f"engine time step [s], in (0, {MAX_ENGINE_DT:g}] (default: each "
                             "engine's calibrated step)")
    _common.add_settings_arg(parser)
    parser.add_argument("--convergence", action="store_true",
                        help="rerun disagreeing engine points at dt/2, dt/4 and doubled "
                             "solver iterations to classify the cause")
    parser.add_argument("--consensus", nargs="?", const=True, default=False,
                        metavar="E1,E2",
                        help="where the model cannot judge an engine point (cause 'model'), "
                             "the engines against each other: each one's own first failure, "
                             "converged in the step, their median and outliers (two engines "
                             "or more, from --engine or given here; docs/atlas.md); on a "
                             "scene the model does not cover (drums, unequal, block_on_block) "
                             "the engines' answer at every --omega (docs/geometry.md)")
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    parser.add_argument("--csv", metavar="FILE", help="write the spectrum as CSV")
    parser.add_argument("--plot", metavar="FILE.png", help="write a Fig. 5-style plot")
    parser.add_argument("--record", metavar="FILE", default=None,
                        help="a recorded ground motion (CSV or PEER .AT2) instead of pulses: "
                             "its first overturning intensity by incremental dynamic "
                             "analysis (--im, --im-range, ...; see 'trilith fragility')")
    scale = parser.add_mutually_exclusive_group()
    scale.add_argument("--scale", default=None, metavar="F", help="multiply the record by F")
    scale.add_argument("--pga", default=None, metavar="A", help=argparse.SUPPRESS)
    scale.add_argument("--pgv", default=None, metavar="V", help=argparse.SUPPRESS)
    add_ida_args(parser)
    add_store_args(parser, scheduler=True)
    return parser


def _cached_frequency(payload):
    """One frequency (both curves) through the run store: the key is the scene,
    the search settings (pulse kind included) and Omega."""
    from trilith_xval.compare.run import runs
    fn, description, omega = payload
    return runs.memo("spectrum-point", {**description, "omega": omega}, lambda: fn(omega))


def _stored_frequency(payload):
    """The stored result of :func:`_cached_frequency`, or None (looked up in this
    process: a warm rerun starts no pool and loads no kernel)."""
    from trilith_xval.compare.run import runs
    _fn, description, omega = payload
    return runs.lookup("spectrum-point", {**description, "omega": omega})


def _map_fn(scene, settings, workers: int, scheduler: str | None):
    """``map_fn`` for :func:`analytic.spectrum.overturning_spectrum`: each frequency
    through the store, on local processes or the ``--scheduler`` cluster.

    Locally, what the store holds is read here; of the rest, the highest
    frequency is computed here first (after the kernels are loaded, so forked
    workers inherit them) and its CPU time decides how many workers the others
    are worth (:func:`analytic._workers.pool_size`)."""
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict

    description = {"scene": scene_dict(scene), "settings": settings.describe()}

    def map_fn(fn, omegas):
        payloads = [(fn, description, w) for w in omegas]
        if scheduler is not None:
            yield from runs.run_many(_cached_frequency, payloads, workers=workers,
                                     lookup=_stored_frequency)
            return
        yield from _local_map(payloads, workers)
    return map_fn


def _local_map(payloads, workers: int):
    """:func:`_cached_frequency` of every payload, yielded in order (see :func:`_map_fn`)."""
    import time

    from trilith_xval.analytic._workers import pool_size
    from trilith_xval.compare.run import runs

    found = [_stored_frequency(p) for p in payloads]
    todo = [i for i, f in enumerate(found) if f is None]
    computed = iter(())
    if todo:  # (only then numba: a rerun the store serves whole never loads it)
        from trilith_xval.analytic import fast
        fast.warm_up(record=False)
        first = max(todo, key=lambda i: payloads[i][2])
        t0 = time.process_time()
        found[first] = _cached_frequency(payloads[first])
        cost = time.process_time() - t0
        rest = [payloads[i] for i in todo if i != first]
        computed = runs.run_many(_cached_frequency, rest,
                                 workers=pool_size(len(rest), cost, workers))
    for value in found:
        yield next(computed) if value is None else value


def _settings(args: argparse.Namespace):
    from trilith_xval.analytic.spectrum import SpectrumSettings, search_run_settings
    from trilith_xval.analytic.trajectory import OverturnCriterion

    if args.t_max is not None and not (math.isfinite(args.t_max) and 0 < args.t_max <= 1e5):
        raise ValueError(f"--t-max must be a time in (0, 1e5] s, got {args.t_max!r}")
    if args.tol is not None and not (math.isfinite(args.tol) and 1e-6 < args.tol <= 10):
        raise ValueError(f"--tol must be in (1e-06, 10] m/s^2, got {args.tol!r}")
    if args.scan_step is not None and not (math.isfinite(args.scan_step)
                                           and 1e-4 < args.scan_step <= 100):
        raise ValueError(f"--scan-step must be in (0.0001, 100] m/s^2, got {args.scan_step!r}")
    from trilith_xval.compare.cli.pulse_shape import shape_from_args
    fast = search_run_settings(criterion=OverturnCriterion(args.criterion), t_max=args.t_max,
                               restitution_factor=restitution_factor(args))
    kw = {"pulse": shape_from_args(args), "fast": fast}
    if args.tol is not None:
        kw["tol"] = args.tol
    if args.scan_step is not None:
        kw["scan_step"] = args.scan_step
    if kw.get("tol", 0.01) > kw.get("scan_step", SpectrumSettings.scan_step):
        raise ValueError("--tol must not exceed --scan-step")
    return SpectrumSettings(**kw)


def _valid_text(validity: dict, i: int, curves=("no_pendulum", "pendulum")) -> str:
    """'yes', 'no' (every curve), 'no (np)' / 'no (yp)' (one of two), '-' (unchecked)."""
    v = {c: validity[c][i]["model_valid"] for c in curves}
    if None in v.values():
        return "-"
    bad = [short for c, short in (("no_pendulum", "np"), ("pendulum", "yp"))
           if c in curves and not v[c]]
    return "yes" if not bad else ("no" if len(bad) == len(curves) else f"no ({bad[0]})")


def _number(value: float, width: int) -> str:
    return f"{value:{width}.4g}" if math.isfinite(value) else f"{'nan':>{width}}"


def run(args: argparse.Namespace) -> int:
    from trilith_xval.analytic.fast_settings import version
    from trilith_xval.analytic.spectrum import overturning_spectrum
    from trilith_xval.compare.run import atomic

    scene = scene_from_args(args)
    if getattr(scene, "kind", "trilith") != "trilith":  # no model: the engines' consensus
        from trilith_xval.compare.cli.spectrum_kinds import kind_spectrum
        return kind_spectrum(args, scene, parse_omega_range, settings_from_args)
    if args.record is not None:
        if restitution_factor(args) != 1.0:  # the record search runs the exact model
            raise ValueError("--restitution-factor is not supported with --record yet "
                             "(the record's intensity search runs the exact impact)")
        return _record_spectrum(args, scene)
    omegas = parse_omega_range(args.omega, "--omega")
    settings = _settings(args)
    workers = resolve_workers(args.workers)
    if args.csv is not None:
        check_output_path(args.csv, "--csv")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", suffixes=PLOT_SUFFIXES)
    # A bar only for a person watching (TTY); it shows up after 1 s of work.
    progress = (not args.json) and sys.stdout.isatty() and _common.VERBOSITY >= 0
    engines_wanted = _engines(args)
    loaded = settings_from_args(args, engines_wanted)
    if args.consensus and len(engines_wanted) < 2:
        raise ValueError(f"--consensus compares engines with each other: give --engine with "
                         f"two or more, got {', '.join(engines_wanted) or 'none'}")
    runs = engine_runs(args, scene, engines_wanted, loaded)
    check_engine_budget(args, runs, omegas, settings.pulse)
    use_store(args)
    spec = overturning_spectrum(scene, omegas, settings, progress=progress,
                                map_fn=_map_fn(scene, settings, workers, args.scheduler))
    if engines_wanted:
        return run_engines(args, scene, spec, runs, workers, loaded)
    from trilith_xval.analytic.threshold_validity import spectrum_validity
    validity = spectrum_validity(spec, workers=workers)
    if args.csv is not None:
        with atomic.atomic_path(args.csv) as tmp:
            spec.to_csv(tmp, validity)
    if args.plot is not None:
        plot_spectrum(spec, args.plot, validity)
    if args.json:
        body = {**spec.to_dict(), "model_validity": validity}
        timings = {"wall_time": body.pop("wall_time"), "workers": workers}
        inputs = {"scene": scene.to_dict(), "omega": args.omega, "pulse": settings.pulse,
                  "criterion": args.criterion, "t_max": args.t_max, "tol": args.tol,
                  "scan_step": args.scan_step, "engine": ENGINE}
        if settings.fast.restitution_factor != 1.0:  # absent at 1, as in the run keys
            inputs["restitution_factor"] = settings.fast.restitution_factor
        body = {"engine": ENGINE, "engine_version": version(), **body}
        print_json(plain(envelope("spectrum", inputs, body, timings)))
        return 0
    print(f"scene {scene.name}: lam = {scene.lam:.4g}, b = {scene.b:.4g} m, mu = {scene.mu:.4g}, "
          f"gamma = {scene.gamma:.4g}; {settings.pulse} pulse; criterion "
          f"{settings.criterion.kind}, t_max = {settings.t_max}, tol = {settings.tol:g} m/s^2, "
          f"scan step max({settings.scan_step:g} m/s^2, {100 * settings.scan_rel_step:g} % A)"
          + (f"; {restitution_text(settings.fast.restitution_factor, scene.has_pendulum)}"
             if settings.fast.restitution_factor != 1.0 else ""))
    both = len(spec.curves) == 2  # without a pendulum: one curve, no gain
    print(f"{'Omega [rad/s]':>13} {'A_np [m/s^2]':>12} {'mode_np':>13}"
          + (f" {'A_yp [m/s^2]':>12} {'mode_yp':>13} {'Delta [%]':>9}" if both else "")
          + "  model valid")
    gain = spec.gain_percent
    for i, w in enumerate(spec.omega):
        print(f"{w:13.4g} {_number(spec.a_no_pendulum[i], 12)} "
              f"{spec.mode_no_pendulum[i] or '-':>13}"
              + (f" {_number(spec.a_pendulum[i], 12)} {spec.mode_pendulum[i] or '-':>13} "
                 f"{_number(gain[i], 9)}" if both else "")
              + f"  {_valid_text(validity, i, spec.curves)}")
    for jump in spec.mode_jumps():
        where = f" ({jump['curve'].replace('_', ' ')})" if both else ""
        print(f"mode jump{where}: {jump['mode_before']} at Omega = "
              f"{jump['omega_before']:g} rad/s -> {jump['mode_after']} at "
              f"{jump['omega_after']:g} rad/s")
    invalid = [float(w) for i, w in enumerate(spec.omega)
               if _valid_text(validity, i, spec.curves) not in ("yes", "-")]
    if invalid:
        why = "a contact would pull or the bob meets a column" if both else \
            "a contact would pull"
        info(f"warning: the model is invalid on the threshold run at {len(invalid)} "
             f"frequencies (Omega {min(invalid):g} to {max(invalid):g} rad/s): {why}; "
             f"those thresholds are the model's, not a trilith's (model_reason in "
             f"--json/--csv)")
    missing = int(sum(1 for a in list(spec.a_no_pendulum) + list(spec.a_pendulum) * both
                      if not math.isfinite(a)))
    if missing:
        info(f"warning: {missing} point(s) did not overturn up to a_max = "
             f"{settings.a_max:g} m/s^2 (shown as nan)")
    if spec.n_undecided:
        info(f"warning: {spec.n_undecided} run(s) undecided (counted as not overturned)")
    info(f"{spec.n_runs} runs in {spec.wall_time:.2f} s on {workers} worker(s)")
    if args.csv is not None:
        info(f"wrote {args.csv}")
    if args.plot is not None:
        info(f"wrote {args.plot}")
    return 0


def _record_spectrum(args: argparse.Namespace, scene) -> int:
    """``--record``: the pulse options do not apply; the engines are those asked for."""
    given = [f"--{n.replace('_', '-')}" for n in ("tol", "scan_step", "dt", "t_max", "csv", "plot")
             if getattr(args, n) is not None]
    if args.omega != DEFAULT_OMEGA:
        given.insert(0, "--omega")
    given[:0] = [f for f, v in (("--pulse", None if args.pulse == "sine" else args.pulse),
                                ("--mp-gamma", args.mp_gamma), ("--mp-nu", args.mp_nu))
                 if v is not None]
    if given or args.convergence:
        raise ValueError(f"--record searches the record's intensity: drop "
                         f"{' and '.join(given) or '--convergence'}")
    backends = ("analytic",) + (() if args.engine.strip() == "analytic" else _engines(args))
    return record_spectrum(args, scene, backends, resolve_workers(args.workers))


def _engines(args: argparse.Namespace) -> tuple[str, ...]:
    """The engines asked for (empty for the analytic spectrum); checked up front;
    ``--consensus E1,E2`` names them as ``--engine E1,E2 --consensus`` does."""
    if isinstance(args.consensus, str):
        if args.engine.strip() != "analytic":
            raise ValueError("give the engines once: --engine E1,E2 --consensus, or "
                             "--consensus E1,E2")
        args.engine = args.consensus
    if args.engine.strip() == "analytic":
        if args.dt is not None or args.convergence:
            raise ValueError("--dt and --convergence need --engine NAME (an engine)")
        return ()
    names = parse_engine_list(args.engine)
    if args.dt is not None and not (math.isfinite(args.dt) and 0.0 < args.dt <= MAX_ENGINE_DT):
        raise ValueError(f"--dt must be in (0, {MAX_ENGINE_DT:g}] s, got {args.dt!r}")
    return names
