"""``trilith campaign FILE.toml``: a declared study, resumable, one combined report.

``trilith campaign campaigns/paper.toml [--out DIR] [--workers N] [--scheduler ADDR]
[--estimate]`` runs every job of the file (see :mod:`compare.campaign.study`) through the
run store and writes ``DIR/campaign.json`` and ``DIR/index.html`` (swapped in
whole).  Killed, it resumes on the next call: finished engine runs and jobs
come from the store.  ``--estimate`` prints the job count and the expected time
(from the run costs measured in the store) and runs nothing.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import sys
import time
from pathlib import Path

from trilith_xval.compare.cli.excitation_args import check_run_budget
from trilith_xval.compare.cli.options import (add_settings_arg, add_store_args, check_output_path,
                                 settings_from_args, use_store)

# Cost of one engine run [s] before the store has measured any (median of the
# Fig. 5 threshold runs at the calibrated step on the 2-core target machine).
PRIOR_RUN_COST = 0.4


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("campaign", help="run a declared study (TOML) through the run "
                                               "store, resumable, with one combined report",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", metavar="FILE.toml", help="campaign file (see campaigns/paper.toml)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory, replaced whole at the end; refused when it "
                        "holds files this tool did not write [campaign-<name>]")
    p.add_argument("--workers", type=int, default=None,
                   help="local processes, >= 1 [the file's, else 2]")
    p.add_argument("--estimate", action="store_true",
                   help="print the number of jobs and the expected time; run nothing")
    add_settings_arg(p)
    add_store_args(p, scheduler=True)


def check_budget(study, file, loaded=None) -> None:
    """Refuse a file whose engine runs would exceed the run budget: the longest
    run of each (engine, step) is at the lowest Omega (the longest pulse); step 0
    is the ``--settings`` file's step (else the calibrated one)."""
    import dataclasses

    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.engines import configure

    from trilith_xval.compare.cli.options import file_options

    # (motion, fixed run length or None: until the verdict is decided)
    motions = ([(pulse_of(p, 1.0, min(study.omegas)), None) for p in study.pulses]
               if study.omegas else [])
    if study.records is not None:  # a record runs its fixed window: end + tail
        longest = max(study.records.records(), key=lambda r: r.end_time)
        motions.append((longest, longest.end_time + study.records.ida.tail))
    for engine in study.engines:
        settings = configure(engine, **file_options(loaded, engine))
        for dt in study.steps:
            for motion, window in motions:
                if dt or window is not None:
                    check_run_budget(engine, dataclasses.replace(settings, dt=dt or settings.dt),
                                     motion, option=f"{file}: campaign.steps", length=window)


def _run_cost(engine: str, dt: float, costs: dict) -> float:
    """Expected cost [s] of one run of ``engine`` at step ``dt`` (0: the calibrated
    threshold step): the mean measured in the store at that step, else the measured
    step nearest to it scaled by the step ratio (steps per simulated second), else a
    prior."""
    from trilith_xval.engines import configure

    from trilith_xval.engines.calibration import calibrated

    # An estimate: the calibrated step whatever the scene (a scene outside its
    # domain runs the finer reference step and costs more than estimated).
    dt = dt or getattr(configure(engine, **calibrated(engine).options), "dt", 1e-4)
    measured = {}
    for label, (mean, _n) in costs.items():
        name, _, step = label.partition(" dt=")
        if name == engine and step:
            measured[float(step)] = mean
    if not measured:
        return PRIOR_RUN_COST
    if dt in measured:
        return measured[dt]
    near = min(measured, key=lambda s: abs(math.log(s / dt)))
    return measured[near] * near / dt


