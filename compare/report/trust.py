"""The trust table: per engine, what it reproduces, up to where, why not beyond,
at what cost and with which settings; and a conclusion in words.

Everything is computed from the campaign's summary document (``summary.json``,
plain JSON: non-finite numbers are ``None``), never typed in, so a stored
summary gives the same table.  Fields the campaign did not measure (e.g. the
cause of a threshold disagreement, added by newer campaigns) read "not
measured".
"""
from __future__ import annotations

import math
import statistics

__all__ = ["trust_table", "threshold_agreement", "engine_cost", "key_settings", "conclusion",
           "label", "fmt_sci", "fmt_seconds", "fmt_pct"]


# Settings that are bookkeeping, not the engine's numerical choices.
_NOT_SETTINGS = {"criterion", "t_max", "theta0", "psi0", "monitor", "engine_version", "t_cap",
                 "base_motion", "blowup_distance", "blowup_speed"}


def label(name: str) -> str:
    """Human name of a backend: its class's ``label`` (the name itself if it is
    not registered, e.g. an engine from a package no longer installed)."""
    from engines import get_backend
    try:
        return get_backend(name).label
    except ValueError:
        return name


def _num(value) -> float | None:
    if value is None or isinstance(value, bool):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _verdict(doc: dict, vid: str, engine: str) -> dict | None:
    for v in doc.get("verdicts", []):
        if v.get("id") == vid and v.get("backend") == engine:
            return {k: v.get(k) for k in ("value", "tolerance", "passed", "unit", "detail")}
    return None


def _points(doc: dict, engine: str) -> list[dict]:
    out = []
    for case, spec in doc.get("spectra", {}).items():
        for p in spec.get("engines", {}).get(engine, []):
            out.append({**p, "case": case})
    return out


def threshold_agreement(points: list[dict], tolerance: float) -> dict:
    """How far up in amplitude an engine's thresholds agree with the model.

    Points are taken in order of the model's threshold ``a_reference``; the
    engine *agrees up to* the highest one reached before the first point whose
    ``|rel_error|`` exceeds ``tolerance`` (or was not bracketed).  Returns
    ``n_points``, ``n_agree``, ``agree_up_to`` [m/s^2] (None when the lowest
    point already disagrees), ``omega_range`` of the agreeing points below it,
    ``first_disagreement`` (that point) and ``failing`` (every disagreeing point,
    with its measured ``cause``/``cause_detail``/``convergence`` when present).
    """
    pts = sorted(points, key=lambda p: (_num(p.get("a_reference")) or math.inf))

    def ok(p):
        err = _num(p.get("rel_error")) if p.get("bracketed", True) else None
        return err is not None and abs(err) <= tolerance

    below, first = [], None
    for p in pts:
        if not ok(p):
            first = p
            break
        below.append(p)
    failing = [p for p in pts if not ok(p)]

    def brief(p):
        return {"case": p.get("case"), "omega": _num(p.get("omega")),
                "a_reference": _num(p.get("a_reference")), "a_engine": _num(p.get("a_engine")),
                "rel_error": _num(p.get("rel_error")),
                "cause": p.get("cause"), "cause_detail": p.get("cause_detail"),
                "convergence": p.get("convergence")}

    omegas = [_num(p.get("omega")) for p in below]
    return {"tolerance": tolerance, "n_points": len(pts), "n_agree": len(pts) - len(failing),
            "agree_up_to": _num(below[-1].get("a_reference")) if below else None,
            "omega_range": [min(omegas), max(omegas)] if omegas else None,
            "first_disagreement": brief(first) if first else None,
            "failing": [brief(p) for p in failing]}


def engine_cost(doc: dict, engine: str) -> dict:
    """Wall time per engine run (median over the A-D time histories), per
    threshold point (mean bisection), runs per point, and an estimated spectrum:
    one threshold point per frequency of the reference grids (both curves)."""
    runs = [_num(c.get("test", {}).get("wall_time")) for c in doc.get("comparisons", [])
            if c.get("backend") == engine]
    runs = [r for r in runs if r is not None]
    pts = _points(doc, engine)
    walls = [_num(p.get("provenance", {}).get("wall_time")) for p in pts]
    walls = [w for w in walls if w is not None]
    n_runs = [p.get("n_runs") for p in pts if p.get("n_runs")]
    n_grid = sum(sum(a is not None for a in spec.get("a", []))
                 for spec in doc.get("spectra", {}).values())
    point = statistics.fmean(walls) if walls else None
    return {"run_s": statistics.median(runs) if runs else None, "n_runs_timed": len(runs),
            "threshold_point_s": point,
            "runs_per_point": statistics.fmean(n_runs) if n_runs else None,
            "spectrum_frequencies": n_grid,
            "spectrum_s": point * n_grid if (point is not None and n_grid) else None}


def key_settings(doc: dict, engine: str) -> dict:
    """The engine's numerical settings that produced the numbers (time step,
    solver iterations, contact parameters; bookkeeping left out)."""
    s = doc.get("settings", {}).get(engine, {})
    return {k: v for k, v in s.items() if k not in _NOT_SETTINGS and v is not None
            and not isinstance(v, (dict, list))}


def fmt_pct(x: float | None, digits: int = 2) -> str:
    return "not measured" if x is None else f"{100.0 * x:.{digits}g} %"


