"""``trilith spectrum --consensus`` on a scene the model does not cover
(:mod:`analytic.kinds`: drums, unequal columns, a block on a block).

There is no model spectrum to bisect around, so each frequency is answered by the
engines alone (:mod:`compare.measure.consensus`): each engine's own first-failure
amplitude (an overturn or a collapse, :mod:`engines.structure_monitor`),
converged in the step, and their consensus.  The consensus search starts from a
guess; without a model the guess is a scan: the first engine's verdicts at
amplitudes growing by :data:`SCAN_FACTOR` from the structure's static uplift
bound ``g w_min / (2 H)`` (:func:`uplift_bound`), the geometric mean of
the last survival and the first failure.
"""
from __future__ import annotations

import math

from trilith_xval.compare.cli.options import envelope, info, print_json

__all__ = ["kind_spectrum", "kind_points", "scan_guess", "SCAN_FACTOR", "SCAN_STEPS"]

# Amplitude ratio of two scan probes: the threshold search then widens its bracket
# up to +-115 % around the guess (compare.measure.thresholds.Search.max_expand), so a
# scan bracket of 1.5 is well inside what it can reach.
SCAN_FACTOR = 1.5
# Probes of the scan: 1.5^14 ~ 290 times the uplift bound, past any one-sine
# threshold of a standing structure (Fig. 5's highest is ~40 times g/lam).
SCAN_STEPS = 14


def uplift_bound(scene) -> float:
    """``g w_min / (2 H)`` [m/s^2], ``w_min`` the narrowest body's width and ``H`` the
    structure's height: below the static uplift of any rigid part of it (about any
    corner its lever to its centre of mass is at least ``w_min / 2`` for centred
    bodies, the centre at most ``H`` above the pivot), so the scan starts below
    the first failure."""
    rects = scene.layout()
    top = max(r.top for r in rects)
    return 0.5 * scene.g * min(r.b for r in rects) / top


def scan_guess(spec, omega: float, kind) -> tuple[float | None, int]:
    """``(guess [m/s^2] or None, runs)``: the geometric mean of the last surviving and
    the first failing amplitude of the scan (module docstring) on ``spec``'s engine."""
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.thresholds import overturns
    a, survived = uplift_bound(spec.scene), None
    for k in range(SCAN_STEPS):
        run = point_spec(spec, spec.scene, omega, a, kind)
        p = overturns(run.backend, run.scene, omega, a, run.settings, kind)
        if p.status in ("overturned", "collapsed"):
            low = survived if survived is not None else a / SCAN_FACTOR
            return math.sqrt(low * a), k + 1
        survived = a
        a *= SCAN_FACTOR
    return None, SCAN_STEPS


def kind_points(runs: dict, scene, omegas, shape) -> tuple[list[dict], int]:
    """``(points, scan runs)``: at each of ``omegas`` [rad/s] the engines' consensus
    (:func:`compare.measure.consensus.consensus_at`, ``runs``: engine -> its
    threshold-search RunSpec) started from the scan of the first engine
    (:func:`scan_guess`); a frequency where the scan finds no failure has status
    ``'none'`` and every engine under ``no_answer``."""
    from trilith_xval.compare.measure.consensus import consensus_at
    first = next(iter(runs.values()))
    points, n_scan = [], 0
    for omega in omegas:
        guess, n = scan_guess(first, float(omega), shape)
        n_scan += n
        if guess is None:
            points.append({"omega": float(omega), "status": "none", "median": None,
                           "a_guess": None, "engines": {}, "outliers": [], "no_answer": [
                               {"engine": e, "cause": "no failure",
                                "detail": "no failure up to the scan's end"} for e in runs]})
            continue
        point = consensus_at(runs, scene, float(omega), guess, shape)
        point["a_guess"] = point.pop("a_model")  # a scan's guess, not a model's number
        points.append(point)
    return points, n_scan


def kind_spectrum(args, scene, parse_omega_range, settings_from_args) -> int:
    """The command for a scene of another kind (module docstring)."""
    from trilith_xval.compare.cli.pulse_shape import shape_from_args
    from trilith_xval.compare.cli.spectrum_engines import check_engine_budget, engine_runs
    from trilith_xval.compare.cli.options import parse_engine_list, use_store
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
    points, n_scan = kind_points(runs, scene, omegas, shape)
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
