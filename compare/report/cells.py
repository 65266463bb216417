"""Table cells and tables of the validation report: HTML (cells coloured pass or
fail, long text folded in ``<details>``), Markdown and CSV from the same rows."""
from __future__ import annotations

import html
import re

__all__ = ["table", "csv_text", "cause_phrase", "unbroken"]


def _cell(text: str, ok: bool | None = None, details: str = "") -> dict:
    """A table cell: ``text``, coloured pass (True) / fail (False) / plain (None);
    ``details`` folded under the text in HTML (``<details>``), appended in CSV."""
    return {"text": text, "ok": ok, "details": details}


# A cell's short text within a few words; the full sentence goes in its details.
_CAUSES = {"agrees": "agrees", "model": "model invalid here (no engine to blame)",
           "no-bracket": "no overturn near the model's", "window": "model's overturning window",
           "contact": "engine's contact model, not its step", "jump": "next to a mode jump",
           "unknown": "cause not measured", "discretisation": "time step too coarse",
           "iterations": "too few solver iterations", "collapse": "engine's frame broke",
           "sensitivity": "flips under a 1e-4 nudge"}


def cause_phrase(cause: str | None) -> str:
    """A measured cause (``compare.measure.engine_spectrum``) in a short phrase."""
    return "not measured" if not cause else _CAUSES.get(cause, cause)


# A number and its unit stay on one line (a no-break space joins them), and a
# token with a hyphen inside ("after-impact", "4.4e-4") is never split at it.
_UNIT = re.compile(r"(\d) (%|α|ms|s|g|Hz|m/s²|rad/s|min)(?=[\s),;.]|$)")
_HYPHENATED = re.compile(r"[^\s<>]*\w-\w[^\s<>]*")


def unbroken(escaped: str) -> str:
    """Already-escaped text with numbers kept on their unit's line and hyphenated
    tokens unsplittable (HTML)."""
    text = _UNIT.sub("\\1\u00a0\\2", escaped)
    return _HYPHENATED.sub(lambda m: f"<span class='nb'>{m.group(0)}</span>", text)


def _text(c) -> str:
    return c["text"] if isinstance(c, dict) else c


def _flat(c, sep: str = " -- ") -> str:
    """A cell as plain text, its details (if any) after ``sep``."""
    if isinstance(c, dict) and c.get("details"):
        return f"{c['text']}{sep}{c['details']}"
    return _text(c)


def table(header: list[str], rows: list[list], md: bool = False) -> str:
    """HTML (in a horizontally scrolling wrapper) or Markdown table.  A cell is a
    string or :func:`_cell` (coloured pass/fail, details on demand in HTML,
    written out after the text in Markdown)."""
    if md:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(_flat(c, ": ").replace("|", "/") for c in r) + " |"
                  for r in rows]
        return "\n".join(lines)

    def td(c):
        ok = c.get("ok") if isinstance(c, dict) else None
        cls = "" if ok is None else (" class='pass'" if ok else " class='fail'")
        more = c.get("details") if isinstance(c, dict) else ""
        inner = unbroken(html.escape(_text(c)))
        if more:
            inner = (f"<details><summary>{inner}</summary>"
                     f"<span class='small'>{unbroken(html.escape(more))}</span></details>")
        return f"<td{cls}>{inner}</td>"

    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(td(c) for c in r) + "</tr>" for r in rows)
    return f"<div class='scroll'><table><tr>{head}</tr>{body}</table></div>"


def csv_text(header: list[str], rows: list[list]) -> str:
    """The same table as CSV (RFC 4180 quoting); a cell's details follow its text
    after " -- "."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows([[_flat(c) for c in r] for r in rows])
    return buf.getvalue()
