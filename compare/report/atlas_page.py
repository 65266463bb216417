"""The trust atlas shown to a person: heat maps, the trusted region per engine and
step, the cost (``trilith atlas --html``, and a section of the report).

A heat map per engine: rows are scenes (with and without the pendulum side by
side), columns the pulse frequencies; colour is the engine's threshold error at
its calibrated threshold step, on a diverging map centred on 0 (blue: the engine
overturns below the model), clipped at 3x the tolerance, with the tolerance
marked on the colour bar; a letter names the primary cause where the engine
disagrees; grey cells are points where the model itself is invalid (no engine
compared with it; in the consensus colour where the engines answered each other,
:mod:`compare.report.atlas_consensus_page`).  A number in an agreeing cell is the coarsest step factor that still
agrees.
"""
from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path

from trilith_xval.compare.report.atlas_consensus_page import (CONSENSUS_COLOUR,
                                                               CONSENSUS_LEGEND,
                                                               CONSENSUS_SYMBOLS,
                                                               consensus_html,
                                                               consensus_symbol)
from trilith_xval.compare.report.cells import unbroken
from trilith_xval.compare.report.trust import label

__all__ = ["CAUSE_SYMBOL", "step_rows", "reached_text", "trusted_rows", "parts_of", "part_line", "restep_line",
           "cost_rows", "heat_map_png", "atlas_html", "write_page"]

CAUSE_SYMBOL = {"model": "M", "collapse": "C", "no-bracket": "B", "window": "W", "jump": "J",
                "discretisation": "D", "iterations": "I", "contact": "K", "sensitivity": "S",
                "unknown": "?"}
TRUSTED_HEAD = ["engine", "step [s]", "agree / valid points reached", "share", "worst |error|",
                "where not (scene Ω: cause)"]
COST_HEAD = ["engine", "step [s]", "points (jobs)", "CPU s per threshold job",
             "CPU s per simulated s", "CPU s in all"]


def _tol(doc: dict) -> float:
    return float(doc.get("config", {}).get("tol", 0.02))


def _rows_of(doc: dict, engine: str) -> list[tuple[dict, list]]:
    return [(pt, pt["engines"].get(engine, [])) for pt in doc["points"]]


def step_rows(doc: dict):
    """Per engine and step, in order, a dict: ``engine``, ``dt``, ``factor``, ``valid``
    (the points where the model is valid and overturns), ``measured`` (``(point,
    row)`` measured at that step: those that agreed at every finer one), ``agree``,
    ``worst`` (largest finite |error| measured at it, or None), ``disagree``
    (``(point, row)`` that do not agree), ``cost`` (its ``cost`` entry),
    ``not_run`` (points the time budget left at that step) and ``reached`` (the
    valid points less those a budget left at that step or a finer one: the
    points the step could be judged on)."""
    valid = [pt for pt in doc["points"] if pt["a_reference"] is not None
             and pt["valid"] is not False]
    cost = {(c["engine"], c["dt"]): c for c in doc.get("cost", [])}
    factors = doc.get("config", {}).get("factors", [])
    for engine, steps in doc.get("steps", {}).items():
        left = 0
        for level, dt in enumerate(steps):
            not_run = doc.get("not_run", {}).get(engine, {}).get(repr(dt))
            left += not_run or 0
            at = [(pt, pt["engines"][engine][level]) for pt in valid
                  if len(pt["engines"].get(engine, [])) > level]
            errs = [abs(r["rel_error"]) for _, r in at if r.get("rel_error") is not None
                    and math.isfinite(r["rel_error"])]
            yield {"engine": engine, "dt": dt,
                   "factor": factors[level] if level < len(factors) else None,
                   "valid": len(valid), "measured": at,
                   "agree": sum(r.get("cause") == "agrees" for _, r in at),
                   "worst": max(errs) if errs else None,
                   "disagree": [(pt, r) for pt, r in at if r.get("cause") != "agrees"],
                   "cost": cost.get((engine, dt), {}),
                   "not_run": not_run, "reached": len(valid) - left}