def _estimates(jobs, store) -> list[float]:
    """Expected cost [s] of each threshold job: runs per job x the run cost."""
    from trilith_xval.compare.campaign.study import JOB_RUNS

    costs = store.mean_costs("run") if store is not None else {}
    return [JOB_RUNS * _run_cost(job.engine, job.dt or dict(job.options).get("dt", 0.0), costs)
            for job in jobs]


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.run import atomic
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.campaign.study import (load_study, reference_jobs, run_reference, run_threshold,
                               threshold_jobs)

    study = load_study(args.file)
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    workers = args.workers or study.workers
    out = Path(args.out or f"campaign-{study.name}")
    if not args.estimate:  # --estimate writes nothing: it leaves the output alone
        check_output_path(out, "--out", directory=True, replace=True)
    loaded = settings_from_args(args, study.engines)
    check_budget(study, args.file, loaded)
    if not study.steps or 0 in study.steps:  # a calibrated step is asked for
        from trilith_xval.compare.campaign.study import _scene
        from trilith_xval.compare.cli.options import step_notes
        step_notes(study.engines, [_scene(n, c) for n in study.scenes for c in study.cases])
    store = use_store(args)
    t0 = time.perf_counter()
    # --estimate writes nothing: it leaves the output location (and its lock) alone.
    with contextlib.nullcontext() if args.estimate else atomic.output_lock(out):
        ref_jobs = reference_jobs(study)
        references = dict(zip(ref_jobs, runs.run_many(run_reference, ref_jobs,
                                                       workers=workers)))
        jobs = threshold_jobs(study, references, None if loaded is None else loaded.tables)
        unique, index = distinct(jobs)
        est = _estimates(unique, store)
        from trilith_xval.compare.campaign.kind_study import kind_points
        n_kind = len(kind_points(study))
        others = (f"; {n_kind} points of {len(study.kind_scenes)} scene(s) of another kind, "
                  f"engine against engine (a scan and {len(study.engines)} converged searches "
                  "each; not in the estimate)" if n_kind else "")
        print(f"campaign {study.name}: {len(study.scenes)} scenes, {len(ref_jobs)} reference "
              f"points, {len(jobs)} engine threshold jobs ({len(unique)} distinct); at most {_duration(sum(est))} of "
              f"CPU, ~{_duration(sum(est) / workers)} on {workers} workers (jobs already in "
              f"the store cost nothing){others}",
              # Asked for with --estimate it is the result (stdout); before a run, a
              # progress line (stderr).
              file=sys.stdout if args.estimate else sys.stderr, flush=True)
        if args.estimate:
            return 0
        bar = _bar(sum(est))
        done = list(runs.run_many(run_threshold, unique, workers=workers,
                                  on_done=lambda i, r: bar.update(est[i])))
        bar.close()
        rows = [{**done[i], "scene": job.scene, "case": job.case} for job, i in zip(jobs, index)]
        kind_rows = []
        if study.kind_scenes:
            from trilith_xval.compare.campaign.kind_study import kind_rows as consensus_rows
            from trilith_xval.compare.run.progress import bar as count_bar
            kbar = count_bar(len(kind_points(study)) * (1 + len(study.engines)),
                             "campaign: engines against each other", "jobs")
            kind_rows = consensus_rows(study, workers, on_done=lambda i, r: kbar.update(1))
            kbar.close()
        record_refs: list = []
        if study.records is not None:
            from trilith_xval.compare.cli.campaign_records import record_rows
            record_refs, more = record_rows(study, workers)
            rows += more
        doc = {"study": study.describe(), "references": [
            {"scene": n, "case": c, "pulse": p, "omega": w, "a_reference": a, "mode": m}
            for (n, c, p, w), (a, m) in references.items()] + record_refs, "rows": rows,
            "consensus": kind_rows,
            "summary": summarise(rows), "versions": _versions(study),
            "settings_file": None if loaded is None else loaded.describe(),
            "wall_time": time.perf_counter() - t0}
        with atomic.report_dir(out, lock=False) as tmp:
            write_campaign(doc, tmp)
    print(runs.stats_line(), file=sys.stderr)
    print(f"campaign written to {out / 'index.html'} ({len(rows)} jobs, "
          f"{sum('error' in r for r in rows)} errors, {time.perf_counter() - t0:.0f} s)")
    return 0


def distinct(jobs: list) -> tuple[list, list[int]]:
    """The jobs with distinct store keys, and for each job the index of its
    distinct one (e.g. the no-pendulum Fig. 8 scenes of one lam are one trilith:
    the scene name is a label)."""
    from trilith_xval.compare.run.keys import digest


    seen: dict[str, int] = {}
    unique, index = [], []
    for job in jobs:
        key = digest(job.description())
        if key not in seen:
            seen[key] = len(unique)
            unique.append(job)
        index.append(seen[key])
    return unique, index


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"


def _bar(total: float):
    from trilith_xval.compare.run.progress import bar
    # Units are seconds of estimated work: tqdm's rate is then the measured speed
    # against the measured costs, and its ETA the remaining estimated work at it.
    return bar(round(total, 1), "campaign", "s of estimated work", unit_scale=False,
               bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} s of work [{elapsed}<{remaining}]")


