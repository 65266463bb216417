"""``trilith atlas``: the trust atlas over the paper's scenes (``compare/campaign/atlas.py``).

``trilith atlas [--engine pymunk,mujoco,pybullet] [--json atlas.json] [--html atlas.html]``
measures every engine's first-overturning amplitude against the model's on the
scenes of Figs. 8-11, Omega 4..28 rad/s by 2, at each engine's calibrated
threshold step and 2x, 5x, 10x coarser, through the run store (killed, it
resumes).  The default engines leave out DART and Drake, whose calibrated
threshold steps are fine enough that their atlas costs hours of CPU (measured in
docs/atlas.md): name them (``--engine dart,drake`` or ``--engine all``),
best with ``--time-budget`` or ``--scheduler``.  ``--from FILE`` renders a
stored atlas without running anything; repeated, it joins atlases of different engines measured separately
(``compare/campaign/atlas_merge.py``).  ``--restep FILE --engine E`` brings a
stored atlas measured before the step rule under it: only the points where the
rule can act are remeasured (``compare/campaign/atlas_restep.py``).
"""
from __future__ import annotations

import argparse
import json
import sys

from trilith_xval.compare.cli.options import (add_engine_list_arg, add_settings_arg, add_store_args,
                                 add_workers_arg, check_output_path, info,
                                 parse_engine_list, parse_omega_range, resolve_workers,
                                 settings_from_args, use_store)