def trusted_rows(doc: dict) -> list[list]:
    """Per engine and step: points that agree (at that step and every finer one)
    over the points where the model is valid and overturns; the worst error
    measured at that step; the disagreeing points with their cause."""
    tol = _tol(doc)
    out = []
    for row in step_rows(doc):
        bad = [f"{pt['scene']}{'' if pt['case'] == 'pendulum' else ' np'} "
               f"{pt['omega']:g}: {r.get('cause') or r.get('error', 'error')}"
               for pt, r in row["disagree"]]
        shown = "; ".join(bad[:6]) + (f"; ... {len(bad) - 6} more" if len(bad) > 6 else "")
        if row["not_run"]:
            shown = "; ".join(filter(None, [f"{row['not_run']} points not run (time budget)",
                                            shown]))
        n = row["reached"]
        if row["measured"]:
            why_empty = "none"
        elif n < row["valid"]:
            why_empty = "not run (the time budget ended at a finer step)"
        else:
            why_empty = f"not run (finer step disagreed or within {100 * tol:g} % nowhere)"
        out.append([row["engine"], f"{row['dt']:.3g}", reached_text(row),
                    f"{100 * row['agree'] / n:.0f} %" if n and row["measured"] else "-",
                    "-" if row["worst"] is None else f"{100 * row['worst']:.2g} %",
                    shown or why_empty])
    return out


def reached_text(row: dict) -> str:
    """``'agree / reached'``, and ``'of valid'`` when a budget left points; a dash
    for a step where nothing was measured after a budget left points."""
    if not row["measured"] and row["reached"] < row["valid"]:
        return "-"
    text = f"{row['agree']} / {row['reached']}"
    return text if row["reached"] == row["valid"] else f"{text} (of {row['valid']})"


def parts_of(doc: dict) -> list[dict]:
    """The separately measured parts of an atlas (one, when it was measured whole),
    each with ``engine_cpu_s``: the CPU seconds of its engines' threshold jobs."""
    parts = doc.get("parts") or [{"engines": list(doc.get("steps", {})),
                                  **{k: doc.get(k) for k in ("command", "provenance", "wall_s",
                                                             "parent_cpu_s", "local_cpu_s",
                                                             "load_average", "workers")}}]
    return [{**part, "engine_cpu_s": math.fsum(
        c["cpu_s"] or 0.0 for c in doc.get("cost", ()) if c["engine"] in part["engines"])}
        for part in parts]


def _cpu_text(part: dict) -> str:
    """The part's CPU: the process and its local workers when recorded; with one
    worker the process alone is all of it; else only the engine jobs' own CPU is
    known (older atlases did not record the workers')."""
    if part.get("local_cpu_s") is not None:
        return f"{part['local_cpu_s']:.0f} CPU s (the process and its workers)"
    if part.get("workers") == 1:
        return f"{part.get('parent_cpu_s') or 0:.0f} CPU s in the process"
    return (f"{part.get('engine_cpu_s') or 0:.0f} CPU s in the engine jobs (the workers' "
            f"whole CPU was not recorded)")


def part_line(part: dict, code=("`", "`")) -> str:
    """One part's engines, command (between ``code`` marks), date, commit, workers,
    load average and cost."""
    prov = part.get("provenance") or {}
    load = part.get("load_average") or []
    when = prov.get("date", "date not recorded")
    commit = str(prov.get("commit") or "")[:12] or "not recorded"
    return (f"{', '.join(label(e) for e in part['engines'])}: {code[0]}{part.get('command')}"
            f"{code[1]}"
            f" ({when}, commit {code[0]}{commit}{code[1]}, {part.get('workers', '?')} worker(s), load average "
            + (" -> ".join(f"{x:.1f}" for x in load) or "?")
            + f", {_cpu_text(part)}, {(part.get('wall_s') or 0) / 60:.0f} min wall)")


