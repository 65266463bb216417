"""The report's "recomputed now / shown from storage" section.

The default ``trilith report`` shows parts of the stored validation beside what
it measured now (:mod:`compare.campaign.stored_parts`); this section says which
is which, names every stored file with the commit and date that stored it, and
lists the re-verified stored points.  A summary without ``sources`` (a full run,
an older stored run) gets a one-line statement that everything was measured by
its own run.
"""
from __future__ import annotations

from html import escape as esc

__all__ = ["sources_banner", "sources_html", "sources_markdown"]


def _origin(src: dict | None) -> str:
    if not src:
        return "unknown source"
    text = (f"{src.get('file')} (stored at commit {str(src.get('commit', '?'))[:12]}, "
            f"{src.get('date', '?')}")
    if src.get("run_commit"):
        text += (f"; measured by commit {str(src['run_commit'])[:12]} on "
                 f"{src.get('run_date', '?')}")
    return text + ")"


def _pct(x) -> str:
    return "—" if x is None else f"{100 * float(x):+.2f} %"


def _num(x) -> str:
    return "—" if x is None else f"{float(x):.4g}"


def sources_banner(doc: dict) -> str:
    """One line above the trust table of a default report (empty otherwise), so
    no reader takes the stored parts for numbers measured now."""
    src = doc.get("sources")
    if not src:
        return ""
    from trilith_xval.compare.campaign.stored_parts import failures, summary_line
    bad = failures(src)
    return ("<p class='banner'>Default report: " + esc(summary_line(src)) + ". <a href="
            "'#sources'>Recomputed and stored parts</a> says which number came from where."
            + "".join(f"<br>{esc(line)}" for line in bad) + "</p>")


def sources_html(doc: dict) -> str:
    """The section's HTML for the summary document ``doc``."""
    src = doc.get("sources")
    if not src:
        return ("<h2 id='sources'>Recomputed and stored parts</h2><p>Every number of this "
                "report was measured by the run that wrote it (no part shown from storage; "
                "the atlas section below is the stored atlas).</p>")
    run = src.get("stored_run")
    parts = src.get("parts") or {}
    rows = [("restitution, A-D histories and verdicts, θ(t)", "recomputed now"),
            ("long runs", esc(str(parts.get("long_runs", "?")))),
            ("mode-jump frequency shifts",
             "stored: " + esc(_origin(run)) if parts.get("jump_shifts") == "stored"
             else "recomputed now")]
    for engine, cases in (parts.get("thresholds") or {}).items():
        for case, c in cases.items():
            now = ", ".join(f"{w:g}" for w in c["recomputed"]) or "none"
            kept = ", ".join(f"{w:g}" for w in c["stored"]) or "none"
            rows.append((f"threshold points, {esc(engine)}, {esc(case)} [Ω rad/s]",
                         f"recomputed now: {now}; stored: {kept}"))
    for engine, s in sorted((src.get("engine_spectra") or {}).items()):
        rows.append((f"full engine spectrum, {esc(engine)}",
                     "stored: " + esc(_origin(s)) + "; re-verified below"))
    if src.get("atlas"):
        rows.append(("trust atlas", "stored: " + esc(_origin(src["atlas"])) + "; "
                     + esc(src.get("atlas_note") or "")))
    table = "".join(f"<tr><td>{a}</td><td>{b}</td></tr>" for a, b in rows)
    rv = src.get("reverified") or []
    rv_rows = "".join(
        f"<tr><td>{esc(r['engine'])}</td><td>{esc(r['case'])}</td><td>{r['omega']:g}</td>"
        f"<td>{_num(r.get('a_stored'))}</td><td>{_num(r.get('a_now'))}</td>"
        f"<td>{esc(str(r.get('mode_stored')))} / {esc(str(r.get('mode_now')))}</td>"
        f"<td>{_num(r.get('dt_stored'))} / {_num(r.get('dt_now'))}</td>"
        f"<td>{esc(r.get('error') or _pct(r.get('rel_difference')))}</td>"
        f"<td>{'agrees' if r['passed'] else '<b>DISAGREES</b>'}</td></tr>" for r in rv)
    unused = src.get("stored_run_unused")
    rules = src.get("rules") or {}
    return "\n".join([
        "<h2 id='sources'>Recomputed and stored parts</h2>",
        "<p class='banner'>This is the default report: it recomputes the cheap checks and "
        "a sample of threshold points now, and shows the rest from the stored validation, "
        "labelled below with the file, commit and date. <code>trilith report --full</code> "
        "(<code>make report-full</code>) remeasures everything.</p>",
        f"<p class='small'>Stored run: {esc(_origin(run)) if run else 'none used'}"
        + (f" — not used: {esc(unused)}" if unused else "") + ".</p>",
        f"<div class='scroll'><table><tr><th>part</th><th>source</th></tr>{table}</table></div>",
        f"<p class='small'>Threshold sample rule: {esc(rules.get('thresholds', ''))}</p>",
        "<h3>Stored engine spectra, re-verified now</h3>",
        f"<p class='small'>{esc(rules.get('reverify', ''))}. A disagreement fails the "
        "report (exit code 1).</p>",
        "<div class='scroll'><table><tr><th>engine</th><th>curve</th><th>Ω [rad/s]</th><th>a stored [m/s²]</th>"
        "<th>a now [m/s²]</th><th>mode stored / now</th><th>dt stored / now [s]</th>"
        "<th>difference</th><th></th></tr>"
        f"{rv_rows}</table></div>"])


def sources_markdown(doc: dict) -> list[str]:
    """Lines of ``summary.md`` saying what was stored and how it re-verified."""
    src = doc.get("sources")
    if not src:
        return []
    from trilith_xval.compare.campaign.stored_parts import failures, summary_line
    out = ["", "**Default report**: parts shown from storage (labelled in index.html and "
           "summary.json `sources`); `trilith report --full` remeasures everything. "
           + summary_line(src) + "."]
    out += [f"- {line}" for line in failures(src)]
    return out
