"""Writing the validation report: ``index.html`` (self-contained), ``summary.json``,
``summary.md``.

The first screen answers "which engine can I trust, for what, up to where, at
what cost": the trust table (:mod:`compare.report.trust`, computed from the summary
document) and a conclusion per engine.  The evidence follows (plots with error
panels, :mod:`compare.report.plots`, and tables), then provenance and, folded
away, the raw settings.  Plots are PNGs embedded as base64 data URIs: the HTML
opens offline with no server and no side files.

``summary.json`` carries ``schema_version``, ``quick``, ``provenance``, the
``trust`` table and verdict rows with stable ``id`` s
(:data:`compare.campaign.verdicts.VERDICT_IDS`).
"""
from __future__ import annotations

import html
import json
from pathlib import Path

from compare.run import atomic
from compare.report import plots
from compare.report import tables
from scenes import POINTS

from compare.run.jsonable import plain as clean_nan
from compare.measure.trajectories import _plain
from compare.report.trust import trust_table

__all__ = ["write_report", "render_html", "render_markdown", "summary_dict", "SCHEMA_VERSION"]

# 2: schema_version, quick, provenance, trust, verdict ids (1 had none of them).
SCHEMA_VERSION = 2


def summary_dict(result, provenance: dict | None = None) -> dict:
    """``summary.json``: strict JSON (non-finite numbers become null)."""
    doc = clean_nan(_plain(result.to_dict()))
    prov = provenance or {}
    out = {"schema_version": SCHEMA_VERSION, "quick": bool(prov.get("quick", False)),
           "provenance": prov, **doc}
    out["trust"] = trust_table(out)
    return out


def _headline(doc: dict) -> str:
    n = len(doc["verdicts"])
    n_pass = sum(bool(v["passed"]) for v in doc["verdicts"])
    return f"{n_pass} of {n} verdicts pass" + (" (QUICK run)" if doc.get("quick") else "")


_QUICK = ("QUICK RUN: smaller grids (one threshold frequency per curve, fewer restitution "
          "cases, no mode-jump probe); not the full campaign's verdicts.")


# ---------------------------------------------------------------- documents
def render_markdown(doc: dict) -> str:
    """``summary.md`` from the summary document."""
    header, rows = tables.trust_rows(doc)
    parts = [f"# Validation report: scene `{doc['config']['scene']}`"]
    if doc.get("quick"):
        parts.append(f"**{_QUICK}**")
    parts += [f"{_headline(doc)}.", "## Which engine to trust", tables.table(header, rows, md=True),
              *(f"- {r['conclusion']}" for r in doc["trust"].values()),
              "## Verdicts", tables.table(tables.HEADERS["verdicts"], tables.verdict_rows(doc), md=True),
              "## Overturning thresholds (away from mode jumps)",
              tables.table(tables.HEADERS["thresholds"], tables.threshold_rows(doc), md=True)]
    if tables.jump_rows(doc):
        parts += ["## Mode-jump frequency shift", tables.table(tables.HEADERS["jumps"], tables.jump_rows(doc), md=True)]
    parts += ["## Restitution", tables.table(tables.HEADERS["restitution"], tables.restitution_rows(doc), md=True),
              "## Time histories A-D", tables.table(tables.HEADERS["histories"], tables.history_rows(doc), md=True),
              "## Run times", tables.table(tables.HEADERS["timings"], tables.timing_rows(doc), md=True)]
    if doc["errors"]:
        parts += ["## Runs that raised", tables.table(tables.HEADERS["errors"], tables.error_rows(doc), md=True)]
    parts += ["## Provenance", tables.table(tables.HEADERS["provenance"], tables.provenance_rows(doc), md=True)]
    return "\n\n".join(parts) + "\n"


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

    header, rows = tables.trust_rows(doc)
    body = [f"<h1>Which engine to trust: scene <code>{esc(doc['config']['scene'])}</code></h1>"]
    if doc.get("quick"):
        body.append(f"<p class='banner'>{esc(_QUICK)}</p>")
    prov = doc.get("provenance") or {}
    body += [f"<p class='headline'><b>{esc(_headline(doc))}.</b> Reference: the analytic "
             "model (accurate path for time histories, compiled path for spectra).</p>",
             f"<p class='small'>{esc(prov.get('date', 'date unknown'))}, commit "
             f"<code>{esc(prov.get('commit', 'unknown')[:12])}</code>; full provenance at the "
             "end.</p>",
             "<h2>Trust table</h2>", tables.table(header, rows),
             *(f"<p class='conclusion'><b>{esc(r['label'])}.</b> {esc(r['conclusion'])}</p>"
               for r in doc["trust"].values()),
             "<h2>Verdicts</h2>", tables.table(tables.HEADERS["verdicts"], tables.verdict_rows(doc)),
             "<h2>Overturning thresholds</h2>",
             "<p>Engine thresholds (bisection around the model's) on the model's spectra; "
             "below, the relative error with the tolerance band. Dotted red: mode jumps, "
             "where the threshold is discontinuous in Ω (engines are tested away from them).</p>",
             img(plots.spectra_figure(doc), "thresholds on the spectra, with error panel"),
             tables.table(tables.HEADERS["thresholds"], tables.threshold_rows(doc))]
    conv = plots.convergence_figure(doc)
    body.append("<h3>Step convergence of the failing points</h3>")
    body.append(img(conv, "threshold error vs time step") if conv else
                "<p>Not measured in this campaign (no point carries a step-convergence "
                "study).</p>")
    if tables.jump_rows(doc):
        body += ["<h3>Mode-jump frequency shift</h3>", tables.table(tables.HEADERS["jumps"], tables.jump_rows(doc))]
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
    body += [tables.table(tables.HEADERS["histories"], tables.history_rows(doc)),
             "<h2>Restitution (free rocking)</h2>",
             "<p>Every impact's velocity ratio against Eq. 20 (no pendulum) and Eq. 19 at the "
             "measured ψ (with it).</p>",
             img(plots.restitution_figure(doc), "restitution per impact"),
             tables.table(tables.HEADERS["restitution"], tables.restitution_rows(doc)),
             "<h2>Run times</h2>", tables.table(tables.HEADERS["timings"], tables.timing_rows(doc))]
    if doc["errors"]:
        body += ["<h2>Runs that raised</h2>", tables.table(tables.HEADERS["errors"], tables.error_rows(doc))]
    body += ["<h2>Provenance</h2>", tables.table(tables.HEADERS["provenance"], tables.provenance_rows(doc)),
             "<details><summary>Scene, campaign configuration and backend settings</summary>",
             *(f"<h3>{k}</h3><pre>{esc(json.dumps(doc[k], indent=1))}</pre>"
               for k in ("scene", "config", "settings")), "</details>"]
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>trilith-xval report: {esc(_headline(doc))}</title><style>{_CSS}</style>"
            "</head><body>\n" + "\n".join(body) + "\n</body></html>\n")


def write_report(result, out_dir, provenance: dict | None = None) -> dict[str, Path]:
    """Write ``index.html``, ``summary.json`` and ``summary.md`` into ``out_dir``.

    ``provenance``: :func:`compare.run.provenance.collect` (date, commit, command,
    versions, machine, ``quick``); collected here without a command when None.
    """
    from compare.run.provenance import collect

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