def restep_line(entry: dict, code=("`", "`")) -> str:
    """One restep (``atlas --restep``): the engine, how many points it remeasured
    under the step rule, the causes that changed per step, and its provenance."""
    changed = ", ".join(f"{float(dt):g} s: {c['changed']}" for dt, c in entry["changes"].items())
    n = entry["points"]
    return (f"step rule applied to {label(entry['engine'])}: {n} point{'s' * (n != 1)} "
            f"where it can act remeasured (the rest carried); causes changed per step: "
            f"{changed}; "
            + part_line({**entry, "engines": [entry["engine"]]}, code))


def cost_rows(doc: dict) -> list[list]:
    def num(x, fmt):
        return "-" if x is None else format(x, fmt)
    return [[c["engine"], f"{c['dt']:.3g}", f"{c['points']} ({c.get('jobs', '?')})",
             num(c["cpu_s_per_point"], ".3g"),
             num(c["cpu_s_per_sim_s"], ".3g"), num(c["cpu_s"], ".4g")]
            for c in doc.get("cost", [])]


def _grid(doc: dict, engine: str, case: str):
    """Rows (scene labels), omegas, error matrix, symbols, invalid mask."""
    import numpy as np
    omegas = sorted({pt["omega"] for pt in doc["points"]})
    labels = list(dict.fromkeys(f"{pt['scene']} ({pt['pulse']})" for pt in doc["points"]
                                if pt["case"] == case))
    err = np.full((len(labels), len(omegas)), np.nan)
    invalid = np.zeros_like(err, dtype=bool)
    text = [["" for _ in omegas] for _ in labels]
    factors = doc.get("config", {}).get("factors", [1])
    for pt in doc["points"]:
        if pt["case"] != case:
            continue
        i, j = labels.index(f"{pt['scene']} ({pt['pulse']})"), omegas.index(pt["omega"])
        if pt["valid"] is False:
            invalid[i, j] = True
            text[i][j] = consensus_symbol(pt, engine)
            continue
        rows = pt["engines"].get(engine, [])
        if pt["a_reference"] is None:
            text[i][j] = "·"  # no overturning in the model's range
            continue
        if not rows:
            text[i][j] = "–"  # valid, but not measured (a time budget ran out)
            continue
        first = rows[0]
        if first.get("rel_error") is not None:
            err[i, j] = first["rel_error"]
        if first.get("cause") != "agrees":
            text[i][j] = CAUSE_SYMBOL.get(first.get("cause"), "E")
        else:
            agreeing = [f for f, r in zip(factors, rows) if r.get("cause") == "agrees"]
            text[i][j] = f"{agreeing[-1]:g}"
    return labels, omegas, err, text, invalid


