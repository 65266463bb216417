"""The verdict table: each measured metric against its tolerance, per engine.

Values are computed from the campaign's measurements (never typed in); a metric
that could not be measured (no impact, threshold not bracketed) fails with
``value = None`` rather than passing silently.
"""
from __future__ import annotations

import math

__all__ = ["build_verdicts", "VERDICT_IDS"]

# Stable ids of the verdict rows (summary.json ``verdicts[*].id``): scripts key on
# these, never on the human-readable ``metric`` text, which may be reworded.
VERDICT_IDS = ("restitution_eq20", "restitution_eq19", "threshold_pendulum",
               "threshold_no_pendulum", "verdicts_AD", "theta_first_impact", "long_run")


def _finite(values) -> list[float]:
    return [float(v) for v in values if v is not None and math.isfinite(float(v))]


def _row(vid: str, metric: str, backend: str, values: list, tolerance: float, reason: str,
         unit: str, n_expected: int, absolute: bool = True) -> dict:
    """Worst case of ``values`` against ``tolerance``; any missing value fails."""
    vals = _finite(abs(v) if (absolute and v is not None) else v for v in values)
    missing = n_expected - len(vals)
    value = max(vals) if vals else None
    passed = bool(vals) and missing == 0 and value <= tolerance
    detail = f"worst of {len(vals)}" + (f"; {missing} not measured" if missing else "")
    return {"id": vid, "metric": metric, "backend": backend, "value": value, "tolerance": tolerance,
            "passed": passed, "unit": unit, "reason": reason, "detail": detail}


def _n_errors(result, job: str, backend: str, pendulum: bool) -> int:
    return sum(1 for e in result.errors
               if e["job"] == job and e["backend"] == backend and e["pendulum"] == pendulum)


def build_verdicts(result) -> list[dict]:
    """Verdict rows for every engine of ``result`` (a :class:`CampaignResult`).
    Jobs that raised count as unmeasured, so their row fails."""
    cfg = result.config
    tol = cfg.tolerances
    why = tol.reasons()
    rows: list[dict] = []
    for name in cfg.engines:
        for vid, pend, metric, tolerance, key in (
                ("restitution_eq20", False, "restitution vs Eq. 20 (max rel. error)",
                 tol.restitution, "restitution"),
                ("restitution_eq19", True, "restitution vs Eq. 19 (max rel. error)",
                 tol.restitution_pendulum, "restitution_pendulum")):
            runs = [r for r in result.restitution if r["backend"] == name and r["pendulum"] == pend]
            n_err = _n_errors(result, "restitution", name, pend)
            if not runs and not n_err:
                continue
            # Every run must deliver at least one impact; each run's worst impact counts.
            values = [r["max_rel_error"] if r["impacts"] else None for r in runs]
            rows.append(_row(vid, metric, name, values, tolerance, why[key], "relative",
                             len(runs) + n_err))
        for case, label in (("pendulum", "with pendulum"), ("no_pendulum", "without pendulum")):
            points = result.spectra.get(case, {}).get("engines", {}).get(name, [])
            n_err = _n_errors(result, "threshold", name, case == "pendulum")
            if not points and not n_err:
                continue
            values = [p["rel_error"] if p["bracketed"] else None for p in points]
            row = _row(f"threshold_{case}",
                       f"overturning threshold {label}, away from jumps (max rel. error)",
                       name, values, tol.threshold, why["threshold"], "relative",
                       len(points) + n_err)
            irregular = sum(p["irregular_runs"] for p in points)
            if irregular:  # 'unstable'/'undecided' runs count as survived in the bisection
                row["detail"] += f"; {irregular} unstable/undecided/collapsed engine runs"
            rows.append(row)
        comps = [c for c in result.comparisons if c["backend"] == name]
        n_cases = len(cfg.points) * (2 if result.scene.has_pendulum else 1)
        if cfg.points:
            mismatches = [c for c in comps if not c["verdict_agrees"]]
            # A case that could not be run counts as a disagreement.
            n_bad = len(mismatches) + (n_cases - len(comps))
            rows.append({
                "id": "verdicts_AD", "metric": "verdict disagreements at A-D (status and mode)",
                "backend": name,
                "value": n_bad, "tolerance": tol.verdict_mismatches,
                "passed": n_bad <= tol.verdict_mismatches, "unit": "count",
                "reason": why["verdict_mismatches"],
                "detail": ", ".join(f"{c['point']}{'+p' if c['pendulum'] else ''}: "
                                    f"{c['status_test']}/{c['mode_test']} vs "
                                    f"{c['status_reference']}/{c['mode_reference']}"
                                    for c in mismatches) or f"{len(comps)} cases agree"})
            rows.append(_row("theta_first_impact",
                             "theta RMS error / alpha before the first impact (A-D)", name,
                             [c["theta_rms_first"] for c in comps], tol.theta_rms_first,
                             why["theta_rms_first"], "fraction of alpha", n_cases))
        longs = [r for r in getattr(result, "long_runs", []) if r["backend"] == name]
        if longs:
            from trilith_xval.compare.measure.long_runs import MAX_CREEP
            bad = [r for r in longs if not r["passed"]]
            rows.append({
                "id": "long_run", "metric": "long runs (fixed window, no early stop): verdict "
                "as the model's, pivot creep (max, m)", "backend": name,
                "value": max(r["pivot_sliding"] for r in longs), "tolerance": MAX_CREEP,
                "passed": not bad, "unit": "m",
                "reason": "the model's verdict over the same window; pivots slide < 1 mm, a "
                          "tenth of the monitor's collapse limit",
                "detail": "; ".join(f"{r['case']} ({r['scene']}): {r['detail']}"
                                    for r in longs)
                + _stored_note(longs)})
    return rows


def _stored_note(rows: list) -> str:
    """Where rows shown from a stored run came from (empty when measured now)."""
    label = next((r["stored"] for r in rows if r.get("stored")), None)
    if not label:
        return ""
    return (f"; from {label.get('file', 'the stored run')} (run "
            f"{str(label.get('run_commit') or label.get('commit') or '?')[:12]}, "
            f"{label.get('run_date') or label.get('date') or 'date not recorded'})")
