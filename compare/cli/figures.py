"""``trilith figures``: the paper's spectrum figures (Figs. 5, 8, 9, 10, 11) as PNG,
PDF or SVG at a publication size (3.5 in or 7 in wide, 300 dpi by default)."""
from __future__ import annotations

import argparse
import sys

from trilith_xval.compare.cli.options import add_workers_arg, check_output_path, info, resolve_workers
from trilith_xval.compare.report.figure_options import DEFAULT_DPI, FORMATS


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "figures",
        help="recompute the paper's overturning-spectrum figures (Figs. 5, 8-11)",
        description="Compute the overturning spectra of the paper's Figs. 5, 8, 9, 10 and 11 "
                    "(with and without pendulum, mode jumps marked) over Omega = 3..30 "
                    "rad/s and write fig5 ... fig11 (PNG, PDF or SVG; Fig. 5 one journal "
                    "column wide, 3.5 in, the others two, 7 in) and figures.json into --out.")
    parser.add_argument("--out", default="figures", metavar="DIR",
                        help="output directory, created if missing; a file there of the "
                             "same name that this tool did not write is never overwritten")
    add_workers_arg(parser)
    parser.add_argument("--dpi", type=int, default=DEFAULT_DPI,
                        help="resolution, in [50, 1200]")
    parser.add_argument("--format", default="png", choices=FORMATS, metavar="FMT",
                        help=f"output format: {', '.join(FORMATS)}")
    parser.add_argument("--quick", action="store_true",
                        help="7 frequencies and coarser tolerances: a smoke run, marked QUICK in "
                             "every caption and in figures.json")
    return parser


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.report.figures import (FigureSettings, check_output_options, make_figures,
                                        output_names, quick_settings)
    workers = resolve_workers(args.workers)
    # Only this tool's own earlier files are rewritten; nothing is created yet.
    check_output_path(args.out, "--out", directory=True, files=output_names(args.format))

    check_output_options(args.dpi, args.format)  # before minutes of spectra
    fs = quick_settings() if args.quick else FigureSettings()
    doc = make_figures(args.out, fs, workers=workers, progress=sys.stderr.isatty(),
                       dpi=args.dpi, fmt=args.format)
    for name, fig in doc["figures"].items():
        print(f"{args.out}/{fig['file']}: {fig['caption']}")
    n_invalid = sum(v["model_valid"] is False for fig in doc["figures"].values()
                    for p in fig["panels"] for curve in p["model_validity"].values()
                    for v in curve)
    if n_invalid:
        info(f"note: {n_invalid} threshold point(s) where the model is invalid (a contact "
             f"would pull or the bob meets a column) are hatched; see model_validity in "
             f"figures.json")
    info(f"{args.out}/figures.json: {doc['n_spectra']} spectra, {len(doc['omega'])} "
         f"frequencies each, {doc['n_runs']} runs ({doc['n_undecided']} undecided) "
         f"in {doc['wall_time']:.1f} s")
    return 0
