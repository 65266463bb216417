"""Writing the validation report: ``index.html`` (self-contained), ``summary.json``,
``summary.md``.

The first screen answers "which engine can I trust, for what, up to where, at
what cost": the trust table (:mod:`compare.trust`, computed from the summary
document) and a conclusion per engine.  The evidence follows (plots with error
panels, :mod:`compare.report_plots`, and tables), then provenance and, folded
away, the raw settings.  Plots are PNGs embedded as base64 data URIs: the HTML
opens offline with no server and no side files.

``summary.json`` carries ``schema_version``, ``quick``, ``provenance``, the
``trust`` table and verdict rows with stable ``id`` s
(:data:`compare.verdicts.VERDICT_IDS`).
"""
from __future__ import annotations

import html
import json
import math
from pathlib import Path

from . import atomic
from . import report_plots as plots
from scenes import POINTS

from .jsonable import plain as clean_nan
from .metrics import _plain
from .trust import fmt_pct, fmt_sci, fmt_seconds, label, trust_table

__all__ = ["write_report", "render_html", "render_markdown", "summary_dict", "SCHEMA_VERSION"]

# 2: schema_version, quick, provenance, trust, verdict ids (1 had none of them).
SCHEMA_VERSION = 2
_JOBS = {"threshold": "overturning thresholds (bisections)", "history": "time histories A-D",
         "restitution": "free-rocking restitution", "jump": "mode-jump frequency"}
_TIMINGS = {"reference_spectra": "reference spectra (analytic model, both curves)",
            "engine_runs_wall": "all jobs, wall time (parallel)",
            "total": "whole campaign, wall time"}


def summary_dict(result, provenance: dict | None = None) -> dict:
    """``summary.json``: strict JSON (non-finite numbers become null)."""
    doc = clean_nan(_plain(result.to_dict()))
    prov = provenance or {}
    out = {"schema_version": SCHEMA_VERSION, "quick": bool(prov.get("quick", False)),
           "provenance": prov, **doc}
    out["trust"] = trust_table(out)
    return out


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


def _table(header: list[str], rows: list[list], md: bool = False) -> str:
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
def _trust_rows(doc: dict) -> tuple[list[str], list[list]]:
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


def _verdict_rows(doc: dict) -> list[list]:
    return [[v.get("id", ""), label(v["backend"]), _cell(_value(v), v["passed"]), _tolerance(v),
             _cell("pass" if v["passed"] else "FAIL", v["passed"]), v["metric"],
             f"{v.get('detail', '')}. {v['reason']}"] for v in doc["verdicts"]]


def _threshold_rows(doc: dict) -> list[list]:
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


def _jump_rows(doc: dict) -> list[list]:
    return [[case.replace("_", " "), label(name), _num(j["amplitude"]),
             _num(j["omega_reference"]), _num(j["omega_engine"]), _num(j.get("shift")),
             str(j["n_runs"])]
            for case, spec in doc["spectra"].items()
            for name, j in spec.get("jump_shifts", {}).items()]


def _history_rows(doc: dict) -> list[list]:
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


def _restitution_rows(doc: dict) -> list[list]:
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


def _timing_rows(doc: dict) -> list[list]:
    t = doc["timings"]
    rows = [[_TIMINGS.get(k, k.replace("_", " ")), fmt_seconds(v)] for k, v in t.items()
            if not isinstance(v, dict)]
    for key, v in t.get("cpu_by_job", {}).items():
        kind, _, name = key.partition(":")
        rows.append([f"{_JOBS.get(kind, kind)}, {label(name)} (summed over runs)",
                     fmt_seconds(v)])
    return rows


def _provenance_rows(doc: dict) -> list[list]:
    p = doc.get("provenance") or {}
    rows = [[k, str(p[k])] for k in ("date", "commit", "command") if k in p]
    rows += [[f"version: {k}", str(v)] for k, v in p.get("versions", {}).items()]
    rows += [[f"machine: {k}", str(v)] for k, v in p.get("machine", {}).items()]
    rows.append(["scene", doc["config"]["scene"]])
    return rows or [["provenance", "not recorded"]]


