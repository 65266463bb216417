"""Work-precision benchmarks: run time against error for every backend.

``make bench`` (via ``benchmarks/run.py``) and ``trilith bench [--quick] [--out DIR]``
call :func:`main`.  It measures

* the analytic accurate path (scipy DOP853) and the compiled fast path across
  their tolerances (:mod:`benchmarks.workprecision_analytic`);
* PyBullet and Pymunk across the time step and their main solver settings
  (:mod:`benchmarks.workprecision_engines`);

marks each backend's Pareto front and its default settings, and writes to
``benchmarks/out/`` (or ``--out``): ``workprecision.json`` (every point, the
machine, versions, date), ``workprecision_<metric>.png`` (log-log plots) and
``workprecision.md`` (the tables that ``docs/benchmarks.md`` quotes).

Full run: ~10 min on 2 cores; ``--quick``: < 2 min (fewer tolerances, two time
steps, no solver sweeps, coarser threshold bisection).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from trilith_xval.compare.run import atomic

from .workprecision_common import OUT_DIR, Point, machine_info, mark_front, \
    plot_work_precision, write_json

__all__ = ["main", "run", "markdown_tables", "default_report", "regenerate", "write_outputs"]

METRICS = {
    "theta-grid": ("analytic: max |theta - theta_ref| / alpha on a 1 ms grid (4 s window)",
                   "max |dtheta| / alpha"),
    "threshold": ("overturning threshold, Fig. 5 trilith, Omega = 4 rad/s",
                  "|A - A_ref| / A_ref"),
    "restitution": ("engines: free-rocking restitution vs Eq. 20 (no pendulum, lam 5 and 3)",
                    "max |r / r_Eq20 - 1|"),
    "theta-rms": ("engines: RMS(theta - theta_analytic) before the 1st impact / alpha",
                  "RMS / alpha"),
}


def run(quick: bool = False, out: Path | None = None, engines=None,
        analytic: bool = True, log=print) -> dict:
    """Measure, mark fronts, write JSON, plots and tables; return the payload."""
    from .workprecision_analytic import run_analytic
    from .workprecision_engines import run_engines

    out = Path(out) if out is not None else OUT_DIR
    if engines is None:
        from trilith_xval.engines import engine_names
        engines = engine_names()
    machine = machine_info()
    start = time.perf_counter()
    points: list[Point] = []
    if analytic:
        log("analytic paths:")
        points += run_analytic(quick, log=log)
    if engines:
        log("engines:")
        points += run_engines(quick, engines=engines, log=log)
    elapsed = time.perf_counter() - start
    machine["loadavg_end"] = machine_info()["loadavg"]
    meta = {"quick": quick, "elapsed_s": round(elapsed, 1), "metrics": {k: v[0] for k, v in
                                                                          METRICS.items()}}
    write_outputs(points, machine, meta, out, log)
    return {"machine": machine, "meta": meta, "points": points}


def apply_resolution_floor(points: list[Point]) -> list[Point]:
    """A bisected threshold is only known to within its final bracket: an error
    below half the bracket's relative width is replaced by that half width and
    flagged ``resolved = False`` (the measured value stays in ``extra``)."""
    for p in points:
        width = p.extra.get("bracket_rel")
        if p.metric != "threshold" or width is None or not math.isfinite(p.error):
            continue
        p.extra.setdefault("raw_error", p.error)
        floor = 0.5 * width
        p.extra["resolved"] = p.extra["raw_error"] > floor
        p.error = max(p.extra["raw_error"], floor)
    return points


def output_names() -> list[str]:
    """The files :func:`write_outputs` writes into its folder."""
    return ["workprecision.json", "workprecision.md",
            *(f"workprecision_{metric}.png" for metric in METRICS)]


def write_outputs(points: list[Point], machine: dict, meta: dict, out: Path, log=print) -> None:
    """Fronts, JSON, plots and markdown tables from measured points; in a folder
    other than the default one, a file of the same name that this tool did not
    write (:data:`compare.run.atomic.MANIFEST`) is never overwritten."""
    if Path(out) != OUT_DIR:
        atomic.check_into(out, output_names())
    atomic.record_into(out, output_names())
    apply_resolution_floor(points)
    mark_front(points)
    write_json(out / "workprecision.json", machine, points, meta)
    for metric, (title, ylabel) in METRICS.items():
        plot_work_precision(points, metric, out / f"workprecision_{metric}.png", title, ylabel)
    atomic.write_text(out / "workprecision.md", markdown_tables(points, machine, meta))
    log(f"wrote {out}/workprecision.json, .md and plots ({meta['elapsed_s']:.0f} s of measuring)")
    for line in default_report(points):
        log(line)


def regenerate(json_path: Path, out: Path | None = None) -> None:
    """Rewrite fronts, plots and tables from a saved ``workprecision.json``
    (no measuring): for changes to the presentation only."""
    data = json.loads(Path(json_path).read_text())
    points = [Point(d["family"], d["metric"], math.inf if d["error"] is None else d["error"],
                    d["time"], d["params"], d["default"], d["on_front"], d["extra"])
              for d in data["points"]]
    from .workprecision_analytic import THRESHOLD_CASE
    for p in points:  # files written before the analytic bracket width was stored
        if p.metric == "threshold" and p.family.startswith("analytic"):
            p.extra.setdefault("bracket_rel", THRESHOLD_CASE["rel_tol"])
    write_outputs(points, data["machine"], data["meta"], Path(out or Path(json_path).parent))


def _fmt_params(params: dict) -> str:
    return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                     for k, v in params.items())


def markdown_tables(points: list[Point], machine: dict, meta: dict) -> str:
    """One table per metric: family, settings, error, median time, time ratio to
    the backend's default, Pareto flag."""
    lines = [f"Machine: {machine['nproc']} cores, {machine['cpu']}; load average "
             f"{machine['loadavg']} at start, {machine.get('loadavg_end')} at end; "
             f"{machine['date']}.",
             "Versions: " + ", ".join(f"{k} {v}" for k, v in machine["versions"].items()) + ".",
             f"Mode: {'quick' if meta['quick'] else 'full'}; run took {meta['elapsed_s']} s.", ""]
    for metric, (title, _) in METRICS.items():
        sel = [p for p in points if p.metric == metric]
        if not sel:
            continue
        lines += [f"### {metric}: {title}", "",
                  "| family | settings | error | time [s] | time / default | front | default |",
                  "|---|---|---|---|---|---|---|"]
        for p in sel:
            backend = p.family.split()[0]
            base = [q for q in sel if q.default and q.family.split()[0] == backend]
            ratio = (p.time / base[0].time if base and math.isfinite(p.time)
                     and base[0].time > 0 else math.nan)
            err = f"{p.error:.2e}" if math.isfinite(p.error) else "failed"
            if metric == "threshold" and p.extra.get("resolved") is False:
                err = f"<= {0.5 * p.extra['bracket_rel']:.1e} (bisection)"
            lines.append(f"| {p.family} | {_fmt_params(p.params)} | {err} | {p.time:.3g} | "
                         f"{ratio:.2f} | {'yes' if p.on_front else ''} | "
                         f"{'**default**' if p.default else ''} |")
        lines.append("")
    lines += ["### Defaults against the Pareto front", ""]
    lines += [f"- {line}" for line in default_report(points)]
    return "\n".join(lines) + "\n"


