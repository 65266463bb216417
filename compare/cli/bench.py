"""``trilith bench``: the work-precision benchmarks (run time against error).

Runs :mod:`benchmarks.bench_workprecision` from the source tree (``benchmarks/``
is not an installed package: it lives next to ``compare/``).  Outputs go to
``benchmarks/out/`` unless ``--out`` says otherwise; see ``docs/benchmarks.md``.
With ``--strict`` the exit code is 1 when a backend's default settings are
dominated (another setting is clearly faster or more accurate, beyond the noise
margins of ``bench_workprecision``) or a default run failed.
"""
from __future__ import annotations

import argparse
import importlib
import math
from pathlib import Path

from trilith_xval.compare.cli.options import (add_engine_list_arg, add_store_args, check_output_path, info,
                      parse_engine_list, use_store)

ROOT = Path(__file__).resolve().parents[2]
from trilith_xval.engines import engine_names


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench", help="work-precision benchmarks: error vs wall time of every backend",
        description="Measure error against the analytic reference versus wall time: the "
                    "analytic paths across tolerances, every engine "
                    f"({', '.join(engine_names())}) across time steps and solver settings. "
                    "Writes JSON, PNG plots and markdown tables.")
    parser.add_argument("--quick", action="store_true",
                        help="the < 2 min variant (fewer points, coarser bisection)")
    parser.add_argument("--out", default=None, metavar="DIR",
                        help="output directory, created if missing (default: benchmarks/out)")
    add_engine_list_arg(parser, engine_names(), none_ok=True)
    parser.add_argument("--no-analytic", action="store_true",
                        help="skip the analytic paths")
    parser.add_argument("--strict", action="store_true",
                        help="exit with code 1 when a default setting is dominated or failed")
    add_store_args(parser)  # the untimed analytic references only; timed runs always run
    return parser


def _load_bench():
    # benchmarks/ is a package of this project (pyproject), importable like compare/.
    return importlib.import_module("benchmarks.bench_workprecision")


def failed_defaults(bench, points) -> list[str]:
    """``backend / metric`` of each default point that failed or is dominated."""
    out = []
    for d in (p for p in points if p.default):
        group = [p for p in points if p.metric == d.metric
                 and p.family.split()[0] == d.family.split()[0]]
        if not math.isfinite(d.error):
            out.append(f"{d.family.split()[0]} / {d.metric}: default run failed")
        elif any(p is not d and bench._dominates(p, d) for p in group):
            out.append(f"{d.family.split()[0]} / {d.metric}: default dominated")
    return out


def run(args: argparse.Namespace) -> int:
    engines = parse_engine_list(args.engine, none_ok=True)  # before any heavy work
    if not engines and args.no_analytic:
        raise ValueError("--engine none with --no-analytic leaves nothing to measure")
    # Only this tool's own earlier files are rewritten; nothing is created yet.
    out = None if args.out is None else check_output_path(args.out, "--out", directory=True,
                                                          files=())
    bench = _load_bench()
    if out is not None:
        from trilith_xval.compare.run.atomic import check_into
        check_into(out, bench.output_names(), "--out")
    use_store(args)
    payload = bench.run(quick=args.quick, out=out, engines=engines,
                        analytic=not args.no_analytic, log=info)
    failures = failed_defaults(bench, payload["points"])
    for line in failures:
        print(f"  FAIL {line}")
    return 1 if (args.strict and failures) else 0
