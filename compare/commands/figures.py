"""``trilith figures``: the paper's spectrum figures (Figs. 5, 8, 9, 10, 11) as PNG."""
from __future__ import annotations

import argparse
import sys

from ._common import add_workers_arg, check_output_path, info, resolve_workers


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "figures",
        help="recompute the paper's overturning-spectrum figures (Figs. 5, 8-11) as PNG",
        description="Compute the overturning spectra of the paper's Figs. 5, 8, 9, 10 and 11 "
                    "(with and without pendulum, mode jumps marked) over Omega = 3..30 "
                    "rad/s and write fig5.png ... fig11.png and figures.json into --out.")
    parser.add_argument("--out", default="figures", metavar="DIR",
                        help="output directory, created if missing")
    add_workers_arg(parser)
    parser.add_argument("--quick", action="store_true",
                        help="5 frequencies and coarser tolerances: a smoke run in seconds")
    return parser


def run(args: argparse.Namespace) -> int:
    workers = resolve_workers(args.workers)
    check_output_path(args.out, "--out", directory=True)
    from compare.figures import FigureSettings, make_figures, quick_settings

    fs = quick_settings() if args.quick else FigureSettings()
    doc = make_figures(args.out, fs, workers=workers, progress=sys.stderr.isatty())
    for name, fig in doc["figures"].items():
        print(f"{args.out}/{fig['file']}: {fig['caption']}")
    info(f"{args.out}/figures.json: {doc['n_spectra']} spectra, {len(doc['omega'])} "
         f"frequencies each, {doc['n_runs']} runs ({doc['n_undecided']} undecided) "
         f"in {doc['wall_time']:.1f} s")
    return 0
