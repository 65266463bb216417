"""``trilith restitution-map``: each engine's effective rocking restitution and
threshold error against lam, over a stated grid of its settings
(:mod:`compare.measure.restitution_map`; docs/restitution-map.md)."""
from __future__ import annotations

import argparse
import json
import math

from trilith_xval.compare.cli.options import (add_store_args, info, print_json, resolve_workers,
                                              use_store)
from trilith_xval.compare.run.jsonable import plain


def add_parser(subparsers) -> argparse.ArgumentParser:
    from trilith_xval.compare.measure.restitution_map import LAMS
    from trilith_xval.engines import engine_names
    parser = subparsers.add_parser(
        "restitution-map",
        help="r_eff / r_H and threshold error vs lam per engine, over its settings",
        description="For each engine and each settings variant of its grid: the free-"
                    "rocking restitution (measured / Eq. 20, the block's Housner value) and "
                    "the one-sine threshold error at Omega = 3 p on the block family "
                    "(lam 1.5-10) and the fig5 trilith (Eq. 20, Eq. 19); the cheapest "
                    "settings within 0.5 % and 2 % per lam range.")
    parser.add_argument("--engine", action="append", default=None, metavar="NAME",
                        help=f"engine ({', '.join(engine_names())} or all); repeatable (default: all)")
    parser.add_argument("--lam", action="append", type=float, default=None, metavar="LAM",
                        help=f"block slenderness, one of {', '.join(f'{x:g}' for x in LAMS)}; "
                             "repeatable (default: all)")
    parser.add_argument("--variant", action="append", default=None, metavar="NAME",
                        help="only the settings variants of this name (e.g. default, "
                             "dt=2e-4); repeatable (default: every variant of each grid)")
    parser.add_argument("--no-trilith", action="store_true",
                        help="leave out the fig5 trilith (Eq. 20 and Eq. 19)")
    parser.add_argument("--json", metavar="FILE", default=None,
                        help="write the map document (as docs/validation/restitution_map.json)")
    parser.add_argument("--out", metavar="DIR", default=None,
                        help="write one figure per engine and the cheapest settings files here")
    parser.add_argument("--workers", type=int, default=1, metavar="N",
                        help="parallel processes; -1 = all cores")
    add_store_args(parser)
    return parser


def _engines(names) -> list[str]:
    from trilith_xval.engines import engine_names
    if not names or names == ["all"]:
        return list(engine_names())
    for n in names:
        if n not in engine_names():
            raise ValueError(f"--engine must be one of {', '.join(engine_names())} or all, "
                             f"got {n!r}")
    if len(set(names)) != len(names):
        raise ValueError(f"--engine: an engine is named twice in {names}")
    return list(names)


def _lams(values) -> list[float]:
    from trilith_xval.compare.measure.restitution_map import LAMS
    if not values:
        return list(LAMS)
    for v in values:
        if not math.isfinite(v) or v not in LAMS:
            raise ValueError(f"--lam must be one of {', '.join(f'{x:g}' for x in LAMS)}, "
                             f"got {v:g}")
    return sorted(set(values))


def run(args: argparse.Namespace) -> int:
    import os
    import time

    from trilith_xval.compare.cli.output_paths import check_output_path
    from trilith_xval.compare.measure.restitution_map import restitution_map
    from trilith_xval.compare.run.provenance import command_line, git_commit

    engines, lams = _engines(args.engine), _lams(args.lam)
    if args.variant is not None:
        from trilith_xval.compare.measure.restitution_map import grid
        known = {v.name for e in engines for v in grid(e)}
        bad = [v for v in args.variant if v not in known]
        if bad:
            raise ValueError(f"--variant must be one of {', '.join(sorted(known))}, "
                             f"got {bad[0]!r}")
    workers = resolve_workers(args.workers)
    if args.json is not None:
        check_output_path(args.json, "--json", suffixes=(".json",))
    if args.out is not None:
        check_output_path(args.out, "--out", directory=True)
    use_store(args)
    t0 = time.perf_counter()
    doc = restitution_map(engines, lams, trilith=not args.no_trilith, workers=workers,
                          variants=args.variant)
    doc = {"command": command_line(args), "commit": git_commit(), "cpu_count": os.cpu_count(),
           "workers": workers, "status": "complete", **doc,
           "wall_s": time.perf_counter() - t0}
    doc = plain(doc)
    if args.json is not None:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=1, allow_nan=True)
            f.write("\n")
    if args.out is not None:
        from trilith_xval.compare.report.restitution_map_doc import write_settings
        from trilith_xval.compare.report.restitution_map_plot import write_figures
        write_figures(doc, args.out)
        write_settings(doc, os.path.join(args.out, "settings"))
    if args.json is None and args.out is None:
        print_json(doc)
        return 0
    for p in doc["cheapest"]:
        print(f"{p['engine']:9s} {p['range']:10s} "
              + (f"{p['variant']} ({p['cpu_s']:.1f} CPU s)" if p["variant"] else "none passes"))
    info(f"{len(doc['cells'])} cells, {doc['cpu_s']:.0f} CPU s spent, load "
         f"{', '.join(f'{x:.1f}' for x in doc['load_average'])}")
    return 0