def heat_map_png(doc: dict, engine: str) -> bytes:
    """The engine's heat map (module docstring) as PNG bytes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import ListedColormap, TwoSlopeNorm
    from matplotlib.ticker import PercentFormatter

    tol = _tol(doc)
    lim = 3 * tol
    cases = [c for c in ("pendulum", "no_pendulum")
             if any(pt["case"] == c for pt in doc["points"])]
    n_rows = max(len(_grid(doc, engine, c)[0]) for c in cases)
    # Stacked: readable on a phone, the Omega axes aligned.
    fig, axes = plt.subplots(len(cases), 1, figsize=(7.5, len(cases) * (1.1 + 0.22 * n_rows)),
                             squeeze=False, layout="constrained")
    cmap = plt.get_cmap("RdBu_r").with_extremes(bad="white")
    image = None
    for ax, case in zip(axes[:, 0], cases):
        labels, omegas, err, text, invalid = _grid(doc, engine, case)
        shown = np.clip(err, -lim, lim)
        image = ax.imshow(np.ma.masked_invalid(shown), cmap=cmap, aspect="auto",
                          norm=TwoSlopeNorm(0.0, -lim, lim), interpolation="nearest")
        grey = np.ma.masked_where(~invalid, np.ones_like(err))
        ax.imshow(grey, cmap="Greys", vmin=0, vmax=3, aspect="auto", interpolation="nearest")
        # Engine against engine, never against the model: its own colour.
        answered = invalid & np.array([[t in CONSENSUS_SYMBOLS for t in row] for row in text])
        ax.imshow(np.ma.masked_where(~answered, np.ones_like(err)),
                  cmap=ListedColormap([CONSENSUS_COLOUR]), aspect="auto",
                  interpolation="nearest")
        for i in range(len(labels)):
            for j in range(len(omegas)):
                if text[i][j]:
                    bad = not text[i][j][0].isdigit() and text[i][j] != "–"
                    ax.text(j, i, text[i][j], ha="center", va="center", fontsize=6.5,
                            color="0.55" if text[i][j] == "–" else "black",
                            fontweight="bold" if bad else "normal")
        ax.set_xticks(range(len(omegas)), [f"{w:g}" for w in omegas], fontsize=7)
        ax.set_yticks(range(len(labels)), labels, fontsize=6.5)
        ax.set_xlabel("Ω [rad/s]")
        ax.set_title(f"{engine}: {case.replace('_', ' ')}", fontsize=9)
    bar = fig.colorbar(image, ax=axes[:, 0].tolist(), fraction=0.04, pad=0.03, aspect=40)
    bar.set_label("A_engine / A_model - 1 (calibrated step)", fontsize=8)
    bar.ax.yaxis.set_major_formatter(PercentFormatter(xmax=1.0, decimals=0))
    bar.set_ticks([-lim, -tol, 0.0, tol, lim])
    for y in (-tol, tol):
        bar.ax.axhline(y, color="black", lw=1.5, zorder=5)
    bar.ax.tick_params(labelsize=7)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _table(head: list[str], rows: list[list]) -> str:
    h = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    # Causes such as "no-bracket" and numbers such as "1e-4" stay whole on a phone.
    b = "".join("<tr>" + "".join(f"<td>{unbroken(html.escape(str(c)))}</td>" for c in r)
                + "</tr>" for r in rows)
    return f"<div class='scroll'><table><tr>{h}</tr>{b}</table></div>"


def budget_text(doc: dict) -> str:
    """Whose time budget left points unmeasured: the atlas's, or (a joined atlas) its
    parts'."""
    if doc.get("budget_s") is not None:
        return f"the time budget of {doc['budget_s'] / 60:.0f} min"
    budgets = [p["budget_s"] / 60 for p in parts_of(doc) if p.get("budget_s") is not None]
    return ("a part's time budget (" + ", ".join(f"{b:.0f}" for b in budgets) + " min)"
            if budgets else "a time budget")


