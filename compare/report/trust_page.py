"""The page and the CSV of ``trilith trust`` (:mod:`compare.campaign.trust_check`):
one column per engine, as the validation report's first screen (trust table,
then the measured points)."""
from __future__ import annotations

import html
import math

from trilith_xval.compare.report.cells import _cell, cause_phrase, csv_text, table
from trilith_xval.compare.report.trust import cost_text, fmt_pct, fmt_sci

__all__ = ["trust_rows", "trust_html", "trust_csv", "point_rows", "spectrum_figures"]


def _thresholds(entry: dict) -> dict:
    v = entry["threshold_verdict"]
    word = {True: "trusted", False: "not trusted", None: "not judged (model invalid)"}
    text = word[v["trusted"]]
    if v.get("finer_dt"):
        text = f"trusted at dt ≤ {fmt_sci(v['finer_dt'])} s"
    return _cell(text, v["trusted"], v["why"])


def _restitution(entry: dict) -> dict:
    rows = entry["restitution"]
    if not rows:
        return _cell("not measured")
    ok = all(r["passed"] for r in rows)
    text = "; ".join(f"{r['equation']}: " + ("no impacts" if r["max_rel_error"] is None else
                                               fmt_pct(abs(r["max_rel_error"])))
                     + f" (≤ {fmt_pct(r['tolerance'])})" for r in rows)
    return _cell(("trusted: " if ok else "not trusted: ") + text, ok)


def _histories(entry: dict) -> dict:
    rows = entry["histories"]
    if not rows:
        return _cell("not measured")
    ok = all(r["passed"] for r in rows)
    worst = max((r["theta_rms_first"] or math.inf for r in rows), default=math.inf)
    flips = [r for r in rows if not r["verdict_agrees"]]
    text = (f"{'trusted' if ok else 'not trusted'}: θ RMS to the first impact "
            f"≤ {fmt_sci(worst)} α" + (f"; {len(flips)} verdict(s) differ" if flips else ""))
    details = "; ".join(f"{r['case']} Ω {r['omega']:g} rad/s at {r['factor']:g}x: model "
                        f"{r['model']}, engine {r['engine']}" for r in rows)
    return _cell(text, ok, details)


def _records(entry: dict) -> dict:
    rows = entry.get("records")
    if not rows:
        return _cell("no record given")
    ok = all(r["passed"] for r in rows)
    return _cell(f"{sum(r['passed'] for r in rows)} of {len(rows)} records within 2 %", ok,
                 "; ".join(f"{r['record']}: model {r['im_model']}, engine {r['im_engine']}"
                           for r in rows))


def _settings(entry: dict) -> dict:
    where = ("calibrated; the scene is inside its domain" if entry["calibrated_inside"]
             and entry["threshold_dt"] != entry["reference_dt"] else
             "the reference step" + ("" if entry["calibrated_inside"]
                                     else ": the scene is outside the calibration's domain"))
    return _cell(f"thresholds at dt = {fmt_sci(entry['threshold_dt'])} s ({where}); "
                 f"restitution and θ(t) at {fmt_sci(entry['reference_dt'])} s", None,
                 entry.get("note", ""))


def _cost(entry: dict) -> dict:
    return _cell(cost_text(entry["cost"],
                           unmeasured="served by the run store (--no-cache measures it)"))


def trust_rows(doc: dict) -> tuple[list[str], list[list]]:
    """The trust table: one row per use, one column per engine."""
    engines = list(doc["engines"])
    header = ["use"] + [doc["engines"][e]["label"] for e in engines]
    spec = [("overturning thresholds (within 2 %)", _thresholds),
            ("restitution (Eq. 20; Eq. 19 with the pendulum)", _restitution),
            ("time histories (θ(t) before the first impact, verdicts)", _histories),
            ("ground motions (first overturning PGA)", _records),
            ("settings", _settings), ("cost", _cost)]
    return header, [[name] + [fn(doc["engines"][e]) for e in engines] for name, fn in spec]


def point_rows(doc: dict) -> tuple[list[str], list[list]]:
    header = ["engine", "curve", "Ω [rad/s]", "A model [m/s²]", "A engine [m/s²]", "error",
              "cause", "dt [s]"]
    rows = []
    for e, entry in doc["engines"].items():
        for p in entry["thresholds"]:
            err = "no bracket" if p["rel_error"] is None else f"{100 * p['rel_error']:+.2f} %"
            rows.append([entry["label"], p["case"].replace("_", " "), f"{p['omega']:.3g}",
                         f"{p['a_model']:.4g}",
                         "-" if p["a_engine"] is None else f"{p['a_engine']:.4g}", err,
                         _cell(cause_phrase(p["cause"]), _ok(p["cause"]), p["cause_detail"]),
                         fmt_sci(p["dt"])])
    return header, rows


