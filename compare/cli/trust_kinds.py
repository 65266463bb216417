"""``trilith trust`` (and ``trilith report``) on a scene of another kind: the
engines' consensus (:mod:`compare.campaign.trust_kinds`) written as trust.json,
trust.csv and index.html, whole."""
from __future__ import annotations

import json

from trilith_xval.compare.cli.options import check_structure_engines

__all__ = ["check_kind_trust", "write_kind_trust", "print_verdicts"]


def check_kind_trust(scene, engines, records, command: str) -> None:
    """The door for a kind (before any work): engines that build the body list, no
    ``--record`` (the record searches start from the model's intensity; a kind's
    would need a scan per record, not built yet)."""
    check_structure_engines(engines, scene.kind, command)
    if records:
        raise ValueError(f"trilith {command} --record: not available on the {scene.kind} kind "
                         "(the record search starts from the model's intensity, which a kind "
                         "does not have)")


def write_kind_trust(scene, engines, out, quiet: bool) -> dict:
    """Measure (:func:`compare.campaign.trust_kinds.trust_kind`) and write ``out``
    whole (:mod:`compare.run.atomic`); returns the document."""
    from trilith_xval.compare.campaign.trust_kinds import trust_kind
    from trilith_xval.compare.report.trust_kinds_page import kind_trust_csv, kind_trust_html
    from trilith_xval.compare.run import atomic
    from trilith_xval.compare.run.jsonable import plain
    with atomic.output_lock(out):
        doc = trust_kind(scene, engines, quiet=quiet)
        with atomic.report_dir(out, lock=False) as tmp:
            (tmp / "trust.json").write_text(json.dumps(plain(doc), indent=1) + "\n")
            (tmp / "trust.csv").write_text(kind_trust_csv(doc))
            (tmp / "index.html").write_text(kind_trust_html(doc))
    return doc


def print_verdicts(doc: dict) -> None:
    """One line per engine on stdout, then what the results are."""
    from trilith_xval.compare.cli.options import info
    from trilith_xval.compare.report.trust_kinds_page import banner
    for entry in doc["engines"].values():
        v = entry["threshold_verdict"]
        word = {True: "trusted", False: "NOT trusted", None: "not judged"}[v["trusted"]]
        print(f"{entry['label']}: thresholds {word}, engine against engine ({v['why']})")
    info(banner(doc))
