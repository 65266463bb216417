"""The page and the CSV of ``trilith trust`` on a scene of another kind
(:mod:`compare.campaign.trust_kinds`): engine against engine, shaped as the
trilith's trust page (:mod:`compare.report.trust_page`): a banner, the trust
table (one column per engine), the consensus table, the measured points."""
from __future__ import annotations

import html

from trilith_xval.compare.report.cells import _cell, csv_text, table
from trilith_xval.compare.report.trust import cost_text, fmt_sci

__all__ = ["banner", "kind_trust_rows", "kind_point_rows", "kind_trust_csv", "kind_trust_html"]


def banner(doc: dict) -> str:
    """The page's first line: what every result is."""
    return (f"engine against engine: the model does not cover the {doc['kind']} kind; every "
            "result is the engines checked against each other, never agreement with a model")


def _thresholds(entry: dict) -> dict:
    v = entry["threshold_verdict"]
    word = {True: "trusted (engine against engine)", False: "not trusted",
            None: "not judged (no consensus)"}[v["trusted"]]
    return _cell(word, v["trusted"], v["why"])


def _histories(entry: dict) -> dict:
    v = entry["history_verdict"]
    word = {True: "agrees with the others", False: "the engines differ",
            None: "not judged"}[v["agrees"]]
    return _cell(word, v["agrees"], v["why"])


def _records(entry: dict) -> dict:
    v = entry.get("record_verdict")
    if v is None:
        return _cell("no record given (--record)")
    word = {True: "trusted (engine against engine)", False: "not trusted",
            None: "not judged (no consensus)"}[v["trusted"]]
    return _cell(word, v["trusted"], v["why"])


def _settings(entry: dict) -> dict:
    return _cell(f"thresholds at dt = {fmt_sci(entry['threshold_dt'])} s, converged in the "
                 f"step from there; time histories at {fmt_sci(entry['reference_dt'])} s",
                 None, entry.get("note", ""))


def _cost(entry: dict) -> dict:
    return _cell(cost_text(entry["cost"], unmeasured="no point measured",
                           per_point=" (its step ladder included)"))


def kind_trust_rows(doc: dict) -> tuple[list[str], list[list]]:
    """The trust table: one row per use, one column per engine."""
    engines = list(doc["engines"])
    header = ["use"] + [doc["engines"][e]["label"] for e in engines]
    no = doc["no_model"]
    spec = [("first-failure thresholds (within 2 % of the engines' median)", _thresholds),
            ("restitution", lambda e: _cell("does not exist (no model)", None,
                                            no["restitution"])),
            ("time histories against the model", lambda e: _cell("do not exist (no model)", None,
                                                                 no["model_theta"])),
            ("time histories, engine against engine (survive or fail at 0.9x, 1.1x the "
             "consensus)", _histories),
            ("ground motions (first failing PGA, within 2 % of the engines' median)",
             _records),
            ("settings", _settings), ("cost", _cost)]
    return header, [[name] + [fn(doc["engines"][e]) for e in engines] for name, fn in spec]


def kind_point_rows(doc: dict) -> tuple[list[str], list[list]]:
    """Every engine's own first failure at every frequency, one row each."""
    header = ["engine", "Ω [rad/s]", "A fails [m/s²]", "A survives [m/s²]",
              "vs the median", "failure", "dt [s]", "CPU [s]", "answer"]
    rows = []
    for p in doc["points"]:
        for e, entry in doc["engines"].items():
            own = p.get("own", {}).get(e) or {}
            row = p["engines"].get(e)
            miss = [n for n in p["no_answer"] if n["engine"] == e]
            answer = (f"no answer: {miss[0]['cause']} ({miss[0]['detail']})" if miss else
                      "outlier" if any(o["engine"] == e for o in p["outliers"]) else p["status"])
            rows.append([entry["label"], f"{p['omega']:.4g}",
                         "-" if own.get("a_fails") is None else f"{own['a_fails']:.4g}",
                         "-" if own.get("a_survives") is None else f"{own['a_survives']:.4g}",
                         "-" if row is None else f"{100 * row['deviation']:+.2f} %",
                         own.get("failure") or "-",
                         "-" if own.get("dt") is None else fmt_sci(own["dt"]),
                         "-" if own.get("cpu_s") is None else f"{own['cpu_s']:.1f}", answer])
    return header, rows


