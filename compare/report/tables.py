"""The validation report's tables: rows built from the summary document
(``summary.json``), rendered as HTML or Markdown by :func:`table`.  Used by
:mod:`compare.report.html`."""
from __future__ import annotations

import html
import math


from compare.report.trust import fmt_pct, fmt_sci, fmt_seconds, label

__all__ = ["HEADERS", "table", "error_rows", "history_rows", "jump_rows", "provenance_rows",
           "restitution_rows", "threshold_rows", "timing_rows", "trust_rows", "verdict_rows"]

_JOBS = {"threshold": "overturning thresholds (bisections)", "history": "time histories A-D",
         "restitution": "free-rocking restitution", "jump": "mode-jump frequency"}
_TIMINGS = {"reference_spectra": "reference spectra (analytic model, both curves)",
            "engine_runs_wall": "all jobs, wall time (parallel)",
            "total": "whole campaign, wall time"}


# ---------------------------------------------------------------- formatting
def _value(v: dict) -> str:
    """A verdict value in the unit of its tolerance: percent, alpha or a count."""
    x, unit = v.get("value"), v.get("unit")
    if x is None:
        return "not measured"
    if unit == "relative":
        return fmt_pct(x)
    if unit == "fraction of alpha":
        return f"{fmt_sci(x)} α"
    return str(x)


def _tolerance(v: dict) -> str:
    unit, tol = v.get("unit"), v.get("tolerance")
    if unit == "relative":
        return f"≤ {fmt_pct(tol)}"
    if unit == "fraction of alpha":
        return f"≤ {fmt_sci(tol)} α"
    return f"≤ {tol}"


def _num(x, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return f"{x:.{digits}g}" if isinstance(x, float) else str(x)


def _status(status, mode) -> str:
    return f"{status} ({mode})" if mode else str(status)


def _cell(text: str, ok: bool | None = None) -> dict:
    return {"text": text, "ok": ok}


def table(header: list[str], rows: list[list], md: bool = False) -> str:
    """HTML (in a horizontally scrolling wrapper) or Markdown table.  A cell is a
    string or :func:`_cell` (coloured pass/fail)."""
    def text(c):
        return c["text"] if isinstance(c, dict) else c

    if md:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(text(c).replace("|", "/") for c in r) + " |" for r in rows]
        return "\n".join(lines)

    def td(c):
        ok = c.get("ok") if isinstance(c, dict) else None
        cls = "" if ok is None else (" class='pass'" if ok else " class='fail'")
        return f"<td{cls}>{html.escape(text(c))}</td>"

    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(td(c) for c in r) + "</tr>" for r in rows)
    return f"<div class='scroll'><table><tr>{head}</tr>{body}</table></div>"


