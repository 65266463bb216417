"""``trilith bench``: the work-precision benchmarks (run time against error).

Runs :mod:`benchmarks.bench_workprecision` from the source tree (``benchmarks/``
is not an installed package: it lives next to ``compare/``).  Outputs go to
``benchmarks/out/`` unless ``--out`` says otherwise; see ``docs/benchmarks.md``.
"""
from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from ._common import add_store_args, use_store

ROOT = Path(__file__).resolve().parents[2]
ENGINES = ("pybullet", "pymunk")


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench", help="work-precision benchmarks: error vs wall time of every backend",
        description="Measure error against the analytic reference versus wall time: the "
                    "analytic paths across tolerances, PyBullet and Pymunk across time "
                    "steps and solver settings. Writes JSON, PNG plots and markdown tables.")
    parser.add_argument("--quick", action="store_true",
                        help="the < 2 min variant (fewer points, coarser bisection)")
    parser.add_argument("--out", default=None, metavar="DIR",
                        help="output directory [benchmarks/out]")
    parser.add_argument("--engines", default=",".join(ENGINES),
                        help="comma-separated engines to measure, or 'none' "
                             f"[{','.join(ENGINES)}]")
    parser.add_argument("--no-analytic", action="store_true",
                        help="skip the analytic paths")
    add_store_args(parser)  # the untimed analytic references only; timed runs always run
    return parser


def _engines(value: str) -> tuple[str, ...]:
    if value.strip() == "none":
        return ()
    names = tuple(v.strip() for v in value.split(",") if v.strip())
    for name in names:
        if name not in ENGINES:
            raise ValueError(f"--engines: unknown engine {name!r}; allowed: "
                             f"{', '.join(ENGINES)} or none")
    return names


def _load_bench():
    if not (ROOT / "benchmarks" / "bench_workprecision.py").is_file():
        raise ValueError(f"benchmarks/ not found next to compare/ (looked in {ROOT}); "
                         "trilith bench runs from a source checkout")
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    return importlib.import_module("benchmarks.bench_workprecision")


def run(args: argparse.Namespace) -> int:
    engines = _engines(args.engines)  # validate before any heavy work
    out = Path(args.out) if args.out is not None else None
    if out is not None and out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a directory, got the file {str(out)!r}")
    use_store(args)
    bench = _load_bench()
    bench.run(quick=args.quick, out=out, engines=engines, analytic=not args.no_analytic)
    return 0
