"""``trilith spectrum --engine``: each engine's threshold searches on the model's
grid, from its run resolved once (:class:`compare.run.spec.RunSpec`), and, with
``--consensus``, the engines against each other where the model is invalid
(:mod:`compare.measure.consensus`)."""
from __future__ import annotations

from trilith_xval.compare.cli.options import envelope, print_json, settings_line
from trilith_xval.compare.cli.model_options import restitution_text

__all__ = ["engine_runs", "check_engine_budget", "run_engines",
           "consensus_where_model_cannot_judge", "print_consensus"]


def engine_runs(args, scene, names, loaded=None) -> dict:
    """Each engine's threshold-search run on ``scene``, resolved once before any
    work (:class:`compare.run.spec.RunSpec`): its calibrated threshold settings
    where the scene is in their domain, else its reference ones, the ``--settings``
    table over them, ``--dt``/``--t-max`` over both; one note per engine whose
    calibration does not hold here."""
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.cli.options import run_spec, step_notes
    options = {} if args.dt is None else {"dt": args.dt}
    if args.t_max is not None:  # the model's window, fixed, in every engine run
        options.update(t_max=args.t_max, early_stop=False)
    if args.dt is None and names:
        step_notes(names, [scene, scene.without_pendulum()] if scene.has_pendulum else [scene])
    return {name: run_spec(name, scene, Still(), loaded, calibrated=True, overrides=options)
            for name in names}


def check_engine_budget(args, runs: dict, omegas, shape) -> None:
    """Refuse before any work an engine run over the run budget: the longest is at
    the lowest Omega, at the finest step a search may take (the step rule goes
    down to the engine's reference step; ``--convergence`` reruns at dt/4)."""
    import dataclasses

    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.engines.calibration import reference_dt

    from trilith_xval.compare.cli.excitation_args import check_run_budget

    for name, run in runs.items():
        dt = min(run.settings.dt, reference_dt(name))
        finest = dt / 4 if args.convergence else dt
        origin = dict(run.origin).get("dt", f"{name}'s reference step")
        option = "--dt" if origin == "the command line" else origin
        option += " (with --convergence: dt/4)" if args.convergence else ""
        check_run_budget(name, dataclasses.replace(run.settings, dt=finest),
                         pulse_of(shape, 1.0, float(min(omegas))), option=option)


