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
           "label", "fmt_sci", "fmt_seconds", "fmt_pct", "cost_text", "AGREEMENT_RULE",
           "EXCUSED"]


# Settings that are bookkeeping, not the engine's numerical choices.
_NOT_SETTINGS = {"criterion", "t_max", "theta0", "psi0", "monitor", "engine_version", "t_cap",
                 "base_motion", "blowup_distance", "blowup_speed"}


def label(name: str) -> str:
    """Human name of a backend: its class's ``label`` (the name itself if it is
    not registered, e.g. an engine from a package no longer installed)."""
    from trilith_xval.engines import get_backend
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


# Causes that do not blame the engine: where the model is invalid, or its own
# threshold curve is discontinuous or has a window, the comparison is ill-posed.
EXCUSED = ("model", "jump", "window")
AGREEMENT_RULE = ("An engine agrees up to the highest model threshold A* such that every "
                  "point with A_model <= A* agrees within the tolerance (robust bracket) or "
                  "disagrees for a cause that does not blame the engine (" + ", ".join(EXCUSED)
                  + "); those exceptions are listed by cause.  The first point that "
                  "disagrees for an engine cause ends the region; every point beyond is "
                  "listed too.")


def threshold_agreement(points: list[dict], tolerance: float) -> dict:
    """How far up in amplitude an engine's thresholds agree with the model
    (:data:`AGREEMENT_RULE`).

    Returns ``n_points``, ``n_agree``, ``agree_up_to`` [m/s^2] (None when the
    lowest point already disagrees for an engine cause), ``omega_range`` of the
    agreeing points up to it, ``exceptions`` (excused points inside the region,
    by cause), ``first_disagreement`` (the point that ends it), ``failing``
    (every disagreeing point with its causes), ``isolated`` (points with
    isolated overturns) and ``rule``.
    """
    from trilith_xval.compare.campaign.summary import ThresholdResult
    pts = sorted((ThresholdResult.from_dict(p) for p in points),
                 key=lambda p: p.a_reference if p.a_reference is not None else math.inf)

    def ok(p):
        if p.cause is not None:
            return p.cause == "agrees"
        return p.rel_error is not None and p.bracketed and abs(p.rel_error) <= tolerance

    inside, first = [], None
    for p in pts:
        if not ok(p) and p.cause not in EXCUSED:
            first = p
            break
        inside.append(p)

    def brief(p):
        return {"case": p.case, "omega": p.omega, "a_reference": p.a_reference,
                "a_engine": p.a_engine, "a_survives": p.a_survives, "rel_error": p.rel_error,
                "rel_resolution": p.rel_resolution, "cause": p.cause,
                "cause_detail": p.cause_detail, "causes": [c.name for c in p.causes],
                "valid": p.valid, "n_isolated": len(p.isolated),
                "convergence": list(p.convergence)}

    agreeing = [p for p in inside if ok(p)]
    omegas = [p.omega for p in agreeing if p.omega is not None]
    exceptions: dict[str, list] = {}
    for p in inside:
        if not ok(p):
            exceptions.setdefault(p.cause, []).append(brief(p))
    return {"tolerance": tolerance, "n_points": len(pts), "n_agree": sum(map(ok, pts)),
            "agree_up_to": agreeing[-1].a_reference if agreeing else None,
            "omega_range": [min(omegas), max(omegas)] if omegas else None,
            "exceptions": exceptions,
            "first_disagreement": brief(first) if first else None,
            "failing": [brief(p) for p in pts if not ok(p)],
            "isolated": [brief(p) for p in pts if p.isolated],
            "rule": AGREEMENT_RULE}


def _median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def engine_cost(doc: dict, engine: str) -> dict:
    """CPU seconds (measured inside each run, when it was computed): per run
    (median over the A-D time histories), per threshold point (mean, with its
    runs), per simulated second (median over the points' searches), and an
    estimated spectrum (one point per frequency of the reference grids, both
    curves); ``points_from_store`` says how many points the run store served
    (they cost nothing now).  None where the summary holds no CPU time (a
    schema-2 summary held wall time only)."""
    from trilith_xval.compare.campaign.summary import ThresholdResult
    runs = [_num(c.get("test", {}).get("cpu_time")) for c in doc.get("comparisons", [])
            if c.get("backend") == engine]
    pts = [ThresholdResult.from_dict(p) for p in _points(doc, engine)]
    cpus = [p.cpu_s for p in pts if p.cpu_s is not None]
    n_runs = [p.n_runs for p in pts if p.n_runs]
    n_grid = sum(sum(a is not None for a in spec.get("a", []))
                 for spec in doc.get("spectra", {}).values())
    point = statistics.fmean(cpus) if cpus else None
    return {"run_cpu_s": _median(runs), "n_runs_timed": sum(r is not None for r in runs),
            "threshold_point_cpu_s": point,
            "runs_per_point": statistics.fmean(n_runs) if n_runs else None,
            "cpu_per_sim_s": _median([p.cpu_per_sim_s for p in pts]),
            "points_from_store": sum(p.from_store for p in pts), "n_points": len(pts),
            "spectrum_frequencies": n_grid,
            "spectrum_cpu_s": point * n_grid if (point is not None and n_grid) else None}


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
    """Seconds in the unit a reader expects: ms, s or min."""
    if x is None:
        return "not measured"
    if x < 1.0:
        ms = 1e3 * x
        return f"{ms:.0f} ms" if ms >= 10 else f"{ms:.2g} ms"
    if x < 120.0:
        return f"{x:.2g} s" if x < 10 else f"{x:.0f} s"
    return f"{x / 60.0:.2g} min"


