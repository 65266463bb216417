"""The atlas's invalid points shown to a person: the engines' consensus, engine
against engine (:mod:`compare.campaign.atlas_consensus`).

In each engine's heat map a point where the model is invalid but the engines
answered is drawn in its own colour (:data:`CONSENSUS_COLOUR`, never the
model-error scale): ``≈`` where this engine lies within 2 % of the engines'
median, ``≠`` where it is an outlier (or one of two engines apart), ``∅`` where it
gave no answer (its step did not converge).  :func:`consensus_html` is the
section: how many points gained an answer, and every point's consensus.
"""
from __future__ import annotations

import html

__all__ = ["CONSENSUS_COLOUR", "CONSENSUS_SYMBOLS", "CONSENSUS_LEGEND", "CONSENSUS_HEAD",
           "consensus_symbol", "consensus_row", "consensus_table", "consensus_html"]

CONSENSUS_COLOUR = "#c9b3e6"  # lavender: outside the red-blue model-error scale
CONSENSUS_SYMBOLS = ("≈", "≠")  # the cells drawn in the consensus colour
CONSENSUS_LEGEND = ("lavender: the model is invalid and the engines answered, engine against "
                    "engine (≈ within 2 % of the engines' median, ≠ an outlier or one of two "
                    "engines apart; ∅ on grey: this engine's step did not converge); ")


def consensus_symbol(point: dict, engine: str) -> str:
    """The heat-map symbol of ``engine`` at an invalid ``point`` (module docstring);
    '' where no consensus was measured."""
    c = point.get("consensus") or {}
    if c.get("status") in (None, "not run", "none"):
        return "∅" if any(n["engine"] == engine for n in c.get("no_answer", [])) else ""
    if engine in c.get("engines", {}):
        odd = c["status"] == "disagree" or any(o["engine"] == engine for o in c["outliers"])
        return "≠" if odd else "≈"
    return "∅" if any(n["engine"] == engine for n in c.get("no_answer", [])) else ""


def _fmt(x, spec: str) -> str:
    return "–" if x is None else format(x, spec)


CONSENSUS_HEAD = ["case", "Ω [rad/s]", "model's number (invalid) [m/s²]",
                  "engines' median [m/s²]", "failure", "status", "each engine vs the median",
                  "outliers (cause)", "no answer (cause)"]


def consensus_row(case: str, omega: float, a_model, c: dict) -> list[str]:
    """One point's consensus ``c`` as a table row under :data:`CONSENSUS_HEAD`."""
    devs = "; ".join(f"{e} {100 * v['deviation']:+.2f} %" for e, v in c["engines"].items())
    odd = "; ".join(f"{o['engine']} ({o['cause']})" for o in c["outliers"])
    none = "; ".join(f"{n['engine']} ({n['cause']})" for n in c["no_answer"])
    return [case.replace("_", " "), f"{omega:g}", _fmt(a_model, ".4g"),
            _fmt(c["median"], ".4g"), c.get("failure") or "–", c["status"], devs or "–",
            odd or "–", none or "–"]


def consensus_table(head: list[str], rows: list[list]) -> str:
    return ("<div class='scroll'><table><tr>" + "".join(f"<th>{html.escape(h)}</th>"
                                                        for h in head) + "</tr>"
            + "".join("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in r)
                      + "</tr>" for r in rows) + "</table></div>")


def consensus_html(doc: dict, tag: str = "h3") -> str:
    """The consensus section of the atlas page (``tag`` its heading)."""
    s = doc["consensus"]
    rows = [[pt["scene"]] + consensus_row(pt["case"], pt["omega"], pt["a_reference"],
                                          pt["consensus"])
            for pt in doc["points"]
            if pt.get("consensus") and pt["consensus"]["status"] != "not run"]
    table = consensus_table(["scene"] + CONSENSUS_HEAD, rows)
    not_run = s["invalid_points"] - s["answerable"]
    status = ", ".join(f"{k} {v}" for k, v in sorted(s["status"].items()))
    cost = (f"{s['cpu_s']:.0f} CPU s in the engine jobs "
            f"({_fmt(s.get('cpu_s_per_engine_point'), '.2g')} per engine and point), load "
            f"average {s['load_average'][0]:.1f} -> {s['load_average'][1]:.1f}")
    return (f"<{tag} id='consensus'>Where the model is invalid: engine against engine</{tag}>"
            f"<p>The model is invalid at {s['invalid_points']} points. At {s['answerable']} of "
            f"them {html.escape(', '.join(s['engines']))} each measured its own first-failure "
            "amplitude (overturn or collapse), converged in the step (two steps within 1 %); "
            f"<b>{s['gained']} points gained an answer</b> ({html.escape(status)}). This is "
            "the engines checked against each other, never agreement with the model. "
            f"{not_run} points are left without one: the bob meets a column there, and the "
            "engines' bob collides with nothing, as the model's. "
            f"Cost: {html.escape(cost)}; <code>{html.escape(str(s.get('command', '')))}</code>"
            f".</p><details><summary>Every point ({len(rows)})</summary>{table}</details>")