def fmt_sci(x: float | None, digits: int = 2) -> str:
    """``3.3e-4`` style (no ``e-04`` padding); 'not measured' for None."""
    if x is None:
        return "not measured"
    if x == 0 or 1e-2 <= abs(x) < 1e4:
        return f"{x:.{digits}g}"
    mant, exp = f"{x:.{digits - 1}e}".split("e")
    mant = mant.rstrip("0").rstrip(".") if "." in mant else mant
    return f"{mant}e{int(exp)}"


def fmt_seconds(x: float | None) -> str:
    """Wall time in the unit a reader expects: ms, s or min."""
    if x is None:
        return "not measured"
    if x < 1.0:
        ms = 1e3 * x
        return f"{ms:.0f} ms" if ms >= 10 else f"{ms:.2g} ms"
    if x < 120.0:
        return f"{x:.2g} s" if x < 10 else f"{x:.0f} s"
    return f"{x / 60.0:.2g} min"


def conclusion(engine: str, row: dict) -> str:
    """A short conclusion for one engine, template sentences filled from ``row``."""
    name = f"{label(engine)} ({row.get('version', 'unknown')})"
    dt = row["settings"].get("dt")
    head = f"{name}" + (f" at dt = {fmt_sci(dt)} s" if dt is not None else "")
    good, bad = [], []
    for key, what in (("restitution_eq20", "restitution against Eq. 20"),
                      ("restitution_eq19", "restitution against Eq. 19")):
        v = row.get(key)
        if v is None or v["value"] is None:
            continue
        text = f"{what} within {fmt_pct(v['value'])} (tolerance {fmt_pct(v['tolerance'])})"
        (good if v["passed"] else bad).append(text if v["passed"] else
                                              f"{what}: off by {fmt_pct(v['value'])} "
                                              f"(tolerance {fmt_pct(v['tolerance'])})")
    ad = row.get("verdicts_AD")
    if ad is not None and ad["value"] is not None:
        n_cases = ad.get("n_cases")
        text = (f"the paper's verdicts at A-D ({n_cases - ad['value']} of {n_cases} cases)"
                if n_cases else "the paper's verdicts at A-D")
        (good if ad["passed"] else bad).append(
            text if ad["passed"] else f"the paper's verdicts at A-D: {ad['value']} disagree")
    th = row.get("theta_first_impact")
    if th is not None and th["value"] is not None:
        (good if th["passed"] else bad).append(
            f"θ(t) before the first impact within {fmt_sci(th['value'])} α (RMS)" if th["passed"]
            else f"θ(t) before the first impact: RMS error {fmt_sci(th['value'])} α "
                 f"(tolerance {fmt_sci(th['tolerance'])} α)")
    thr = row["thresholds"]
    if thr["n_points"]:
        tol = fmt_pct(thr["tolerance"])
        if thr["agree_up_to"] is not None:
            lo, hi = thr["omega_range"]
            good.append(f"overturning thresholds within {tol} up to A = "
                        f"{thr['agree_up_to']:.3g} m/s² (Ω {lo:g}-{hi:g} rad/s, "
                        f"{thr['n_agree']} of {thr['n_points']} points agree)")
        first = thr["first_disagreement"]
        if first is not None:
            err = first["rel_error"]
            cause = first.get("cause") or "not measured"
            detail = f": {first['cause_detail']}" if first.get("cause_detail") else ""
            bad.append(f"the threshold at A = {first['a_reference']:.3g} m/s², "
                       f"Ω = {first['omega']:g} rad/s ("
                       + (f"{100 * err:+.2g} %" if err is not None else "not bracketed")
                       + f"; cause: {cause}{detail})")
    parts = [head + " reproduces " + ("; ".join(good) if good else "none of the checks") + "."]
    if bad:
        parts.append("It does not reproduce " + "; ".join(bad) + ".")
    cost = row["cost"]
    if cost["run_s"] is not None:
        text = f"One run costs {fmt_seconds(cost['run_s'])}"
        if cost["spectrum_s"] is not None:
            text += (f", a threshold point {fmt_seconds(cost['threshold_point_s'])} "
                     f"({cost['runs_per_point']:.2g} runs) and a spectrum of "
                     f"{cost['spectrum_frequencies']} frequencies about "
                     f"{fmt_seconds(cost['spectrum_s'])}")
        parts.append(text + " (wall time on the measuring machine).")
    return " ".join(parts)


def trust_table(doc: dict) -> dict[str, dict]:
    """Per engine of ``doc["config"]["engines"]``: the trust-table row and its
    ``conclusion``.  ``doc`` is the summary document (see module docstring)."""
    tol = doc.get("config", {}).get("tolerances", {}).get("threshold", 0.02)
    n_points_ad = len(doc.get("config", {}).get("points", []))
    has_pend = bool(doc.get("scene", {}).get("gamma"))
    out = {}
    for engine in doc.get("config", {}).get("engines", []):
        row = {"version": doc.get("versions", {}).get(engine, "unknown"),
               "label": label(engine)}
        for vid in ("restitution_eq20", "restitution_eq19", "verdicts_AD", "theta_first_impact"):
            row[vid] = _verdict(doc, vid, engine)
        if row["verdicts_AD"] is not None:
            row["verdicts_AD"]["n_cases"] = n_points_ad * (2 if has_pend else 1)
        row["thresholds"] = threshold_agreement(_points(doc, engine), tol)
        row["cost"] = engine_cost(doc, engine)
        row["settings"] = key_settings(doc, engine)
        mine = [v for v in doc.get("verdicts", []) if v.get("backend") == engine]
        row["verdicts"] = {"passed": sum(bool(v.get("passed")) for v in mine),
                           "total": len(mine)}
        row["conclusion"] = conclusion(engine, row)
        out[engine] = row
    return out
