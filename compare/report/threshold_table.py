"""The validation report's table of engine threshold points: one flat record per
point (SI numbers, g and Hz beside; the model's validity there), exported as CSV
(``thresholds.csv``) and shown as rows of :data:`compare.report.tables.HEADERS`
``["thresholds"]``.  Used by :mod:`compare.report.html`.
"""
from __future__ import annotations

from trilith_xval.compare.report import units
from trilith_xval.compare.report.cells import _cell, cause_phrase
from trilith_xval.compare.report.trust import fmt_seconds, fmt_sci, label
from trilith_xval.compare.report.units import TWO_PI

__all__ = ["threshold_points", "threshold_csv", "threshold_rows"]


def _validity_at(case, omega) -> dict | None:
    """The model's validity on its own threshold run at ``omega`` (the case's
    ``model_validity`` list, aligned with its ``omega``; written by
    :func:`compare.report.html.add_model_validity`), or None."""
    val = case.raw.get("model_validity")
    if not val or omega is None:
        return None
    for w, v in zip(case.omega, val):
        if w is not None and abs(w - omega) < 1e-9:
            return v
    return None


def _point_validity(case, p) -> tuple[bool | None, str]:
    """``(valid, reason)`` of the model at an engine point: the point's own
    checks (at the model's and the engine's thresholds and along the bracket)
    when the campaign made them, else the model's threshold run at its Ω."""
    if p.valid is not None or p.cause == "model":
        bad = [v for v in p.validity if not v.valid]
        reason = "; ".join(f"{v.where}: {v.reason}" for v in bad) or p.cause_detail
        return (False, reason) if (p.valid is False or p.cause == "model") else (True, "")
    v = _validity_at(case, p.omega) or {}
    return v.get("model_valid"), v.get("model_reason", "")


def threshold_points(doc: dict) -> list[dict]:
    """Every engine threshold point as a flat record (SI numbers, g and Hz
    beside), for the CSV export and the table; read through the typed summary
    (:class:`compare.campaign.summary.Summary`)."""
    from trilith_xval.compare.campaign.summary import Summary

    summary = Summary.from_dict(doc)
    tol = summary.threshold_tolerance
    out = []
    for case in summary.spectra.values():
        for name, pts in case.engines.items():
            for p in pts:
                err, w = p.rel_error, p.omega
                valid, reason = _point_validity(case, p)
                resolution = p.rel_resolution if p.rel_resolution is not None else p.rel_tol
                out.append({
                    "case": case.name, "engine": name, "omega_rad_s": w,
                    "f_hz": None if w is None else w / TWO_PI,
                    "pulse_period_s": None if not w else TWO_PI / w,
                    "a_model_m_s2": p.a_reference,
                    "a_model_g": None if p.a_reference is None else p.a_reference / units.G,
                    "a_engine_m_s2": p.a_engine, "a_survives_m_s2": p.a_survives,
                    "rel_error": err, "rel_resolution": resolution, "tolerance_rel": tol,
                    "within_tolerance": err is not None and abs(err) <= tol,
                    "mode_model": p.mode_reference, "mode_engine": p.mode_engine,
                    "model_valid": valid, "model_reason": reason,
                    "cause": p.cause, "cause_detail": p.cause_detail, "n_runs": p.n_runs,
                    "dt_s": p.dt, "cpu_s": p.cpu_s, "from_store": p.from_store})
    return out


def threshold_csv(doc: dict) -> str:
    """:func:`threshold_points` as CSV: one row per engine point, numbers in SI
    at full precision (empty: not measured)."""
    import csv
    import io

    pts = threshold_points(doc)
    buf = io.StringIO()
    fields = list(pts[0]) if pts else ["case", "engine"]
    w = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    for p in pts:
        w.writerow({k: "" if v is None else (f"{v:.12g}" if isinstance(v, float) else v)
                    for k, v in p.items()})
    return buf.getvalue()


def _valid_cell(valid: bool | None, reason: str) -> dict:
    if valid is None:
        return _cell("not checked")
    return _cell("yes") if valid else _cell("no (engine not blamed)", None, reason)


def threshold_rows(doc: dict) -> list[list]:
    rows = []
    for p in threshold_points(doc):
        ok = p["within_tolerance"]
        if not ok and p["model_valid"] is False:
            ok = None  # the model is invalid there: no engine is to blame
        w = p["omega_rad_s"]
        rows.append([p["case"].replace("_", " "), label(p["engine"]),
                     "n/a" if w is None else f"{w:g} ({p['f_hz']:.2g} Hz)",
                     units.accel(p["a_model_m_s2"]), units.accel(p["a_engine_m_s2"]),
                     _cell(units.rel_error(p["rel_error"], p["rel_resolution"]), ok),
                     f"{p['mode_model'] or '—'} / {p['mode_engine'] or '—'}",
                     _valid_cell(p["model_valid"], p["model_reason"]),
                     f"{p['n_runs']}" + ("" if p["dt_s"] is None
                                         else f" at dt {fmt_sci(p['dt_s'])} s"),
                     _cell(cause_phrase(p["cause"]), None,
                           "" if p["cause"] == "agrees" else (p["cause_detail"] or "")),
                     fmt_seconds(p["cpu_s"]) + (" (store)" if p["from_store"] else "")])
    return rows