def cost_text(cost: dict, *, unmeasured: str, per_point: str = "") -> str:
    """An engine's cost as the trust pages state it: median CPU per threshold point
    (``per_point`` says what it includes), CPU s per simulated s, and the CPU of the
    failing points' reruns when there were any; ``unmeasured`` when no threshold
    point was measured."""
    if cost.get("threshold_point_cpu_s") is None:
        return unmeasured
    parts = [f"{fmt_seconds(cost['threshold_point_cpu_s'])} CPU per threshold point{per_point}"]
    if cost.get("cpu_per_sim_s") is not None:
        parts.append(f"{cost['cpu_per_sim_s']:.3g} CPU s per simulated s")
    if cost.get("rerun_cpu_s"):
        parts.append("failing points remeasured (finer steps, causes): "
                     f"{fmt_seconds(cost['rerun_cpu_s'])} CPU")
    return "; ".join(parts)


def conclusion(engine: str, row: dict) -> str:
    """A short conclusion for one engine, template sentences filled from ``row``."""
    name = f"{label(engine)} ({row.get('version', 'unknown')})"
    dt = row["settings"].get("dt")
    head = f"{name}" + (f" at dt = {fmt_sci(dt)} s" if dt is not None else "")
    t_dt = row.get("threshold_dt")
    if dt is not None and t_dt is not None and t_dt != dt:  # its calibrated threshold step
        head += f" (threshold searches at {fmt_sci(t_dt)} s, docs/calibrate.md)"
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
    lr = row.get("long_run")
    if lr is not None and lr["value"] is not None:
        (good if lr["passed"] else bad).append(
            f"long runs (rest, and after a pulse, fixed window): {lr['detail']}")
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
            text = (f"overturning thresholds within {tol} up to A = {thr['agree_up_to']:.3g} "
                    f"m/s² (Ω {lo:g}-{hi:g} rad/s, {thr['n_agree']} of {thr['n_points']} "
                    f"points agree")
            exc = "; ".join(f"{cause}: Ω " + ", ".join(f"{p['omega']:g}" for p in pts)
                            for cause, pts in thr.get("exceptions", {}).items())
            good.append(text + (f"; exceptions where the model is no fair reference: {exc}"
                                if exc else "") + ")")
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
    if cost["run_cpu_s"] is not None or cost["threshold_point_cpu_s"] is not None:
        bits = []
        if cost["run_cpu_s"] is not None:
            bits.append(f"one run {fmt_seconds(cost['run_cpu_s'])}")
        if cost["threshold_point_cpu_s"] is not None:
            bits.append(f"a threshold point {fmt_seconds(cost['threshold_point_cpu_s'])} "
                        f"({cost['runs_per_point']:.2g} runs)")
        if cost["spectrum_cpu_s"] is not None:
            bits.append(f"a spectrum of {cost['spectrum_frequencies']} frequencies about "
                        f"{fmt_seconds(cost['spectrum_cpu_s'])}")
        store = (f"; {cost['points_from_store']} of {cost['n_points']} points were served "
                 "by the run store" if cost["points_from_store"] else "")
        parts.append("CPU time when computed: " + ", ".join(bits) + store + ".")
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
        for vid in ("restitution_eq20", "restitution_eq19", "verdicts_AD", "theta_first_impact",
                    "long_run"):
            row[vid] = _verdict(doc, vid, engine)
        if row["verdicts_AD"] is not None:
            row["verdicts_AD"]["n_cases"] = n_points_ad * (2 if has_pend else 1)
        row["thresholds"] = threshold_agreement(_points(doc, engine), tol)
        row["cost"] = engine_cost(doc, engine)
        row["settings"] = key_settings(doc, engine)
        if engine in (doc.get("threshold_settings") or {}):  # their own step
            row["threshold_dt"] = doc["threshold_settings"][engine].get("dt")
        if doc.get("threshold_domain"):  # summaries from before domains had none
            row["threshold_domain"] = doc["threshold_domain"].get(engine)
        mine = [v for v in doc.get("verdicts", []) if v.get("backend") == engine]
        row["verdicts"] = {"passed": sum(bool(v.get("passed")) for v in mine),
                           "total": len(mine)}
        row["conclusion"] = conclusion(engine, row)
        out[engine] = row
    return out