# ---------------------------------------------------------------- tables
def trust_rows(doc: dict) -> tuple[list[str], list[list]]:
    trust = doc["trust"]
    engines = list(trust)
    tols = doc["config"]["tolerances"]
    header = ["check (tolerance)"] + [trust[e]["label"] for e in engines]

    def verdict_cell(row, key):
        v = row.get(key)
        return _cell("not measured") if v is None else _cell(_value(v), v["passed"])

    def thresholds(row):
        t = row["thresholds"]
        if not t["n_points"]:
            return _cell("not measured")
        if t["agree_up_to"] is None:
            text = "none agree"
        else:
            lo, hi = t["omega_range"]
            text = f"A ≤ {t['agree_up_to']:.3g} m/s² (Ω {lo:g}-{hi:g} rad/s)"
        return _cell(f"{text}; {t['n_agree']} of {t['n_points']} points",
                     t["n_agree"] == t["n_points"])

    def causes(row):
        t = row["thresholds"]
        if not t["n_points"]:
            return _cell("not measured")
        if not t["failing"]:
            return _cell("all agree")
        measured = any(p.get("cause") for p in t["failing"])
        parts = []
        for p in t["failing"]:
            err = "not bracketed" if p["rel_error"] is None else f"{100 * p['rel_error']:+.2g} %"
            where = f"Ω {p['omega']:g}{'' if p['case'] == 'pendulum' else ' (no pend.)'}"
            cause = ""
            if measured:
                cause = f", {p.get('cause') or 'not measured'}"
                cause += f" ({p['cause_detail']})" if p.get("cause_detail") else ""
            parts.append(f"{where}: {err}{cause}")
        text = "; ".join(parts)
        return _cell(text if measured else f"not measured ({text})", False)

    def ad(row):
        v = row.get("verdicts_AD")
        if v is None or v["value"] is None:
            return _cell("not measured")
        n = v.get("n_cases") or 0
        return _cell(f"{n - v['value']} of {n} agree", v["passed"])

    def cost(row, key):
        c = row["cost"]
        if key == "run":
            return _cell(fmt_seconds(c["run_s"]))
        if c["threshold_point_s"] is None:
            return _cell("not measured")
        return _cell(f"{fmt_seconds(c['threshold_point_s'])} per point "
                     f"({c['runs_per_point']:.2g} runs); ≈ {fmt_seconds(c['spectrum_s'])} for "
                     f"{c['spectrum_frequencies']} frequencies")

    def settings(row):
        return _cell(", ".join(f"{k} = {fmt_sci(v)}" if isinstance(v, float) else f"{k} = {v}"
                               for k, v in row["settings"].items()) or "defaults")

    spec = [("restitution vs Eq. 20, worst impact", f"≤ {fmt_pct(tols['restitution'])}",
             lambda r: verdict_cell(r, "restitution_eq20")),
            ("restitution vs Eq. 19 at the measured ψ",
             f"≤ {fmt_pct(tols['restitution_pendulum'])}",
             lambda r: verdict_cell(r, "restitution_eq19")),
            ("the paper's verdicts at A-D, status and mode", "all must agree", ad),
            ("θ(t) RMS error before the first impact", f"≤ {fmt_sci(tols['theta_rms_first'])} α",
             lambda r: verdict_cell(r, "theta_first_impact")),
            ("overturning thresholds agree up to", f"within {fmt_pct(tols['threshold'])}",
             thresholds),
            ("where thresholds disagree: measured cause", "", causes),
            ("cost per run: median wall time at A-D", "", lambda r: cost(r, "run")),
            ("cost per threshold point and per spectrum", "", lambda r: cost(r, "spectrum")),
            ("settings that achieve it", "", settings),
            ("verdicts passed", "", lambda r: _cell(
                f"{r['verdicts']['passed']} of {r['verdicts']['total']}",
                r["verdicts"]["passed"] == r["verdicts"]["total"]))]
    rows = [[f"{name} ({tol})" if tol else name] + [fn(trust[e]) for e in engines]
            for name, tol, fn in spec]
    return header, rows


def verdict_rows(doc: dict) -> list[list]:
    return [[v.get("id", ""), label(v["backend"]), _cell(_value(v), v["passed"]), _tolerance(v),
             _cell("pass" if v["passed"] else "FAIL", v["passed"]), v["metric"],
             f"{v.get('detail', '')}. {v['reason']}"] for v in doc["verdicts"]]


def threshold_rows(doc: dict) -> list[list]:
    tol = doc["config"]["tolerances"]["threshold"]
    rows = []
    for case, spec in doc["spectra"].items():
        for name, pts in spec.get("engines", {}).items():
            for p in pts:
                err = p.get("rel_error")
                ok = err is not None and abs(err) <= tol
                rows.append([case.replace("_", " "), label(name), _num(p["omega"]),
                             _num(p["a_reference"]), _num(p["a_engine"]),
                             _cell("n/a" if err is None else f"{100 * err:+.3g} %", ok),
                             f"{p['mode_reference']} / {p['mode_engine']}", str(p["n_runs"]),
                             p.get("cause") or "not measured",
                             fmt_seconds(p.get("provenance", {}).get("wall_time"))])
    return rows