def add_parser(subparsers) -> None:
    p = subparsers.add_parser("atlas", help="the trust atlas: engines vs the model over the "
                                            "paper's scenes and coarser steps",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    add_engine_list_arg(p, None)
    p.add_argument("--omega", default="4:28:2", metavar="START:STOP:STEP",
                   help="pulse frequencies [rad/s]")
    p.add_argument("--factors", default="1,2,5,10", metavar="F[,F...]",
                   help="time steps as multiples of each engine's calibrated threshold "
                        "step, increasing, in [1, 50]; a coarser one runs only where the "
                        "finer one agreed")
    p.add_argument("--json", default=None, metavar="FILE",
                   help="write the atlas as JSON (docs/validation/atlas.json is the stored one)")
    p.add_argument("--html", default=None, metavar="FILE",
                   help="write a standalone HTML page (heat maps, trusted region, cost)")
    p.add_argument("--from", dest="from", action="append", default=None, metavar="FILE",
                   help="a stored atlas JSON; run nothing, write it with --html/--json. "
                        "Repeated: one atlas of the engines of every file (measured "
                        "separately, on the same scenes, grid and model)")
    p.add_argument("--restep", default=None, metavar="FILE",
                   help="a stored atlas: remeasure, for each --engine, only the points "
                        "where it failed at a step coarser than its reference step (the "
                        "step rule's points), carry every other row, and write the whole "
                        "atlas with --json")
    p.add_argument("--consensus", default=None, metavar="E1,E2[,...]|all",
                   help="also where the model is invalid: each engine's own first-failure "
                        "amplitude, converged in the step, and the engines' consensus (engine "
                        "against engine, never the model); with --from, added to the stored "
                        "atlas (docs/atlas.md)")
    p.add_argument("--time-budget", type=float, default=None, metavar="MIN",
                   help="wall minutes after which no new chunk of engine jobs starts; the "
                        "jobs left are recorded as not run (default: no limit)")
    add_settings_arg(p)
    add_workers_arg(p)
    add_store_args(p, scheduler=True)


def _factors(text: str) -> tuple[float, ...]:
    try:
        return tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise ValueError(f"--factors: {text!r} is not a comma-separated list of numbers") from None


def _join_command(args: argparse.Namespace, sources: list) -> str:
    """The command line of a join: only the options a join reads."""
    import shlex

    words = ["trilith", "atlas"] + [w for path in sources for w in ("--from", str(path))]
    for flag, value in (("--json", args.json), ("--html", args.html)):
        if value is not None:
            words += [flag, str(value)]
    return shlex.join(words)


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.campaign.atlas import AtlasConfig, run_atlas

    if args.json is not None:
        check_output_path(args.json, "--json", suffixes=(".json",))
    if args.html is not None:
        check_output_path(args.html, "--html", suffixes=(".html",))
    sources = getattr(args, "from")  # "from" is a keyword: the flag's own name as dest
    consensus = (None if args.consensus is None
                 else parse_engine_list(args.consensus, "--consensus"))
    if consensus is not None and len(consensus) < 2:
        raise ValueError(f"--consensus needs at least two engines to compare, got "
                         f"{args.consensus!r}")
    if args.restep is not None:
        if sources is not None or consensus is not None:
            raise ValueError("--restep runs alone: not with --from or --consensus")
        if args.json is None:
            raise ValueError("--restep writes the whole atlas: give --json FILE")
        doc = _restep(args)
        page = _render(doc, args, f"--restep {args.restep!r}")
        _write_json(args.json, doc)
    elif sources is not None:
        if args.html is None and args.json is None:
            raise ValueError("--from reads stored atlases: give --html FILE and/or --json FILE")
        from trilith_xval.compare.campaign.atlas_check import read_atlas
        docs = [read_atlas(path) for path in sources]
        if len(docs) > 1:
            from trilith_xval.compare.campaign.atlas_merge import merge_atlases
            from trilith_xval.compare.run.provenance import collect
            doc = merge_atlases(docs, [f"--from {p!r}" for p in sources])
            doc["provenance"] = collect(args)
            # A join runs nothing: engines, grid, workers and store do not apply.
            doc["command"] = doc["provenance"]["command"] = _join_command(args, sources)
        else:
            doc = docs[0]
        if consensus is not None:
            use_store(args)
            doc = _with_consensus(doc, consensus, resolve_workers(args.workers), args)
        page = _render(doc, args, " ".join(f"--from {p!r}" for p in sources))
        if args.json is not None:
            _write_json(args.json, doc)
    else:
        engines = parse_engine_list(args.engine)
        omegas = parse_omega_range(args.omega, "--omega")
        loaded = settings_from_args(args, engines)
        try:
            config = AtlasConfig(engines=engines, omegas=tuple(float(w) for w in omegas),
                                 factors=_factors(args.factors),
                                 settings=() if loaded is None else tuple(
                                     (e, tuple(sorted(t.items())))
                                     for e, t in loaded.tables.items() if e in engines))
        except ValueError as exc:
            raise ValueError(f"--factors/--engine: {exc}") from None
        budget = args.time_budget
        if budget is not None and not (0.0 <= budget <= 1e5):
            raise ValueError(f"--time-budget must be in [0, 1e5] min, got {budget!r}")
        workers = resolve_workers(args.workers)
        use_store(args)
        from trilith_xval.compare.campaign.atlas import atlas_scenes
        from trilith_xval.compare.campaign.study import _scene
        from trilith_xval.compare.cli.options import step_notes
        step_notes(engines, [_scene(n, c) for n, _ in atlas_scenes(config)
                             for c in config.cases])
        doc = run_atlas(config, workers, None if budget is None else 60.0 * budget)
        from trilith_xval.engines import engine_names
        doc["engines_not_run"] = [e for e in engine_names() if e not in engines]
        doc["settings_file"] = None if loaded is None else loaded.describe()
        from trilith_xval.compare.run.provenance import collect
        doc["provenance"] = collect(args)
        doc["command"] = doc["provenance"]["command"]
        if consensus is not None:
            doc = _with_consensus(doc, consensus, workers, args)
        page = _render(doc, args, "the atlas")
        if args.json is not None:
            _write_json(args.json, doc)
    if page is not None:
        from trilith_xval.compare.run import atomic
        atomic.write_text(args.html, page)
        info(f"wrote {args.html}")
    _print(doc)
    return 0


def _restep_command(args: argparse.Namespace, engine: str) -> str:
    """The command line of one engine's restep: only the options a restep reads
    (the grid and factors are the stored atlas's)."""
    import shlex

    words = ["trilith", "atlas", "--restep", str(args.restep), "--engine", engine,
             "--json", str(args.json), "--workers", str(args.workers)]
    if getattr(args, "cache", None):
        words += ["--cache", str(args.cache)]
    if getattr(args, "no_cache", False):
        words.append("--no-cache")
    return shlex.join(words)


def _restep(args: argparse.Namespace) -> dict:
    """The stored atlas ``--restep`` with each ``--engine``'s step-rule points
    remeasured (compare/campaign/atlas_restep.py)."""
    from trilith_xval.compare.campaign.atlas import run_atlas
    from trilith_xval.compare.campaign.atlas_check import read_atlas
    from trilith_xval.compare.campaign.atlas_restep import (merge_restep, restep_config,
                                                            rule_points)
    from trilith_xval.compare.run.provenance import collect
    if args.engine is None:
        raise ValueError("--restep needs --engine E[,E...]: the engines to bring under "
                         "the step rule")
    doc = read_atlas(args.restep, "--restep")
    engines = parse_engine_list(args.engine)
    plans = [(e, rule_points(doc, e)) for e in engines]  # every engine checked first
    workers = resolve_workers(args.workers)
    use_store(args)
    for engine, points in plans:
        info(f"restep {engine}: {len(points)} of {len(doc['points'])} points where the "
             "step rule can act")
        # No point to remeasure: nothing runs (an empty selection is not "all").
        part = (run_atlas(restep_config(doc, engine, points), workers) if points else
                {"config": doc["config"], "steps": doc["steps"], "points": [],
                 "wall_s": 0.0, "parent_cpu_s": 0.0, "local_cpu_s": 0.0, "workers": workers})
        part["provenance"] = collect(args)
        part["command"] = part["provenance"]["command"] = _restep_command(args, engine)
        doc = merge_restep(doc, part, engine)
    return doc


def _with_consensus(doc: dict, engines, workers: int, args) -> dict:
    """``doc`` with the engines' consensus at its invalid points, and the command
    that added it."""
    from trilith_xval.compare.campaign.atlas_consensus import add_consensus
    from trilith_xval.compare.run.provenance import collect
    doc = add_consensus(doc, engines, workers)
    doc["consensus"]["command"] = collect(args)["command"]
    return doc


def _render(doc: dict, args: argparse.Namespace, where: str) -> str | None:
    """The HTML page (when ``--html``) and the printed rows, built in memory before
    any file is written: a document the checks let through but the renderer
    cannot read is still refused with nothing written."""
    from trilith_xval.compare.report.atlas_page import page_html, trusted_rows
    try:
        trusted_rows(doc)
        return page_html(doc) if args.html is not None else None
    except (KeyError, TypeError, AttributeError, ValueError, IndexError) as exc:
        raise ValueError(f"{where}: not an atlas this version can render "
                         f"({type(exc).__name__}: {exc})") from None


def _write_json(path: str, doc: dict) -> None:
    from trilith_xval.compare.run import atomic
    from trilith_xval.compare.run.jsonable import plain
    atomic.write_text(path, json.dumps(plain(doc), separators=(",", ":"), allow_nan=False)
                      + "\n")
    info(f"wrote {path}")


def _print(doc: dict) -> None:
    """The trusted region per engine and step, one line each."""
    from trilith_xval.compare.report.atlas_page import trusted_rows
    print("engine, step [s]: points that agree / valid points reached (share), worst |error|; "
          "where not", file=sys.stdout)
    for engine, dt, agree, share, worst, where in trusted_rows(doc):
        print(f"{engine}, {dt}: {agree} ({share}), {worst}; {where}", file=sys.stdout)
    c = doc.get("consensus")
    if c:
        print(f"where the model is invalid ({c['invalid_points']} points; engine against "
              f"engine, {', '.join(c['engines'])}): {c['gained']} gained an answer of "
              f"{c['answerable']} the engines can answer; "
              + ", ".join(f"{k} {v}" for k, v in sorted(c["status"].items())), file=sys.stdout)