def _ok(cause: str) -> bool | None:
    """Green where the engine agrees, plain where the model cannot judge it."""
    return True if cause == "agrees" else None if cause == "model" else False


def spectrum_figures(doc: dict) -> list[str]:
    """Per curve: the model's first-overturning spectrum (invalid frequencies
    hatched) with each engine's points and their error against the tolerance
    band, as the validation report draws them (base64 PNGs)."""
    from trilith_xval.compare.report import plots
    out = []
    for case, rows in doc["band"]["curves"].items():
        engines = []
        for e, entry in doc["engines"].items():
            pts = [p for p in entry["thresholds"] if p["case"] == case]
            engines.append({**plots._style_of(e),
                            "omega": plots._arr([p["omega"] for p in pts]),
                            "a": plots._arr([p["a_engine"] for p in pts]),
                            "error": 100.0 * plots._arr([p["rel_error"] for p in pts])})
        data = {"title": f"{doc['scene'].get('name')}: "
                         + ("with pendulum" if case == "pendulum" else "without pendulum"),
                "tol": 100.0 * doc["tolerances"]["threshold"],
                "omega": plots._arr([r["omega"] for r in rows]),
                "a": plots._arr([r["a_model"] for r in rows]),
                "valid": [r["valid"] for r in rows], "breaks": [], "jumps": [],
                "engines": engines}
        out.append(plots._figure("trust-spectrum", data, plots._draw_spectrum))
    return out


def trust_csv(doc: dict) -> str:
    """Every threshold point of every engine, one row each."""
    return csv_text(*point_rows(doc))


def _consensus_section(doc: dict) -> str:
    """Where the model is invalid: the engines against each other (two or more)."""
    from trilith_xval.compare.report.atlas_consensus_page import (CONSENSUS_HEAD,
                                                                   consensus_row,
                                                                   consensus_table)
    found = doc.get("consensus")
    if found is None:
        return ""
    if not found:
        return ("<h2>Where the model is invalid</h2><p>No frequency of the grid where the "
                "model is invalid and the engines can answer.</p>")
    rows = [consensus_row(c["case"], c["omega"], c["a_model"], c) for c in found]
    return ("<h2>Where the model is invalid: engine against engine</h2><p>Each engine's own "
            "first failure (overturn or collapse), converged in the step (two steps within "
            "1 %), against the other engines' median; never agreement with the model, which "
            "cannot judge there.</p>" + consensus_table(CONSENSUS_HEAD, rows))


def trust_html(doc: dict) -> str:
    from trilith_xval.compare.report.html import _CSS
    esc = html.escape
    sc = doc["scene"]
    band = doc["band"]
    valid = {c: sum(r["valid"] is not False and r["a_model"] is not None for r in rows)
             for c, rows in band["curves"].items()}
    header, rows = trust_rows(doc)
    words = ", ".join(f"{k} = {sc[k]:g}" for k in ("lam", "b", "mu", "gamma")
                      if isinstance(sc.get(k), (int, float)))
    body = [f"<h1>Which engine to trust on <code>{esc(str(sc.get('name')))}</code></h1>",
            f"<p class='headline'>{esc(words)} (lam: slenderness h/b; b: column width [m]; "
            "mu: lintel/column mass ratio; gamma: pendulum/column mass ratio). The model is "
            "valid at " + ", ".join(f"{n} of {len(band['omegas'])} frequencies "
                                   f"({c.replace('_', ' ')})" for c, n in valid.items())
            + f" of Ω = {band['omegas'][0]:.3g}-{band['omegas'][-1]:.3g} rad/s "
              f"({band['omegas'][0] / (2 * math.pi):.2g}-"
              f"{band['omegas'][-1] / (2 * math.pi):.2g} Hz).</p>",
            "<h2>Trust table</h2>", table(header, rows),
            "<h2>Threshold points</h2>",
            "<div class='figs'>" + "".join(
                f"<img alt='overturning spectrum and engine points' "
                f"src='data:image/png;base64,{png}'>" for png in spectrum_figures(doc))
            + "</div>", table(*point_rows(doc)), _consensus_section(doc),
            f"<p class='small'>{esc(doc['project'])}; CPU {doc['cost']['cpu_s']:.1f} s in "
            f"this process, wall {doc['cost']['wall_s']:.1f} s, load average "
            + ", ".join(f"{x:.2f}" for x in doc['cost']['load_average']) + ".</p>"]
    return ("<!doctype html><html lang='en'><head><meta charset='utf-8'><meta name='viewport' "
            "content='width=device-width,initial-scale=1'><title>trilith-xval trust: "
            f"{esc(str(sc.get('name')))}</title><style>{_CSS}</style></head><body>"
            + "".join(body) + "</body></html>\n")