def _versions(study) -> dict:
    from trilith_xval.compare.run.keys import backend_version, project_version
    return {"project": project_version(), "analytic-fast": backend_version("analytic-fast"),
            **{e: backend_version(e) for e in study.engines}}


def summarise(rows: list[dict]) -> list[dict]:
    """Per engine and time step: jobs, bracketed, median and worst |rel. error|."""
    import math

    import numpy as np
    groups: dict = {}
    for r in rows:
        groups.setdefault((r["engine"], r["dt"]), []).append(r)
    out = []
    for (engine, dt), rs in sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1] or 0)):
        errs = [abs(r["rel_error"]) for r in rs if math.isfinite(r.get("rel_error", math.nan))]
        out.append({"engine": engine, "dt": dt, "jobs": len(rs),
                    "errors": sum("error" in r for r in rs), "bracketed": len(errs),
                    "median_abs_rel_error": float(np.median(errs)) if errs else None,
                    "max_abs_rel_error": max(errs) if errs else None})
    return out


def write_campaign(doc: dict, out: Path) -> None:
    """``campaign.json`` (strict JSON) and a plain ``index.html`` table."""
    import html
    import json

    from trilith_xval.compare.run import atomic

    from trilith_xval.compare.run.jsonable import plain

    atomic.write_text(out / "campaign.json", json.dumps(plain(doc), indent=1,
                                                        allow_nan=False))

    def table(rows, cols):
        head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
        body = "".join("<tr>" + "".join(f"<td>{html.escape(_fmt(r.get(c)))}</td>"
                                         for c in cols) + "</tr>" for r in rows)
        return f"<table><tr>{head}</tr>{body}</table>"
    cols = ["scene", "case", "pulse", "record", "omega", "engine", "dt", "a_reference", "a_engine",
            "rel_error", "rel_resolution", "cause", "valid", "mode_reference", "mode_engine",
            "n_runs", "cpu_s", "from_store", "error"]
    study = doc["study"]
    page = ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>campaign "
            f"{html.escape(study['name'])}</title><style>body{{font-family:sans-serif}}"
            "table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;"
            "padding:2px 6px;text-align:right}</style></head><body>"
            f"<h1>Campaign {html.escape(study['name'])}</h1>"
            f"<p>{len(study['scenes']) + len(study.get('kind_scenes') or ())} scenes, engines "
            f"{', '.join(study['engines'])}, "
            f"steps {study['steps']}, Omega {study['omegas']} rad/s"
            + ("; engine overturning threshold against the analytic one (rel_error = "
               "A_engine/A_analytic - 1)" if doc["rows"] else "") + ".</p>"
            + ("<h2>Summary</h2>" + table(doc["summary"], list(doc["summary"][0]))
               + "<h2>Every job</h2>" + table(doc["rows"], cols) if doc["rows"] else "")
            + _consensus_section(doc.get("consensus") or [], study["engines"], table)
            + f"<h2>Versions</h2>{table([doc['versions']], list(doc['versions']))}"
            "</body></html>\n")
    atomic.write_text(out / "index.html", page)


def _consensus_section(rows: list[dict], engines: list[str], table) -> str:
    """The points of the scenes of another kind (compare.campaign.kind_study): each
    engine's own first failure and the consensus, headed as engine against engine."""
    if not rows:
        return ""
    flat = []
    for r in rows:
        row = {k: r.get(k) for k in ("scene", "case", "pulse", "omega", "status", "median",
                                     "failure")}
        for e in engines:
            got = (r.get("engines") or {}).get(e)
            row[f"{e} [m/s^2]"] = got["a_fails"] if got else None
            row[f"{e} vs median"] = f"{100 * got['deviation']:+.2f} %" if got else None
        row["outliers"] = "; ".join(f"{o['engine']} ({o['cause']})" for o in r["outliers"])
        row["no answer"] = "; ".join(f"{m['engine']} ({m['cause']})" for m in r["no_answer"])
        flat.append(row)
    return ("<h2>Scenes of another kind: engine against engine</h2><p>The model does not "
            "cover these scenes (docs/geometry.md): each engine's own first failure "
            "(overturn or collapse), converged in the step, and the median of the engines; "
            "never agreement with the model.</p>" + table(flat, list(flat[0])))


def _fmt(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.5g}"
    return str(value)