def _history_rows(doc: dict) -> tuple[list[str], list[list]]:
    engines, body = list(doc["engines"]), doc["histories"][0]["body"]
    header = (["Ω [rad/s]", "x consensus", "A [m/s²]"]
              + [f"{doc['engines'][e]['label']}: verdict, peak |θ| of {body}" for e in engines]
              + ["every engine agrees"])
    rows = []
    for h in doc["histories"]:
        cells = []
        for e in engines:
            r = h["engines"][e]
            peak = "-" if r["peak_rad"] is None else (f"{r['peak_rad']:.3g} rad "
                                                      f"({r['peak_over_alpha']:.2f} α)")
            cells.append(f"{r['status']}, {peak}")
        rows.append([f"{h['omega']:.4g}", f"{h['factor']:g}", f"{h['amplitude']:.4g}", *cells,
                     _cell("yes" if h["agree"] else "no", h["agree"])])
    return header, rows


def kind_trust_csv(doc: dict) -> str:
    """Every engine's own first failure at every frequency, one row each."""
    return csv_text(*kind_point_rows(doc))


def kind_trust_html(doc: dict) -> str:
    from trilith_xval.compare.report.atlas_consensus_page import (CONSENSUS_HEAD,
                                                                   consensus_row,
                                                                   consensus_table)
    from trilith_xval.compare.report.html import _CSS
    esc = html.escape
    sc, d = doc["scene"], doc["design"]
    # One-sine pulses only: the atlas's case column is dropped; the guess is the scan's.
    head = CONSENSUS_HEAD[1:2] + ["scan's guess [m/s²]"] + CONSENSUS_HEAD[3:]
    cons = [consensus_row("", p["omega"], p["a_guess"], p)[1:] for p in doc["points"]]
    recs = "".join([
        "<h2>Ground motions: engine against engine</h2><p>Each engine's own first failing "
        "PGA of each record (the record scaled; every run over the record and "
        f"{esc(str(doc.get('record_tail', '')))} s after it), converged in the step, "
        "and their median.</p>",
        consensus_table(["record", "scan's guess [m/s²]"] + CONSENSUS_HEAD[3:],
                        [[r["record"]] + consensus_row("", 0.0, r["a_guess"], r)[2:]
                         for r in doc["records"]])] if doc["records"] else [])
    hist = (table(*_history_rows(doc)) if doc["histories"] else
            "<p>No frequency with a consensus threshold: no time histories.</p>")
    body = [f"<h1>Which engine to trust on <code>{esc(str(sc.get('name')))}</code> "
            f"({esc(doc['kind'])})</h1>",
            f"<p class='banner'>{esc(banner(doc))}.</p>",
            f"<p class='headline'>Threshold design: {len(d['omegas'])} frequencies, "
            f"{d['over_p'][0]:.3g}-{d['over_p'][-1]:.3g} p spaced geometrically, p = "
            f"{d['p']:.3g} rad/s the slowest stack's rocking frequency parameter "
            f"(sqrt(3 g / 4 R), R = {d['R']:.3g} m, the stack on "
            f"<code>{esc(d['stack'])}</code>): Ω = "
            + ", ".join(f"{w:.3g}" for w in d["omegas"]) + " rad/s. At each, every engine's "
            "own first failure (overturn or collapse) converged in the step (two steps within "
            f"{100 * doc['tolerances']['step_agree']:g} %), and their median; the search "
            f"starts from a scan of the first engine ({d['scan_runs']} runs).</p>",
            "<p>" + esc(doc["no_model"]["restitution"]) + ".<br>"
            + esc(doc["no_model"]["model_theta"]) + ".</p>",
            "<h2>Trust table</h2>", table(*kind_trust_rows(doc)),
            "<h2>Consensus: engine against engine</h2>", consensus_table(head, cons),
            "<h2>Time histories: engine against engine</h2>", hist, recs,
            "<h2>Each engine's own first failure</h2>", table(*kind_point_rows(doc)),
            f"<p class='small'>{esc(doc['project'])}; CPU {doc['cost']['cpu_s']:.1f} s in "
            f"this process, wall {doc['cost']['wall_s']:.1f} s, load average "
            + ", ".join(f"{x:.2f}" for x in doc['cost']['load_average']) + ".</p>"]
    return ("<!doctype html><html lang='en'><head><meta charset='utf-8'><meta name='viewport' "
            "content='width=device-width,initial-scale=1'><title>trilith-xval trust: "
            f"{esc(str(sc.get('name')))} (engine against engine)</title><style>{_CSS}</style>"
            "</head><body>" + "".join(body) + "</body></html>\n")
