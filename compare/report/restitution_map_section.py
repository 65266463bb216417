"""The HTML report's restitution-map section, from the stored map
(``docs/validation/restitution_map.json``, measured by ``trilith restitution-map``,
not by the report's own campaign): a table of every cell and one figure per
engine (:mod:`compare.report.restitution_map_plot`)."""
from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path

from trilith_xval.compare.report.cells import unbroken

__all__ = ["restitution_map_html", "stored_restitution_map_section", "measurements_html"]

# Published measurements of the rocking restitution against Housner's ratio; the
# citations are in docs/measured-impacts.md, where each is read.
_CITED = ("ElGawady et al. (EESD 2011): measured restitution about 0.95 of Housner's on "
          "concrete and 0.67 on rubber at aspect ratio 5 (0.97 on concrete at 3); "
          "Kalliontzis, Sritharan &amp; Schultz (J. Struct. Eng. 2016): Housner's value "
          "consistently below the measured one.")
_MEASURED = Path(__file__).resolve().parents[2] / "docs" / "validation" / "impact_measurement.json"

_COLS = (("engine", "engine"), ("variant", "variant"), ("scene", "scene"),
         ("equation", "equation"), ("n_impacts", "impacts"), ("r_ratio", "r_eff/r_H"), ("r_worst", "worst impact [%]"),
         ("thr_error", "threshold error [%]"), ("cpu_s", "CPU s"))


def _cell(key: str, value) -> str:
    if isinstance(value, float):
        if not math.isfinite(value):
            return "-"
        if key in ("r_worst", "thr_error"):
            return f"{100 * value:+.2f}"
        return f"{value:.4f}" if key == "r_ratio" else f"{value:.2f}"
    return "-" if value is None else str(value)


def _figure_data(doc: dict, engine: str) -> str:
    import matplotlib.pyplot as plt
    from trilith_xval.compare.report.restitution_map_plot import engine_figure
    fig = engine_figure(doc, engine)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def restitution_map_html(doc: dict, figures: bool = True) -> str:
    """The section: heading, how it was measured, the cheapest settings, the
    figures (``figures``) and the table of cells."""
    from trilith_xval.compare.report.restitution_map_doc import settings_name
    esc = html.escape
    picks = "".join(
        f"<li>{esc(p['engine'])} {esc(p['range'])}: "
        + (f"<code>{esc(p['variant'])}</code> ({p['cpu_s']:.1f} CPU s, "
           f"<code>{esc(settings_name(p))}</code>)" if p["variant"] else "none passes")
        + "</li>" for p in doc["cheapest"])
    imgs = "".join(f'<img alt="restitution map {esc(e)}" src="data:image/png;base64,'
                   f'{_figure_data(doc, e)}">' for e in doc["engines"]) if figures else ""
    head = "".join(f"<th>{esc(t)}</th>" for _, t in _COLS)
    rows = "".join("<tr>" + "".join(f"<td>{unbroken(esc(_cell(k, c.get(k))))}</td>"
                                    for k, _ in _COLS)
                   + "</tr>" for c in doc["cells"])
    return ("<h2 id='restitution-map'>Restitution map</h2>"
            f"<p>Per engine and settings variant: r_eff / r_H (mean of the first "
            f"{doc['n_impacts']} free-rocking impacts, measured / Eq. 20 or Eq. 19) and the "
            f"one-sine threshold error at Omega = {doc['omega_ratio']:g} p, on the block "
            f"family and the fig5 trilith. Pass: every impact within "
            f"{100 * doc['r_tol']:g} %, threshold within {100 * doc['thr_tol']:g} % "
            f"(docs/restitution-map.md).</p><p>Cheapest passing settings:</p><ul>{picks}</ul>"
            f"{imgs}<div class='scroll'><table><tr>{head}</tr>{rows}</table></div>")


def measurements_html(path=None) -> str:
    """The paragraph that puts the map beside measurements: the cited published
    factors and, when the stored impact measurement is present, its square-block
    numbers (``docs/validation/impact_measurement.json``); empty text never."""
    import json
    p = Path(path) if path is not None else _MEASURED
    text = f"<p><b>Beside measurements.</b> {_CITED}"
    if p.is_file():
        s = json.loads(p.read_text())["summary"]
        m = s["measured"]
        text += (f" Measured square-block drops (MCube data, {s['impacts']} rocking-like "
                 f"impacts): post/pre angular-velocity ratio median {m['median']:+.2f} "
                 f"(quartiles {m['p25']:+.2f} to {m['p75']:+.2f}; "
                 f"{100 * s['fraction_rebounding']:.0f} % rebound onto the other corner) "
                 f"against Housner's {s['housner']:+.2f}; no single-valued rigid model "
                 f"closes the measured scatter (RMS {s['floor_any_single_value']:.2f}).")
    return text + " (docs/measured-impacts.md)</p>"


def stored_restitution_map_section(path=None, figures: bool = True) -> str:
    """The section from the stored map; a line saying it is missing when there is none."""
    from trilith_xval.compare.report.restitution_map_doc import STORED, read_map
    p = Path(path) if path is not None else STORED
    if not p.is_file():
        return ("<h2 id='restitution-map'>Restitution map</h2><p>No stored map "
                f"(<code>{html.escape(p.name)}</code>); <code>trilith restitution-map --json "
                "docs/validation/restitution_map.json</code> measures it.</p>")
    return ("<p class='small'>From the stored map <code>docs/validation/restitution_map.json"
            "</code> (measured separately from this report's campaign).</p>"
            + restitution_map_html(read_map(p), figures) + measurements_html())
