"""Writing the validation report: ``index.html`` (self-contained), ``summary.json``,
``summary.md``, ``trust.csv`` and ``thresholds.csv``.

The first screen answers "which engine can I trust, for what, up to where, at
what cost": one recommendation line per use (:mod:`compare.report.recommend`),
the trust table (:mod:`compare.report.trust`, computed from the summary
document) and a conclusion per engine.  The evidence follows (plots with error
panels, :mod:`compare.report.plots`, and tables), then the engines' settings as
a table, provenance and, folded away, scene and configuration.  Plots are PNGs
and the CSV exports data URIs: the HTML opens offline with no server and no
side files.

``summary.json`` carries ``schema_version``, ``quick``, ``provenance``, the
``trust`` table, verdict rows with stable ``id`` s
(:data:`compare.campaign.verdicts.VERDICT_IDS`) and, beside each reference
spectrum, ``model_validity``: the model's own validity on its threshold run at
every frequency (:func:`add_model_validity`).
"""
from __future__ import annotations

import base64
import html
import json
from pathlib import Path

from trilith_xval.compare.run import atomic
from trilith_xval.compare.report import plots
from trilith_xval.compare.report import tables
from trilith_xval.compare.report import threshold_table
from trilith_xval.compare.report import units
from trilith_xval.compare.report.cells import unbroken
from trilith_xval.compare.report.recommend import recommendations
from trilith_xval.scenes import POINTS

from trilith_xval.compare.run.jsonable import plain
from trilith_xval.compare.report.trust import AGREEMENT_RULE, trust_table

__all__ = ["write_report", "render_html", "render_markdown", "summary_dict", "add_model_validity",
           "SCHEMA_VERSION"]

# The schema (and its version) lives in one place, compare/campaign/summary.py.
from trilith_xval.compare.campaign.summary import SCHEMA_VERSION  # noqa: E402