def run_engines(args, scene, spec, runs: dict, workers: int, loaded=None) -> int:
    """Each engine's spectrum on the model's grid ``spec``, from its resolved run
    (:func:`engine_runs`)."""
    from pathlib import Path

    from trilith_xval.compare.run import atomic
    from trilith_xval.compare.measure import engine_spectrum as es
    from trilith_xval.compare.measure import engine_spectrum_files as files

    import os
    import time

    names = tuple(runs)
    results, walls = [], {}
    for name, run in runs.items():
        t0 = time.perf_counter()
        results.append(es.engine_spectrum(run, spec, kind=spec.settings.pulse,
                                          workers=workers, convergence=args.convergence))
        walls[name] = time.perf_counter() - t0
    agreed = _consensus(scene, runs, results, spec.settings.pulse) if args.consensus else None
    if args.csv:
        with atomic.atomic_path(args.csv) as tmp:
            files.write_csv(results, tmp)
    if args.plot:
        with atomic.atomic_path(args.plot, Path(args.plot).suffix) as tmp:
            files.plot(spec, results, tmp)
    if args.json:
        from trilith_xval.analytic.fast_settings import version
        analytic = spec.to_dict()
        timings = {"wall_time": analytic.pop("wall_time"), "engine_wall_time": walls,
                   "engine_cpu_s": {r.engine: r.cost() for r in results},
                   "load_average": list(os.getloadavg()), "workers": workers}
        inputs = {"scene": scene.to_dict(), "omega": args.omega, "pulse": spec.settings.pulse,
                  "criterion": args.criterion, "t_max": args.t_max, "tol": args.tol,
                  "scan_step": args.scan_step, "engine": list(names), "dt": args.dt,
                  "convergence": args.convergence,
                  "settings_file": None if loaded is None else loaded.describe()}
        if spec.settings.fast.restitution_factor != 1.0:  # the engines' target: the scaled model
            inputs["restitution_factor"] = spec.settings.fast.restitution_factor
        body = {"engine": list(names),
                "engine_version": {"analytic": version(), **{r.engine: r.version for r in results}},
                "analytic": analytic, "engines": {r.engine: r.to_dict() for r in results}}
        if agreed is not None:  # engine against engine, apart from the model's comparison
            body["consensus"] = agreed
        print_json(envelope("spectrum", inputs, body, timings))
        return 0
    rf = spec.settings.fast.restitution_factor
    if rf != 1.0:  # the engines' target is the scaled model, not the exact impact
        print(f"A_model: the model with {restitution_text(rf, scene.has_pendulum)}")
    for r in results:
        cost = r.cost()
        if loaded is not None:
            print(settings_line(loaded, r.engine))
        print(f"{r.engine} ({r.version}), dt = {r.settings['dt']:g} s, robust bracket "
              f"{100 * r.rel_tol:g} % of A, tolerance {100 * r.tol:g} %; {cost['runs']} runs, "
              f"{cost['cpu_s']:.1f} CPU s when computed ({cost['cpu_s_spent']:.1f} spent now, "
              f"{cost['points_from_store']} of {cost['points']} points from the run store)")
        print(f"{'curve':>11} {'Omega':>6} {'A_model':>8} {'A_engine':>8} {'error':>7}  cause")
        for curve, points in r.curves.items():
            for p in points:
                iso = f" [{len(p.isolated)} isolated]" if p.isolated else ""
                print(f"{curve:>11} {p.omega:6.3g} {p.a_reference:8.3f} {p.a_engine:8.3f} "
                      f"{100 * p.rel_error:+6.2f}%  {p.cause}{iso}"
                      + ("" if p.cause == "agrees" else f": {p.cause_detail}"))
    if agreed is not None:
        print_consensus(agreed)
    return 0


def _consensus(scene, runs: dict, results, kind) -> list[dict]:
    return consensus_where_model_cannot_judge(
        scene, runs, [(c, pts) for r in results for c, pts in r.curves.items()], kind)


def consensus_where_model_cannot_judge(scene, runs: dict, curves, kind) -> list[dict]:
    """The engines' consensus (:func:`compare.measure.consensus.consensus_at`) at
    every point of ``curves`` (pairs ``(curve, engine points)``) where the model
    cannot judge an engine, with a progress line per tenth."""
    from trilith_xval.compare.measure.consensus import consensus_at, where_model_cannot_judge
    from trilith_xval.compare.run.progress import bar
    points = where_model_cannot_judge(curves)
    progress = bar(len(points), "consensus", "points")
    out = []
    try:
        for curve, omega, a_model in points:
            sc = scene if curve == "pendulum" else scene.without_pendulum()
            out.append({"curve": curve, **consensus_at(runs, sc, omega, a_model, kind)})
            progress.update(1)
    finally:
        progress.close()
    return out


def print_consensus(agreed: list[dict]) -> None:
    print(f"where the model cannot judge ({len(agreed)} points): engine against engine, "
          "each one's own first failure converged in the step")
    print(f"{'curve':>11} {'Omega':>6} {'A_model':>8} {'median':>8}  status; each engine")
    for c in agreed:
        each = ", ".join(f"{e} {100 * v['deviation']:+.2f}%" for e, v in c["engines"].items())
        odd = "".join(f"; outlier {o['engine']} ({o['cause']})" for o in c["outliers"])
        none = "".join(f"; {n['engine']}: no answer ({n['cause']})" for n in c["no_answer"])
        median = "-" if c["median"] is None else f"{c['median']:8.3f}"
        print(f"{c['curve']:>11} {c['omega']:6.3g} {c['a_model']:8.3f} {median:>8}  "
              f"{c['status']} ({c['failure'] or '-'}); {each or '-'}{odd}{none}")
