"""``trilith spectrum --consensus`` on a scene the model does not cover
(:mod:`analytic.kinds`: drums, unequal columns, a block on a block).

There is no model spectrum to bisect around, so each frequency is answered by the
engines alone (:mod:`compare.measure.consensus`): each engine's own first-failure
amplitude (an overturn or a collapse, :mod:`engines.structure_monitor`),
converged in the step, and their consensus.  The consensus search starts from a
guess; without a model the guess is a scan: the first engine's verdicts at
amplitudes growing by :data:`SCAN_FACTOR` from the structure's static uplift
bound ``g w_min / (2 H)`` (:func:`~compare.measure.consensus.uplift_bound`), the
geometric mean of the last survival and the first failure
(:func:`compare.measure.consensus.scan`, shared with ``trilith fragility``).
"""
from __future__ import annotations

from trilith_xval.compare.cli.options import envelope, info, print_json
from trilith_xval.compare.measure.consensus import SCAN_FACTOR, SCAN_STEPS, scan, uplift_bound

__all__ = ["kind_spectrum", "scan_guess", "uplift_bound", "SCAN_FACTOR", "SCAN_STEPS"]


def scan_guess(spec, omega: float, kind) -> tuple[float | None, int]:
    """``(guess [m/s^2] or None, runs)``: the scan (:func:`compare.measure.consensus.scan`)
    of ``spec``'s engine from the uplift bound at ``omega`` (module docstring)."""
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.thresholds import overturns

    def fails(a: float) -> bool:
        run = point_spec(spec, spec.scene, omega, a, kind)
        p = overturns(run.backend, run.scene, omega, a, run.settings, kind)
        return p.status in ("overturned", "collapsed")
    return scan(fails, uplift_bound(spec.scene))


def kind_spectrum(args, scene, parse_omega_range, settings_from_args) -> int:
    """The command for a scene of another kind (module docstring)."""
    from trilith_xval.compare.cli.pulse_shape import shape_from_args
    from trilith_xval.compare.cli.spectrum_engines import check_engine_budget, engine_runs
    from trilith_xval.compare.cli.options import parse_engine_list, use_store
    from trilith_xval.compare.measure.consensus import consensus_at
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES

    kind = scene.kind
    if not args.consensus:
        raise ValueError(f"trilith spectrum: there is no model spectrum of the {kind} kind "
                         f"(scene {scene.name!r}); give --consensus E1,E2 (the engines against "
                         f"each other: {', '.join(STRUCTURE_ENGINES)})")
    given = [f"--{n.replace('_', '-')}" for n in ("record", "csv", "plot", "tol", "scan_step")
             if getattr(args, n, None) is not None]
    given += ["--convergence"] if args.convergence else []
    if given:
        raise ValueError(f"trilith spectrum --consensus on the {kind} kind: "
                         f"{', '.join(given)} do not apply (no model spectrum)")
    if isinstance(args.consensus, str):
        if args.engine.strip() != "analytic":
            raise ValueError("give the engines once: --engine E1,E2 --consensus, or "
                             "--consensus E1,E2")
        names = parse_engine_list(args.consensus, "--consensus")
    else:
        names = parse_engine_list(args.engine)
    if len(names) < 2:
        raise ValueError(f"--consensus compares engines with each other: give two or more, "
                         f"got {', '.join(names) or 'none'}")
    for name in names:
        if name not in STRUCTURE_ENGINES:
            raise ValueError(f"trilith spectrum: {name} runs the parametric trilith only, not "
                             f"the {kind} kind (engines that run it: "
                             f"{', '.join(STRUCTURE_ENGINES)})")
    omegas = parse_omega_range(args.omega, "--omega")
    shape = shape_from_args(args)
    loaded = settings_from_args(args, names)
    runs = engine_runs(args, scene, names, loaded)
    if args.criterion != "topple":
        runs = {n: r.with_options("--criterion", criterion=args.criterion)
                for n, r in runs.items()}
    check_engine_budget(args, runs, omegas, shape)
    use_store(args)
    first = next(iter(runs.values()))
    points, n_scan = [], 0
    for omega in omegas:
        guess, n = scan_guess(first, float(omega), shape)
        n_scan += n
        if guess is None:
            points.append({"omega": float(omega), "status": "none", "median": None,
                           "a_guess": None, "engines": {}, "outliers": [], "no_answer": [
                               {"engine": e, "cause": "no failure",
                                "detail": "no failure up to the scan's end"} for e in names]})
            continue
        point = consensus_at(runs, scene, float(omega), guess, shape)
        point["a_guess"] = point.pop("a_model")  # a scan's guess, not a model's number
        points.append(point)
    if args.json:
        inputs = {"scene": scene.to_dict(), "omega": args.omega, "pulse": shape,
                  "criterion": args.criterion, "t_max": args.t_max, "consensus": list(names)}
        body = {"kind": kind, "model": None, "points": points, "scan_runs": n_scan}
        print_json(envelope("spectrum", inputs, body, {}))
        return 0
    print(f"scene {scene.name} ({kind}): no model; each engine's own first failure "
          f"(overturn or collapse), converged in the step, and their consensus; {shape} pulse, "
          f"criterion {args.criterion}")
    head = "".join(f" {e + ' [m/s^2]':>18}" for e in names)
    print(f"{'Omega [rad/s]':>13}{head} {'median':>9} {'status':>10}  failure")
    for p in points:
        cells = []
        for e in names:
            row = p["engines"].get(e)
            cells.append(f" {row['a_fails']:18.4g}" if row else f" {'-':>18}")
        median = f"{p['median']:9.4g}" if p["median"] is not None else f"{'-':>9}"
        print(f"{p['omega']:13.4g}{''.join(cells)} {median} {p['status']:>10}  "
              f"{p.get('failure') or '-'}")
        for miss in p["no_answer"]:
            info(f"  Omega {p['omega']:g}: {miss['engine']} has no answer ({miss['cause']}: "
                 f"{miss['detail']})")
        for out in p["outliers"]:
            info(f"  Omega {p['omega']:g}: {out['engine']} is an outlier "
                 f"({100 * out['deviation']:+.2g} %, cause {out['cause']})")
    info("engine against engine, never agreement with a model (docs/geometry.md)")
    return 0