def default_report(points: list[Point]) -> list[str]:
    """For each backend and metric: is the default on the front, and if not, the
    cheapest front point at least as accurate."""
    out = []
    groups: dict[tuple[str, str], list[Point]] = {}
    for p in points:
        groups.setdefault((p.family.split()[0], p.metric), []).append(p)
    for (backend, metric), group in sorted(groups.items()):
        defaults = [p for p in group if p.default]
        if not defaults:
            continue
        d = defaults[0]
        better = [p for p in group if p is not d and _dominates(p, d)]
        if not better:
            where = "on the Pareto front" if d.on_front else "on the front within noise"
            out.append(f"{backend} / {metric}: default {where} "
                       f"(error {d.error:.2e}, {d.time:.3g} s)")
            continue
        b = min(better, key=lambda p: p.time)
        out.append(f"{backend} / {metric}: default dominated: {_fmt_params(b.params)} gives "
                   f"error {b.error:.2e} in {b.time:.3g} s vs default {d.error:.2e} in "
                   f"{d.time:.3g} s ({b.time / d.time:.2f} x the time)")
    return out


# Margins for calling a default dominated: on the shared 2-core machine medians of
# identical work moved by up to ~30 % between sweeps (PyBullet with 10 solver
# iterations timed slower than with 50), and errors within 10 % are the same for
# practical purposes.
TIME_NOISE = 0.15
ERROR_SAME = 0.10


def _dominates(p: Point, d: Point) -> bool:
    """``p`` is clearly better than ``d``: much more accurate for no more time, or
    much faster for no less accuracy (beyond the noise margins)."""
    if not (math.isfinite(p.error) and math.isfinite(p.time)):
        return False
    more_accurate = p.error <= (1 - 2 * ERROR_SAME) * d.error and p.time <= (1 + TIME_NOISE) * d.time
    faster = p.time <= (1 - 2 * TIME_NOISE) * d.time and p.error <= (1 + ERROR_SAME) * d.error
    return more_accurate or faster


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m benchmarks.bench_workprecision`` and of
    ``benchmarks/run.py`` (which calls ``main()`` with no arguments: full run)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the < 2 min variant")
    parser.add_argument("--out", type=Path, default=None, help=f"output directory [{OUT_DIR}]")
    parser.add_argument("--engines", default="all",
                        help="comma-separated engines, 'all' or 'none' [all]")
    parser.add_argument("--no-analytic", action="store_true", help="skip the analytic paths")
    parser.add_argument("--regenerate", type=Path, default=None, metavar="JSON",
                        help="only rewrite plots and tables from a saved workprecision.json")
    args = parser.parse_args([] if argv is None else argv)
    if args.regenerate is not None:
        regenerate(args.regenerate, args.out)
        return 0
    from trilith_xval.engines import engine_list
    engines = () if args.engines == "none" else engine_list(args.engines)
    run(quick=args.quick, out=args.out, engines=engines, analytic=not args.no_analytic)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