_H = {"verdicts": ["id", "engine", "value", "tolerance", "result", "metric", "detail and reason"],
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


def _headline(doc: dict) -> str:
    n = len(doc["verdicts"])
    n_pass = sum(bool(v["passed"]) for v in doc["verdicts"])
    return f"{n_pass} of {n} verdicts pass" + (" (QUICK run)" if doc.get("quick") else "")


_QUICK = ("QUICK RUN: smaller grids (one threshold frequency per curve, fewer restitution "
          "cases, no mode-jump probe); not the full campaign's verdicts.")


# ---------------------------------------------------------------- documents
def render_markdown(doc: dict) -> str:
    """``summary.md`` from the summary document."""
    header, rows = _trust_rows(doc)
    parts = [f"# Validation report: scene `{doc['config']['scene']}`"]
    if doc.get("quick"):
        parts.append(f"**{_QUICK}**")
    parts += [f"{_headline(doc)}.", "## Which engine to trust", _table(header, rows, md=True),
              *(f"- {r['conclusion']}" for r in doc["trust"].values()),
              "## Verdicts", _table(_H["verdicts"], _verdict_rows(doc), md=True),
              "## Overturning thresholds (away from mode jumps)",
              _table(_H["thresholds"], _threshold_rows(doc), md=True)]
    if _jump_rows(doc):
        parts += ["## Mode-jump frequency shift", _table(_H["jumps"], _jump_rows(doc), md=True)]
    parts += ["## Restitution", _table(_H["restitution"], _restitution_rows(doc), md=True),
              "## Time histories A-D", _table(_H["histories"], _history_rows(doc), md=True),
              "## Run times", _table(_H["timings"], _timing_rows(doc), md=True)]
    if doc["errors"]:
        parts += ["## Runs that raised", _table(_H["errors"], _error_rows(doc), md=True)]
    parts += ["## Provenance", _table(_H["provenance"], _provenance_rows(doc), md=True)]
    return "\n\n".join(parts) + "\n"


def _error_rows(doc: dict) -> list[list]:
    return [[e["job"], label(e["backend"]), "yes" if e["pendulum"] else "no",
             " ".join(e["label"]), e["error"]] for e in doc["errors"]]


_CSS = """*{box-sizing:border-box}
body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;max-width:1100px;margin:auto;
padding:0.8em;line-height:1.4;color:#111;overflow-wrap:break-word}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
img{max-width:100%;height:auto;display:block;margin:0.6em 0}
.scroll{overflow-x:auto;max-width:100%;margin:0.5em 0}
table{border-collapse:collapse;font-size:13px}
td,th{border:1px solid #bbb;padding:3px 6px;vertical-align:top;text-align:left}
th{background:#eee}td.pass{background:#d4edda}td.fail{background:#f8d7da}
.banner{background:#fff3cd;border:2px solid #d39e00;padding:0.6em;font-weight:bold}
.headline{font-size:1.1em}.small{font-size:0.85em;color:#444}.conclusion{margin:0.4em 0 0.8em 0}
pre{white-space:pre-wrap;overflow-wrap:anywhere;font-size:11px;background:#f6f6f6;padding:0.5em}
code{overflow-wrap:anywhere}
td{overflow-wrap:anywhere}
@media (max-width:600px){body{padding:0.4em}table{font-size:11px}td,th{padding:2px 3px}}
@media print{body{max-width:none;padding:0}.scroll{overflow:visible}
td.pass,td.fail,th,.banner{-webkit-print-color-adjust:exact;print-color-adjust:exact}
img,table{break-inside:avoid}h2{break-after:avoid}}"""


def render_html(doc: dict, histories: dict | None = None, alphas: dict | None = None) -> str:
    """``index.html`` from the summary document; ``histories`` (``(point,
    pendulum, backend) -> Trajectory``) and ``alphas`` (``pendulum -> alpha``)
    give the time-history plots, left out when None (e.g. from a stored summary)."""
    esc = html.escape

    def img(data, alt):
        return "" if data is None else f'<img alt="{esc(alt)}" src="data:image/png;base64,{data}">'

    header, rows = _trust_rows(doc)
    body = [f"<h1>Which engine to trust: scene <code>{esc(doc['config']['scene'])}</code></h1>"]
    if doc.get("quick"):
        body.append(f"<p class='banner'>{esc(_QUICK)}</p>")
    prov = doc.get("provenance") or {}
    body += [f"<p class='headline'><b>{esc(_headline(doc))}.</b> Reference: the analytic "
             "model (accurate path for time histories, compiled path for spectra).</p>",
             f"<p class='small'>{esc(prov.get('date', 'date unknown'))}, commit "
             f"<code>{esc(prov.get('commit', 'unknown')[:12])}</code>; full provenance at the "
             "end.</p>",
             "<h2>Trust table</h2>", _table(header, rows),
             *(f"<p class='conclusion'><b>{esc(r['label'])}.</b> {esc(r['conclusion'])}</p>"
               for r in doc["trust"].values()),
             "<h2>Verdicts</h2>", _table(_H["verdicts"], _verdict_rows(doc)),
             "<h2>Overturning thresholds</h2>",
             "<p>Engine thresholds (bisection around the model's) on the model's spectra; "
             "below, the relative error with the tolerance band. Dotted red: mode jumps, "
             "where the threshold is discontinuous in Ω (engines are tested away from them).</p>",
             img(plots.spectra_figure(doc), "thresholds on the spectra, with error panel"),
             _table(_H["thresholds"], _threshold_rows(doc))]
    conv = plots.convergence_figure(doc)
    body.append("<h3>Step convergence of the failing points</h3>")
    body.append(img(conv, "threshold error vs time step") if conv else
                "<p>Not measured in this campaign (no point carries a step-convergence "
                "study).</p>")
    if _jump_rows(doc):
        body += ["<h3>Mode-jump frequency shift</h3>", _table(_H["jumps"], _jump_rows(doc))]
    body += ["<h2>Time histories at the paper's points A-D</h2>",
             "<p>θ/α of every backend (model solid) and, below, the engine's error "
             "|θ − θ_model|/α on a log scale; dotted: the model's first impact.</p>"]
    for point in doc["config"]["points"]:
        amp, omega = POINTS[point]
        if histories:
            body.append(img(plots.history_figure(histories, point, alphas or {},
                                                 doc["config"]["reference"],
                                                 f"{point}: A = {amp:g} m/s², Ω = {omega:g}"),
                            f"time history at point {point}"))
    body += [_table(_H["histories"], _history_rows(doc)),
             "<h2>Restitution (free rocking)</h2>",
             "<p>Every impact's velocity ratio against Eq. 20 (no pendulum) and Eq. 19 at the "
             "measured ψ (with it).</p>",
             img(plots.restitution_figure(doc), "restitution per impact"),
             _table(_H["restitution"], _restitution_rows(doc)),
             "<h2>Run times</h2>", _table(_H["timings"], _timing_rows(doc))]
    if doc["errors"]:
        body += ["<h2>Runs that raised</h2>", _table(_H["errors"], _error_rows(doc))]
    body += ["<h2>Provenance</h2>", _table(_H["provenance"], _provenance_rows(doc)),
             "<details><summary>Scene, campaign configuration and backend settings</summary>",
             *(f"<h3>{k}</h3><pre>{esc(json.dumps(doc[k], indent=1))}</pre>"
               for k in ("scene", "config", "settings")), "</details>"]
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>trilith-xval report: {esc(_headline(doc))}</title><style>{_CSS}</style>"
            "</head><body>\n" + "\n".join(body) + "\n</body></html>\n")


def write_report(result, out_dir, provenance: dict | None = None) -> dict[str, Path]:
    """Write ``index.html``, ``summary.json`` and ``summary.md`` into ``out_dir``.

    ``provenance``: :func:`compare.provenance.collect` (date, commit, command,
    versions, machine, ``quick``); collected here without a command when None.
    """
    from .provenance import collect

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if provenance is None:
        provenance = collect(backends=result.versions)
    doc = summary_dict(result, provenance)
    alphas = {True: result.scene.alpha, False: result.scene.without_pendulum().alpha}
    paths = {"html": out / "index.html", "json": out / "summary.json", "md": out / "summary.md"}
    atomic.write_text(paths["json"], json.dumps(doc, indent=1, allow_nan=False))
    atomic.write_text(paths["md"], render_markdown(doc))
    atomic.write_text(paths["html"], render_html(doc, result.histories, alphas))
    return paths