def jump_rows(doc: dict) -> list[list]:
    return [[case.replace("_", " "), label(name), _num(j["amplitude"]),
             _num(j["omega_reference"]), _num(j["omega_engine"]), _num(j.get("shift")),
             str(j["n_runs"])]
            for case, spec in doc["spectra"].items()
            for name, j in spec.get("jump_shifts", {}).items()]


def history_rows(doc: dict) -> list[list]:
    tol = doc["config"]["tolerances"]["theta_rms_first"]
    rows = []
    for c in doc["comparisons"]:
        rms = c.get("theta_rms_first")
        rows.append([c["point"], "yes" if c["pendulum"] else "no", label(c["backend"]),
                     _status(c["status_reference"], c["mode_reference"]),
                     _cell(_status(c["status_test"], c["mode_test"]), c["verdict_agrees"]),
                     _cell("n/a" if rms is None else f"{fmt_sci(rms)} α",
                           None if rms is None else rms <= tol),
                     "n/a" if c.get("theta_max_all") is None else f"{fmt_sci(c['theta_max_all'])} α",
                     "n/a" if c.get("uplift_time_error") is None
                     else f"{1e3 * c['uplift_time_error']:+.3g} ms",
                     fmt_seconds(c["test"].get("wall_time"))])
    return rows


def restitution_rows(doc: dict) -> list[list]:
    tols = doc["config"]["tolerances"]
    rows = []
    for r in doc["restitution"]:
        tol = tols["restitution_pendulum" if r["pendulum"] else "restitution"]
        err = r.get("max_rel_error")
        rows.append([label(r["backend"]), _num(r["lam"]), _num(r["mu"]), _num(r["gamma"]),
                     r["equation"], str(len(r["impacts"])),
                     _cell("no impact" if err is None or not r["impacts"] else fmt_pct(err, 3),
                           err is not None and bool(r["impacts"]) and err <= tol)])
    return rows


def timing_rows(doc: dict) -> list[list]:
    t = doc["timings"]
    rows = [[_TIMINGS.get(k, k.replace("_", " ")), fmt_seconds(v)] for k, v in t.items()
            if not isinstance(v, dict)]
    for key, v in t.get("cpu_by_job", {}).items():
        kind, _, name = key.partition(":")
        rows.append([f"{_JOBS.get(kind, kind)}, {label(name)} (summed over runs)",
                     fmt_seconds(v)])
    return rows


def provenance_rows(doc: dict) -> list[list]:
    p = doc.get("provenance") or {}
    rows = [[k, str(p[k])] for k in ("date", "commit", "command") if k in p]
    rows += [[f"version: {k}", str(v)] for k, v in p.get("versions", {}).items()]
    rows += [[f"machine: {k}", str(v)] for k, v in p.get("machine", {}).items()]
    rows.append(["scene", doc["config"]["scene"]])
    return rows or [["provenance", "not recorded"]]


HEADERS = {"verdicts": ["id", "engine", "value", "tolerance", "result", "metric", "detail and reason"],
      "thresholds": ["case", "engine", "Ω [rad/s]", "A model [m/s²]", "A engine [m/s²]",
                     "error", "mode (model / engine)", "runs", "cause", "wall"],
      "jumps": ["case", "engine", "probe A [m/s²]", "Ω jump model", "Ω jump engine",
                "shift [rad/s]", "runs"],
      "histories": ["point", "pendulum", "engine", "verdict (model)", "verdict (engine)",
                    "θ RMS error before 1st impact", "θ max error (whole run)",
                    "uplift time error", "wall"],
      "restitution": ["engine", "λ", "μ", "γ", "equation", "impacts", "worst error"],
      "timings": ["what", "time"],
      "errors": ["job", "engine", "pendulum", "label", "error"],
      "provenance": ["what", "value"]}


def error_rows(doc: dict) -> list[list]:
    return [[e["job"], label(e["backend"]), "yes" if e["pendulum"] else "no",
             " ".join(e["label"]), e["error"]] for e in doc["errors"]]
