"""``trilith fragility`` on a scene the model does not cover (:mod:`analytic.kinds`:
drums, unequal columns, a block on a block): the engines against each other.

There is no model IDA, so each engine gives its own first failing intensity of
every record (an overturn or a collapse, :mod:`engines.structure_monitor`): a scan
from the structure's static uplift bound, then the robust bracket converged in the
step (:mod:`compare.measure.record_kinds`).  Then per engine the empirical curve and
the lognormal fit with its bootstrap band (:mod:`compare.measure.fragility`), and
per record the engines' consensus (:func:`compare.measure.consensus.consensus`: the
median, each engine's deviation, outliers beyond 2 % among three or more engines).
No model curve is drawn or claimed: engine against engine, never agreement with
the model.
"""
from __future__ import annotations

__all__ = ["check_kind_engines", "record_consensus", "print_kind_header", "print_kind_fragility"]


def check_kind_engines(scene, engines_: tuple[str, ...], args) -> None:
    """One line refusing, before any work, what ``trilith fragility`` cannot do on
    a scene of another kind: fewer than two engines (one engine has nobody to be
    checked against), an engine that does not build the body list, ``--stripes``
    (the multiple-stripe analysis is the model's comparison)."""
    from trilith_xval.compare.cli.options import check_structure_engines
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    kind = scene.kind
    if len(engines_) < 2:
        raise ValueError(f"trilith fragility: there is no model of the {kind} kind (scene "
                         f"{scene.name!r}); --engine needs two or more engines to check "
                         f"against each other ({', '.join(STRUCTURE_ENGINES)}), got "
                         f"{','.join(engines_) or 'none'}")
    check_structure_engines(engines_, kind, "fragility")
    if args.stripes is not None:
        raise ValueError(f"--stripes: the multiple-stripe analysis is not run on the {kind} "
                         "kind (no model to compare it with); leave it out")


def _own(row: dict, im_hi: float) -> dict:
    """A record row of :func:`compare.measure.record_kinds.own_intensity` in the shape
    :func:`compare.measure.consensus.consensus` reads."""
    ok = row["bracketed"] and not row["censored"] and row["im_overturn"] is not None
    cause, detail = row.get("cause"), row.get("detail")
    if row["censored"]:
        cause, detail = "censored", f"no failure up to {im_hi:g}"
    return {"converged": ok, "a_fails": row["im_overturn"], "failure": row.get("failure"),
            "dt": row.get("dt"), "cause": None if ok else cause, "detail": detail}


def record_consensus(doc: dict, im_hi: float) -> list[dict]:
    """Per record of ``doc`` (a fragility summary, engines only) the engines'
    consensus on its first failing intensity.  An outlier's cause is ``collapse``
    or ``overturn`` when it failed otherwise than the majority, else ``unknown``
    (the pulse cause search, :func:`compare.measure.consensus.outlier_cause`, is
    not run on records)."""
    from trilith_xval.compare.measure.consensus import consensus
    out = []
    for i, rec in enumerate(doc["records"]):
        owns = {b: _own(body["records"][i], im_hi) for b, body in doc["backends"].items()}
        first = consensus(owns)
        causes = {o["engine"]: ("collapse" if owns[o["engine"]]["failure"] == "collapsed"
                                else "overturn")
                  for o in first["outliers"]
                  if owns[o["engine"]]["failure"] != first["failure"]}
        out.append({"record": rec["label"], **consensus(owns, causes)})
    return out


def print_kind_header(doc: dict) -> None:
    """The first line of a kind's result: what the curves are, and are not."""
    print(f"scene {doc['scene'].get('name', '')} ({doc['kind']}): no model; each engine's own "
          "first failing intensity (overturn or collapse) per record, converged in the step; "
          "engine against engine, never agreement with a model")


def print_kind_fragility(doc: dict, st) -> None:
    """The per-record consensus table and the closing line of a kind's result."""
    from trilith_xval.analytic.ida import IM_UNITS
    from trilith_xval.compare.cli.options import info
    from trilith_xval.compare.cli.spectrum_kinds import print_consensus_table
    unit = IM_UNITS[st.im] or "-"
    names = list(doc["backends"])
    print_consensus_table(doc["consensus"], names, ("record", 16), unit,
                          lambda p: f"{p['record'][:16]:>16}", lambda p: p["record"], col=16)
    steps = sorted({r["dt"] for body in doc["backends"].values() for r in body["records"]
                    if r.get("dt") is not None})
    info(f"steps of the answers: {', '.join(f'{d:.3g} s' for d in steps) or '-'} (each "
         "converged: twice the step and the step agree within 1 %)")
    info("engine against engine, never agreement with a model (docs/geometry.md)")
