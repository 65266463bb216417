"""``trilith report``: run the validation campaign and write the report.

``trilith report [--scene fig5] [--engines pybullet,pymunk] [--quick] [--out DIR]``
writes ``DIR/index.html`` (self-contained), ``DIR/summary.json`` and
``DIR/summary.md``.  Exit code 0 when the report was written, whatever the
verdicts say (they are the report's content); 2 on bad input.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from engines import ENGINES
from scenes import scene_path

from ._common import add_store_args, use_store


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("report", help="run the validation campaign, write an HTML/JSON report",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default="fig5", help="scene name or TOML path [fig5]")
    p.add_argument("--engines", default=",".join(ENGINES),
                   help=f"comma-separated engines from {', '.join(ENGINES)} [all]")
    p.add_argument("--quick", action="store_true",
                   help="smaller grids (< 2 min on 2 cores) instead of the full campaign")
    p.add_argument("--out", default="report", help="output directory [report]")
    p.add_argument("--workers", type=int, default=2, help="parallel processes, >= 1 [2]")
    p.add_argument("--dt", type=float, default=None,
                   help="override every engine's time step [s] (default: calibrated)")
    add_store_args(p, scheduler=True)


def parse_engines(text: str) -> tuple[str, ...]:
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if not names:
        raise ValueError(f"--engines must name at least one of {', '.join(ENGINES)}")
    for n in names:
        if n not in ENGINES:
            raise ValueError(f"--engines: unknown engine {n!r}; allowed: {', '.join(ENGINES)}")
    return names


def run(args: argparse.Namespace) -> int:
    from compare import atomic, runs
    from compare.campaign import CampaignConfig, run_campaign
    from compare.report_html import write_report

    scene_path(args.scene)  # ValueError naming the scene before any work
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    changes = dict(scene=args.scene, engines=parse_engines(args.engines), workers=args.workers,
                   engine_dt=args.dt)
    config = CampaignConfig.quick(**changes) if args.quick else CampaignConfig(**changes)
    if Path(args.out).is_file():
        raise ValueError(f"--out must be a directory, got the file {args.out!r}")
    use_store(args)
    t0 = time.perf_counter()
    with atomic.output_lock(args.out):  # a second report into the same --out: clear error
        result = run_campaign(config)
        with atomic.report_dir(args.out, lock=False) as tmp:  # swapped in whole
            paths = {k: Path(args.out) / p.name for k, p in write_report(result, tmp).items()}
    print(runs.stats_line(), file=sys.stderr)
    n_fail = sum(not v["passed"] for v in result.verdicts)
    print(f"report written to {paths['html']} ({len(result.verdicts) - n_fail}/"
          f"{len(result.verdicts)} verdicts pass, {time.perf_counter() - t0:.0f} s)",
          file=sys.stdout)
    for v in result.verdicts:
        if not v["passed"]:
            print(f"  FAIL {v['backend']}: {v['metric']} = {v['value']} "
                  f"(tolerance {v['tolerance']})")
    return 0