def summary_dict(result, provenance: dict | None = None) -> dict:
    """``summary.json``: strict JSON (non-finite numbers become null)."""
    doc = plain(result.to_dict())
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
    if doc.get("rendered_from"):
        prov = doc.get("provenance") or {}
        parts.append(f"**Rendered from the stored run `{doc['rendered_from']['file']}` "
                     f"(measured {prov.get('date', 'on an unknown date')}, commit "
                     f"{str(prov.get('commit', 'unknown'))[:12]}): nothing was recomputed.**")
    from trilith_xval.compare.report.sources_section import sources_markdown
    parts += sources_markdown(doc)
    parts += [f"{_headline(doc)}.", "## Recommendation",
              "\n".join(f"- {r}" for r in recommendations(doc)),
              "## Which engine to trust", tables.table(header, rows, md=True),
              AGREEMENT_RULE,
              *(f"- {r['conclusion']}" for r in doc["trust"].values()),
              "## Verdicts", tables.table(tables.HEADERS["verdicts"], tables.verdict_rows(doc), md=True),
              "## Overturning thresholds (away from mode jumps)",
              tables.table(tables.HEADERS["thresholds"], threshold_table.threshold_rows(doc),
                           md=True)]
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
padding:0.8em;line-height:1.4;color:#111}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
img{max-width:100%;height:auto;display:block;margin:0.3em 0}
.figs{display:grid;grid-template-columns:repeat(auto-fit,minmax(min(100%,460px),1fr));gap:0.6em}
.scroll{overflow-x:auto;max-width:100%;margin:0.5em 0}
table{border-collapse:collapse;font-size:13px}
td,th{border:1px solid #bbb;padding:3px 6px;vertical-align:top;text-align:left;
overflow-wrap:normal;word-break:normal;hyphens:none}
th{background:#eee}td.pass{background:#d4edda}td.fail{background:#f8d7da}
td:first-child{min-width:9em}
summary{cursor:pointer}.nb{white-space:nowrap}
.banner{background:#fff3cd;border:2px solid #d39e00;padding:0.6em;font-weight:bold}
.reco{background:#eef5ff;border-left:4px solid #3b73c4;padding:0.3em 0.8em}
.reco ul{margin:0.2em 0;padding-left:1.2em}.reco li{margin:0.1em 0}
.headline{font-size:1.1em}.small{font-size:0.85em;color:#444}.conclusion{margin:0.4em 0 0.8em 0}
code{overflow-wrap:anywhere}
@media (max-width:600px){body{padding:0.4em}table{font-size:11px}td,th{padding:2px 3px}
td:first-child{min-width:7em}td:last-child{min-width:9em}}
@media print{body{max-width:none;padding:0}.scroll{overflow:visible}
td.pass,td.fail,th,.banner{-webkit-print-color-adjust:exact;print-color-adjust:exact}
img,table{break-inside:avoid}h2{break-after:avoid}}"""


def _download(name: str, text: str) -> str:
    """A link that saves ``text`` as ``name`` from the page itself (a data URI:
    the report stays one self-contained file)."""
    data = base64.b64encode(text.encode("utf-8")).decode("ascii")
    return (f"<a download='{html.escape(name)}' href='data:text/csv;base64,{data}'>"
            f"{html.escape(name)}</a>")


def render_html(doc: dict, histories: dict | None = None, alphas: dict | None = None) -> str:
    """``index.html`` from the summary document; ``histories`` (``(point,
    pendulum, backend) -> Trajectory``) and ``alphas`` (``pendulum -> alpha``)
    give the time-history plots, left out when None (e.g. from a stored summary)."""
    esc = html.escape

    def img(data, alt):
        return "" if data is None else f'<img alt="{esc(alt)}" src="data:image/png;base64,{data}">'

    def figs(items):
        items = [img(d, alt) for d, alt in items if d is not None]
        return f"<div class='figs'>{''.join(items)}</div>" if items else ""

    from trilith_xval.compare.report.sources_section import sources_banner, sources_html
    header, rows = tables.trust_rows(doc)
    body = [f"<h1>Which engine to trust: scene <code>{esc(doc['config']['scene'])}</code></h1>"]
    if doc.get("quick"):
        body.append(f"<p class='banner'>{esc(_QUICK)}</p>")
    prov = doc.get("provenance") or {}
    if doc.get("rendered_from"):  # trilith report --from: a stored run, not this code's
        src = doc["rendered_from"]
        body.append(f"<p class='banner'>Rendered from the stored run <code>{esc(src['file'])}"
                    f"</code> (sha256 {esc(src['sha256'][:12])}), measured "
                    f"{esc(prov.get('date', 'on an unknown date'))} at commit "
                    f"<code>{esc(str(prov.get('commit', 'unknown'))[:12])}</code>: nothing was "
                    "recomputed; time-history plots are not stored.</p>")
    body += [f"<p class='headline'><b>{esc(_headline(doc))}.</b> Reference: the analytic "
             "model (accurate path for time histories, compiled path for spectra).</p>",
             "<div class='reco'><b>Recommendation</b><ul>",
             *(f"<li>{unbroken(esc(line))}</li>" for line in recommendations(doc)),
             "</ul></div>",
             sources_banner(doc),
             "<h2>Trust table</h2>", tables.table(header, rows),
             f"<p class='small'>{esc(prov.get('date', 'date unknown'))}, commit "
             f"<code>{esc(prov.get('commit', 'unknown')[:12])}</code>; full provenance at the "
             "end. Download: " + _download("trust.csv", tables.csv_text(header, rows)) + ", "
             + _download("thresholds.csv", threshold_table.threshold_csv(doc)) + ".</p>",
             f"<p class='small'>{esc(AGREEMENT_RULE)}</p>",
             *(f"<p class='conclusion'><b>{esc(r['label'])}.</b> "
               f"{unbroken(esc(r['conclusion']))}</p>" for r in doc["trust"].values()),
             sources_html(doc),
             "<h2>Verdicts</h2>", tables.table(tables.HEADERS["verdicts"], tables.verdict_rows(doc)),
             "<h2>Overturning thresholds</h2>",
             "<p>Engine thresholds (bisection around the model's) on the model's spectra; "
             "below, the relative error with the tolerance band. Dotted red: mode jumps, "
             "where the threshold is discontinuous in Ω (engines are tested away from them). "
             "Hatched grey: the model itself is invalid on its threshold run (a contact would "
             "have to pull: the columns hop or the lintel is thrown off); no engine is blamed "
             "there. An error no larger than the engine's bracket (the relative width between "
             "its highest surviving and lowest overturning amplitude) is no number: it "
             "prints as |e| ≤ that width.</p>",
             figs((d, f"thresholds on the spectrum {case}, with error panel")
                  for case, d in plots.spectra_figures(doc)),
             tables.table(tables.HEADERS["thresholds"], threshold_table.threshold_rows(doc))]
    conv = plots.convergence_figure(doc)
    body.append("<h3>Step convergence of the failing points</h3>")
    body.append(figs([(conv, "threshold error vs time step")]) if conv else
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
            title = f"{point}: A = {amp:g} m/s² ({amp / units.G:.2g} g), Ω = {omega:g} rad/s"
            body.append(figs((d, f"time history at point {point}") for d in
                             plots.history_figures(histories, point, alphas or {},
                                                   doc["config"]["reference"], title)))
    body += [tables.table(tables.HEADERS["histories"], tables.history_rows(doc)),
             "<h2>Restitution (free rocking)</h2>",
             "<p>Every impact's velocity ratio against Eq. 20 (no pendulum) and Eq. 19 at the "
             "measured ψ (with it).</p>",
             figs((d, "restitution per impact") for d in plots.restitution_figures(doc)),
             tables.table(tables.HEADERS["restitution"], tables.restitution_rows(doc)),
             "<h2>Run times</h2>", tables.table(tables.HEADERS["timings"], tables.timing_rows(doc))]
    if doc.get("records"):  # trilith report --record
        from trilith_xval.compare.report.record_section import record_section_html
        body += record_section_html(doc["records"])
    if doc["errors"]:
        body += ["<h2>Runs that raised</h2>", tables.table(tables.HEADERS["errors"], tables.error_rows(doc))]
    from trilith_xval.compare.report.atlas_page import stored_atlas_section
    body.append(stored_atlas_section())
    from trilith_xval.compare.report.restitution_map_section import (
        stored_restitution_map_section)
    body.append(stored_restitution_map_section())
    s_head, s_rows = tables.settings_rows(doc)
    body += ["<h2>Engine settings</h2>", tables.table(s_head, s_rows),
             "<h2>Provenance</h2>", tables.table(tables.HEADERS["provenance"], tables.provenance_rows(doc)),
             "<details><summary>Scene and campaign configuration</summary>",
             *(f"<h3>{k}</h3>" + tables.table(["name", "value"], tables.key_value_rows(doc[k]))
               for k in ("scene", "config")), "</details>"]
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>trilith-xval report: {esc(_headline(doc))}</title><style>{_CSS}</style>"
            "</head><body>\n" + "\n".join(body) + "\n</body></html>\n")


def add_model_validity(doc: dict, scene, workers: int = 1) -> dict:
    """Put the model's validity on its threshold run at every frequency of each
    reference spectrum into ``doc["spectra"][case]["model_validity"]`` (aligned with
    ``omega``; :func:`analytic.threshold_validity.point_validity`), unless the
    summary already carries it.  The campaign's pulses are one-sine (Eq. 22)."""
    from trilith_xval.analytic.threshold_validity import curve_validity
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict

    scenes = {"pendulum": scene, "no_pendulum": scene.without_pendulum()}
    for case, spec in doc.get("spectra", {}).items():
        if case in scenes and "model_validity" not in spec:
            sc = scenes[case]
            # Kept in the active run store: a report rebuilt from stored runs
            # reruns none of these accurate runs.
            spec["model_validity"] = plain(runs.memo(
                "curve-validity", {"scene": scene_dict(sc), "omega": spec["omega"],
                                   "a": spec["a"], "kind": "sine"},
                lambda: curve_validity(sc, spec["omega"], spec["a"], "sine", workers)))
    return doc


def write_report(result, out_dir, provenance: dict | None = None,
                 extra: dict | None = None) -> dict[str, Path]:
    """Write ``index.html``, ``summary.json``, ``summary.md``, ``trust.csv`` and
    ``thresholds.csv`` into ``out_dir``.

    ``provenance``: :func:`compare.run.provenance.collect` (date, commit, command,
    versions, machine, ``quick``); collected here without a command when None.
    ``extra``: more top-level keys of the summary (``records``: the section of
    :mod:`compare.report.record_section`).
    """
    from trilith_xval.compare.run.provenance import collect

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if provenance is None:
        provenance = collect(backends=result.versions)
    doc = add_model_validity(summary_dict(result, provenance), result.scene,
                             max(1, int(result.config.workers or 1)))
    doc.update(plain(extra or {}))
    alphas = {True: result.scene.alpha, False: result.scene.without_pendulum().alpha}
    return _write_documents(doc, out, result.histories, alphas)


def _write_documents(doc: dict, out: Path, histories=None, alphas=None) -> dict[str, Path]:
    """The report's five files from the summary document ``doc``, each written whole."""
    paths = {"html": out / "index.html", "json": out / "summary.json", "md": out / "summary.md",
             "trust_csv": out / "trust.csv", "thresholds_csv": out / "thresholds.csv"}
    atomic.write_text(paths["json"], json.dumps(doc, indent=1, allow_nan=False))
    atomic.write_text(paths["md"], render_markdown(doc))
    atomic.write_text(paths["trust_csv"], tables.csv_text(*tables.trust_rows(doc)))
    atomic.write_text(paths["thresholds_csv"], threshold_table.threshold_csv(doc))
    atomic.write_text(paths["html"], render_html(doc, histories, alphas))
    return paths


def write_stored_report(doc: dict, out_dir, source: dict) -> dict[str, Path]:
    """The report of a stored run (``trilith report --from FILE``): the files of
    :func:`write_report` rendered from its ``summary.json`` document ``doc``, without
    the time-history plots (a summary stores their errors, not the trajectories)
    and with a banner naming ``source`` (``{"file", "sha256"}``), the run's date
    and commit: nothing is recomputed."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return _write_documents({**doc, "rendered_from": dict(source)}, out)