def atlas_html(doc: dict, level: int = 2) -> str:
    """The atlas as an HTML fragment (headings at ``level``): what was run, the heat
    maps, the trusted region and the cost."""
    h, sub = f"h{level}", f"h{level + 1}"
    cfg = doc.get("config", {})
    ran = ", ".join(doc.get("steps", {})) or "none"
    not_run = ", ".join(doc.get("engines_not_run", [])) or "none"
    skipped = "; ".join(f"{e} at dt {dt}: {n} points" for e, by in doc.get("not_run", {}).items()
                        for dt, n in by.items())
    n_invalid = sum(pt["valid"] is False for pt in doc["points"])
    parts = [f"<{h} id='atlas'>Trust atlas</{h}>",
             f"<p>{len(doc['points'])} model points ({len({pt['scene'] for pt in doc['points']})} "
             f"scenes of Figs. 8-11, both curves, Ω {min(cfg.get('omegas', [0])):g}-"
             f"{max(cfg.get('omegas', [0])):g} rad/s); the model is invalid at {n_invalid} "
             "of them (no engine compared with the model there"
             + ("; the engines against each other, below" if doc.get("consensus") else "")
             + f"). Engines run: {html.escape(ran)}; not run: "
             f"{html.escape(not_run)}. Tolerance {100 * _tol(doc):g} %; steps "
             f"{html.escape(', '.join(f'{f:g}' for f in cfg.get('factors') or []))} x each "
             "engine's calibrated threshold "
             "step, a coarser one only where the finer one agreed."
             + (f" Not run ({budget_text(doc)} reached): {html.escape(skipped)}."
                if skipped else "") + "</p>"]
    legend = ("Colour: threshold error at the calibrated step (black lines on the bar: the "
              "tolerance); grey: the model is invalid (no engine compared with it); "
              + (CONSENSUS_LEGEND if doc.get("consensus") else "") + "a digit: the coarsest "
              "step factor that still agrees; a letter: the cause of a disagreement ("
              + ", ".join(f"{s} {c}" for c, s in CAUSE_SYMBOL.items())
              + "); a dot: the model does not overturn in its search range; a dash: not "
              "measured (a time budget ran out).")
    for engine in doc.get("steps", {}):
        png = base64.b64encode(heat_map_png(doc, engine)).decode()
        # Readable on a phone: the map keeps 600 px and scrolls sideways rather
        # than shrinking its scene labels below legibility.
        parts.append(f"<{sub}>{html.escape(engine)}</{sub}><div class='scroll'><img "
                     f"style='min-width:600px' alt='atlas heat map {html.escape(engine)}' "
                     f"src='data:image/png;base64,{png}'></div>"
                     f"<p class='small'>{html.escape(legend)}</p>")
    if doc.get("consensus"):
        parts.append(consensus_html(doc, sub))
    parts += [f"<{sub}>Trusted region per engine and step</{sub}>",
              _table(TRUSTED_HEAD, trusted_rows(doc)),
              f"<{sub}>Cost per engine and step</{sub}>", _table(COST_HEAD, cost_rows(doc)),
              f"<{sub}>How it was measured</{sub}><ul>"
              + "".join(f"<li>{html.escape(part_line(p, ('', '')))}</li>" for p in parts_of(doc))
              + "".join(f"<li>{html.escape(restep_line(r, ('', '')))}</li>"
                        for r in doc.get("resteps", ()))
              + "</ul>" + (f"<p>Joined by <code>{html.escape(str(doc.get('command')))}</code>"
                           "</p>" if len(parts_of(doc)) > 1 else "")]
    return "\n".join(parts)


STYLE = ("body{font-family:sans-serif;margin:1em;max-width:1300px}img{max-width:100%;"
         "height:auto}table{border-collapse:collapse;font-size:12px}td,th{border:1px solid "
         "#ccc;padding:2px 6px;text-align:left;vertical-align:top}.scroll{overflow-x:auto}"
         "@media (max-width:600px){body{margin:0.4em}table{font-size:11px}"
         "td,th{padding:2px 3px}}.nb{white-space:nowrap}")


def page_html(doc: dict) -> str:
    """A standalone page of :func:`atlas_html`."""
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><meta name='viewport' "
            "content='width=device-width, initial-scale=1'><title>trust atlas</title>"
            f"<style>{STYLE}</style></head><body>{atlas_html(doc, 1)}</body></html>\n")


def write_page(doc: dict, path) -> Path:
    """:func:`page_html`, written atomically."""
    from trilith_xval.compare.run import atomic
    atomic.write_text(path, page_html(doc))
    return Path(path)


STORED = Path(__file__).resolve().parents[2] / "docs" / "validation" / "atlas.json"


def stored_atlas_section(path=None) -> str:
    """The report's atlas section from the stored atlas (``docs/validation/atlas.json``,
    measured by ``trilith atlas``, not by the report's own campaign); a line saying
    it is missing when there is none."""
    from trilith_xval.compare.campaign.atlas_check import read_atlas
    p = Path(path) if path is not None else STORED
    if not p.is_file():
        return ("<h2 id='atlas'>Trust atlas</h2><p>No stored atlas "
                f"(<code>{html.escape(str(p.name))}</code>); <code>trilith atlas --json "
                "docs/validation/atlas.json</code> measures it (docs/atlas.md).</p>")
    doc = read_atlas(p, "stored atlas")
    return ("<p class='small'>From the stored atlas <code>docs/validation/atlas.json</code> "
            "(measured separately from this report's campaign).</p>" + atlas_html(doc, 2))
