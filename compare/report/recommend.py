"""One recommendation line per use of an engine, read off the trust table.

A reader of the validation report mostly wants "which engine, at which step,
for what I am about to do".  The uses are the campaign's checks grouped by
what a user computes:

* **overturning thresholds** (spectra, maps): every threshold point within the
  tolerance; an engine whose disagreements all converge at a smaller step
  (cause ``discretisation`` with "dt <= X s meets") is recommended at that step;
  points where the model itself is invalid (cause ``model``) count against no
  engine;
* **restitution without the pendulum** (Eq. 20) and **with it** (Eq. 19 at the
  measured psi);
* **time histories** (the paper's verdicts at A-D and theta(t) before the first
  impact);
* **long runs** (tens of seconds at rest and after a pulse: the pivots must not
  creep).

Engines not recommended are named with the number that excludes them, so the
line is checked against the tables below it, never typed.
"""
from __future__ import annotations

import re

from trilith_xval.compare.report.cells import cause_phrase
from trilith_xval.compare.report.trust import fmt_pct, fmt_sci, fmt_seconds, label

__all__ = ["recommendations"]

_DT_MEETS = re.compile(r"dt <= ([0-9.eE+-]+) s (?:meets|would meet)")


def _dt(row: dict, thresholds: bool = False) -> str:
    """The step an engine ran at: its threshold searches' (``thresholds``) or its
    default one."""
    dt = row.get("threshold_dt") if thresholds else None
    dt = dt if dt is not None else row.get("settings", {}).get("dt")
    return "its default step" if dt is None else f"dt = {fmt_sci(dt)} s"


def _thresholds(trust: dict) -> str | None:
    good, finer, bad = [], [], []
    for e, row in sorted(trust.items(), key=lambda kv: _point_cost(kv[1])):
        t = row["thresholds"]
        if not t["n_points"]:
            continue
        blamed = [p for p in t["failing"] if p.get("cause") != "model"]
        cost = row["cost"].get("threshold_point_cpu_s")
        at = _dt(row, thresholds=True) + (f", {fmt_seconds(cost)} CPU per point"
                                          if cost is not None else "")
        if not blamed:
            good.append((label(e), at))
            continue
        steps = [_DT_MEETS.search(p.get("cause_detail") or "") for p in blamed]
        if all(p.get("cause") == "discretisation" for p in blamed) and all(steps):
            finer.append((label(e),
                          f"dt ≤ {fmt_sci(min(float(m.group(1)) for m in steps))} s"))
        else:
            worst = max(blamed, key=lambda p: abs(p["rel_error"] or 0.0))
            err = ("not bracketed" if worst["rel_error"] is None
                   else f"{100 * worst['rel_error']:+.1f} %")
            bad.append(f"{label(e)} ({err} at Ω = {worst['omega']:g} rad/s, "
                       f"{cause_phrase(worst.get('cause'))})")
    line = _line("Overturning thresholds, cheapest that passes first", good + finer, bad,
                 ordered=True)
    return None if line is None else line[:-1] + _domain_sentence(trust) + "."


def _point_cost(row: dict) -> float:
    cost = row.get("cost", {}).get("threshold_point_cpu_s")
    return float("inf") if cost is None else cost


def _domain_sentence(trust: dict) -> str:
    """Where the calibrated threshold steps hold, and which engines run their
    reference step on this scene."""
    inside, outside = [], []
    for e, row in trust.items():
        dom = row.get("threshold_domain") or {}
        if not dom.get("calibrated"):
            continue
        (inside if dom.get("inside") else outside).append(label(e))
    if not inside and not outside:
        return ""
    groups: dict[str, list[str]] = {}
    for e, row in trust.items():
        dom = row.get("threshold_domain") or {}
        if dom.get("calibrated") and dom.get("domain"):
            text = ", ".join(f"{k.replace('_over_', '/')} {v[0]:g}-{v[1]:g}"
                             for k, v in dom["domain"].items() if isinstance(v, list))
            groups.setdefault(text, []).append(label(e))
    ranges = "; ".join(f"{', '.join(names)}: {text}" for text, names in groups.items())
    text = (". Calibrated threshold steps hold inside the domain of their calibration"
            + (f" ({ranges})" if ranges else "") + " (engines/NAME_/thresholds.toml, "
            "docs/calibrate.md)")
    if outside:
        text += ("; this scene is outside it, so " + ", ".join(outside)
                 + " ran the reference step")
    return text


def _verdict_use(trust: dict, title: str, key: str, what) -> str | None:
    good, bad = [], []
    for e, row in trust.items():
        v = row.get(key)
        if v is None or v.get("value") is None:
            continue
        if v["passed"]:
            good.append((label(e), _dt(row)))
        else:
            bad.append(f"{label(e)} ({what(v, row)})")
    return _line(title, good, bad)


def _histories(trust: dict) -> str | None:
    good, bad = [], []
    for e, row in trust.items():
        checks = [row.get(k) for k in ("verdicts_AD", "theta_first_impact")]
        checks = [c for c in checks if c is not None and c.get("value") is not None]
        if not checks:
            continue
        if all(c["passed"] for c in checks):
            good.append((label(e), _dt(row)))
        else:
            bad.append(label(e))
    return _line("Time histories (verdicts at A-D, θ(t) to the first impact)", good, bad)


def _line(title: str, good: list[tuple[str, str]], bad: list[str],
          ordered: bool = False) -> str | None:
    """``title: A or B at dt = X; C at dt <= Y; not D (why)``: the engines that
    pass, grouped by the step they pass at (each in its own place when
    ``ordered``: cheapest first), then the ones that do not."""
    if not good and not bad:
        return None
    if ordered:
        groups = [f"{name} at {step}" for name, step in good]
    else:
        steps: dict[str, list[str]] = {}
        for name, step in good:
            steps.setdefault(step, []).append(name)
        groups = [(", ".join(n[:-1]) + " or " + n[-1] if len(n) > 1 else n[0])
                  + f" at {step}" for step, n in steps.items()]
    text = f"{title}: " + ("; ".join(groups) if groups else "no engine passes")
    if bad:
        text += "; not " + ", not ".join(bad)
    return text + "."


def recommendations(doc: dict) -> list[str]:
    """The recommendation lines of the summary document ``doc`` (its ``trust``
    table), one per use that the campaign measured."""
    trust = doc.get("trust", {})

    def off(v, row):
        return f"off by {fmt_pct(v['value'])}, tolerance {fmt_pct(v['tolerance'])}"

    lines = [_thresholds(trust),
             _verdict_use(trust, "Restitution without the pendulum (Eq. 20)",
                          "restitution_eq20", off),
             _verdict_use(trust, "Restitution with the pendulum (Eq. 19)",
                          "restitution_eq19", lambda v, row: off(v, row) + _worst_lam(doc, row)),
             _histories(trust),
             _verdict_use(trust, "Long runs (rest, and rocking after a pulse)", "long_run",
                          lambda v, row: f"pivots slid {1e3 * v['value']:.2g} mm, tolerance "
                                         f"{1e3 * v['tolerance']:.2g} mm")]
    return [line for line in lines if line]


def _worst_lam(doc: dict, row: dict) -> str:
    """", worst at λ = 7" for the engine of ``row``: the pendulum restitution case
    with the largest error."""
    cases = [r for r in doc.get("restitution", []) if r.get("pendulum")
             and label(r.get("backend", "")) == row.get("label")
             and r.get("max_rel_error") is not None]
    if not cases:
        return ""
    worst = max(cases, key=lambda r: abs(r["max_rel_error"]))
    return f", worst at λ = {worst['lam']:g}"
