"""``trilith spectrum --consensus`` on a scene the model does not cover
(:mod:`analytic.kinds`: drums, unequal columns, a block on a block): each
frequency answered by the engines alone, started from a scan
(:mod:`compare.measure.kind_scan`).
"""
from __future__ import annotations

from trilith_xval.compare.cli.options import envelope, info, print_json

__all__ = ["kind_spectrum", "print_consensus_table"]


def kind_spectrum(args, scene, parse_omega_range, settings_from_args) -> int:
    """The command for a scene of another kind (module docstring)."""
    from trilith_xval.compare.cli.pulse_shape import shape_from_args
    from trilith_xval.compare.cli.spectrum_engines import check_engine_budget, engine_runs
    from trilith_xval.compare.cli.options import (check_structure_engines, parse_engine_list,
                                                  use_store)
    from trilith_xval.compare.measure.kind_scan import kind_point
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
    check_structure_engines(names, kind, "spectrum")
    omegas = parse_omega_range(args.omega, "--omega")
    shape = shape_from_args(args)
    loaded = settings_from_args(args, names)
    runs = engine_runs(args, scene, names, loaded)
    if args.criterion != "topple":
        runs = {n: r.with_options("--criterion", criterion=args.criterion)
                for n, r in runs.items()}
    check_engine_budget(args, runs, omegas, shape)
    use_store(args)
    points, n_scan = [], 0
    for omega in omegas:
        point, n = kind_point(runs, scene, float(omega), shape)
        n_scan += n
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
    print_consensus_table(points, names, ("Omega [rad/s]", 13), "m/s^2",
                          lambda p: f"{p['omega']:13.4g}", lambda p: f"Omega {p['omega']:g}")
    info("engine against engine, never agreement with a model (docs/geometry.md)")
    return 0


def print_consensus_table(points, names, head: tuple[str, int], unit: str, label, where,
                          col: int = 18) -> None:
    """One row per consensus point (:func:`compare.measure.consensus.consensus`): its
    ``label(point)`` under ``head`` (title, width), each engine's own first failure
    [``unit``] in a column ``col`` wide, the median, the status and the failure; then
    on stderr each engine without an answer and each outlier, prefixed ``where(point)``."""
    title, width = head
    print(f"{title:>{width}}" + "".join(f" {e + ' [' + unit + ']':>{col}}" for e in names)
          + f" {'median':>9} {'status':>10}  failure")
    for p in points:
        cells = "".join(f" {p['engines'][e]['a_fails']:{col}.4g}" if e in p["engines"]
                        else f" {'-':>{col}}" for e in names)
        median = f"{p['median']:9.4g}" if p["median"] is not None else f"{'-':>9}"
        print(f"{label(p)}{cells} {median} {p['status']:>10}  {p.get('failure') or '-'}")
        for miss in p["no_answer"]:
            info(f"  {where(p)}: {miss['engine']} has no answer ({miss['cause']}: "
                 f"{miss['detail']})")
        for out in p["outliers"]:
            info(f"  {where(p)}: {out['engine']} is an outlier "
                 f"({100 * out['deviation']:+.2g} %, cause {out['cause']})")
