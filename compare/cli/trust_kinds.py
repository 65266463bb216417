"""``trilith trust`` (and ``trilith report``) on a scene of another kind: the
engines' consensus (:mod:`compare.campaign.trust_kinds`) written as trust.json,
trust.csv and index.html, whole."""
from __future__ import annotations

import json

from trilith_xval.compare.cli.options import check_structure_engines

__all__ = ["check_kind_trust", "write_kind_trust", "print_verdicts"]


def check_kind_trust(scene, engines, command: str) -> None:
    """The door for a kind (before any work): two or more engines that build the
    body list (one engine alone has nothing to be judged against; as map,
    fragility and restitution, it is refused rather than measured for minutes)."""
    check_structure_engines(engines, scene.kind, command)
    if len(engines) < 2:
        raise ValueError(f"trilith {command}: there is no model of the {scene.kind} kind; "
                         f"--engine needs two or more engines to judge against each other, "
                         f"got {','.join(engines) or 'none'}")


def write_kind_trust(scene, engines, out, quiet: bool, records=()) -> dict:
    """Measure (:func:`compare.campaign.trust_kinds.trust_kind`) and write ``out``
    whole (:mod:`compare.run.atomic`); returns the document."""
    from trilith_xval.compare.campaign.trust_kinds import trust_kind
    from trilith_xval.compare.report.trust_kinds_page import kind_trust_csv, kind_trust_html
    from trilith_xval.compare.run import atomic
    from trilith_xval.compare.run.jsonable import plain
    with atomic.output_lock(out):
        doc = trust_kind(scene, engines, records=records, quiet=quiet)
        with atomic.report_dir(out, lock=False) as tmp:
            (tmp / "trust.json").write_text(json.dumps(plain(doc), indent=1) + "\n")
            (tmp / "trust.csv").write_text(kind_trust_csv(doc))
            (tmp / "index.html").write_text(kind_trust_html(doc))
    return doc


def print_verdicts(doc: dict) -> None:
    """One line per engine on stdout, then what the results are."""
    from trilith_xval.compare.cli.options import info
    from trilith_xval.compare.report.trust_kinds_page import banner
    words = {True: "trusted", False: "NOT trusted", None: "not judged"}
    for entry in doc["engines"].values():
        for use, key in (("thresholds", "threshold_verdict"), ("ground motions",
                                                               "record_verdict")):
            v = entry.get(key)
            if v is not None:
                print(f"{entry['label']}: {use} {words[v['trusted']]}, engine against engine "
                      f"({v['why']})")
    info(banner(doc))
