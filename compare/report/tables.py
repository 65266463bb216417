"""The validation report's tables: rows built from the summary document
(``summary.json``), rendered as HTML or Markdown by :func:`table` (the engine
threshold points: :mod:`compare.report.threshold_table`).  Used by
:mod:`compare.report.html`."""
from __future__ import annotations

import math

from trilith_xval.compare.report import units
from trilith_xval.compare.report.cells import _cell, cause_phrase, csv_text, table
from trilith_xval.compare.report.threshold_table import (  # noqa: F401  (in __all__)
    threshold_csv, threshold_points, threshold_rows)
from trilith_xval.compare.report.trust import fmt_pct, fmt_sci, fmt_seconds, label
from trilith_xval.compare.report.units import TWO_PI

__all__ = ["HEADERS", "table", "csv_text", "error_rows", "history_rows", "jump_rows",
           "provenance_rows", "restitution_rows", "threshold_rows", "threshold_points",
           "threshold_csv", "timing_rows", "trust_rows", "verdict_rows", "settings_rows",
           "key_value_rows", "cause_phrase"]

_JOBS = {"threshold": "overturning thresholds (bisections)", "history": "time histories A-D",
         "restitution": "free-rocking restitution", "jump": "mode-jump frequency",
         "long_run": "long runs (fixed window)"}
_TIMINGS = {"reference_spectra": "reference spectra (analytic model, both curves)",
            "engine_runs_wall": "all jobs, wall time (parallel)",
            "total": "whole campaign, wall time"}


# ---------------------------------------------------------------- formatting
def _value(v: dict, bracket: float | None = None) -> str:
    """A verdict value in the unit of its tolerance: percent, alpha or a count;
    a threshold error (``bracket``: the bisection's relative width) at the
    bracket's resolution."""
    x, unit = v.get("value"), v.get("unit")
    if x is None:
        return "not measured"
    if bracket is not None and unit == "relative":
        return units.rel_error(x, bracket).lstrip("+")
    if unit == "relative":
        return fmt_pct(x)
    if unit == "fraction of alpha":
        return f"{fmt_sci(x)} α"
    if unit == "m":
        return f"{fmt_sci(x)} m"
    return str(x)


def _tolerance(v: dict) -> str:
    unit, tol = v.get("unit"), v.get("tolerance")
    if unit == "relative":
        return f"≤ {fmt_pct(tol)}"
    if unit == "fraction of alpha":
        return f"≤ {fmt_sci(tol)} α"
    if unit == "m":
        return f"≤ {fmt_sci(tol)} m"
    return f"≤ {tol}"


def _num(x, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return f"{x:.{digits}g}" if isinstance(x, float) else str(x)


def _status(status, mode) -> str:
    return f"{status} ({mode})" if mode else str(status)


# ---------------------------------------------------------------- tables
def trust_rows(doc: dict) -> tuple[list[str], list[list]]:
    trust = doc["trust"]
    engines = list(trust)
    tols = doc["config"]["tolerances"]
    header = ["check (tolerance)"] + [trust[e]["label"] for e in engines]

    def verdict_cell(row, key):
        v = row.get(key)
        return _cell("not measured") if v is None else _cell(_value(v), v["passed"])

    def thresholds(row):
        t = row["thresholds"]
        if not t["n_points"]:
            return _cell("not measured")
        if t["agree_up_to"] is None:
            text = "none agree"
        else:
            lo, hi = t["omega_range"]
            span = (f"Ω {lo:g} rad/s ({lo / TWO_PI:.2g} Hz)" if lo == hi else
                    f"Ω {lo:g} to {hi:g} rad/s ({lo / TWO_PI:.2g} to {hi / TWO_PI:.2g} Hz)")
            text = f"A ≤ {units.accel(t['agree_up_to'])}, {span}"
        return _cell(f"{text}; {t['n_agree']} of {t['n_points']} points",
                     t["n_agree"] == t["n_points"])

    def causes(row):
        t = row["thresholds"]
        if not t["n_points"]:
            return _cell("not measured")
        if not t["failing"]:
            return _cell("all agree")
        short, long = [], []
        for p in t["failing"]:
            err = units.rel_error(p["rel_error"])
            where = f"Ω {p['omega']:g} rad/s{'' if p['case'] == 'pendulum' else ' (no pend.)'}"
            short.append(f"{where}: {err}, {cause_phrase(p.get('cause'))}")
            long.append(f"{where}: {p.get('cause_detail') or 'not measured'}")
        blamed = any(p.get("cause") != "model" for p in t["failing"])
        return _cell("; ".join(short), False if blamed else None, "; ".join(long))

    def ad(row):
        v = row.get("verdicts_AD")
        if v is None or v["value"] is None:
            return _cell("not measured")
        n = v.get("n_cases") or 0
        return _cell(f"{n - v['value']} of {n} agree", v["passed"])

    def cost(row, key):
        c = row["cost"]
        if key == "run":
            return _cell("not measured" if c["run_cpu_s"] is None
                         else fmt_seconds(c["run_cpu_s"]) + " CPU")
        if c["threshold_point_cpu_s"] is None:
            return _cell("not measured")
        return _cell(f"{fmt_seconds(c['threshold_point_cpu_s'])} CPU per point "
                     f"({c['runs_per_point']:.2g} runs); ≈ {fmt_seconds(c['spectrum_cpu_s'])} "
                     f"for {c['spectrum_frequencies']} frequencies")

    def settings(row):
        # The steps the recommendation names: the threshold searches' (calibrated
        # inside its domain, else the reference) beside the other checks'.
        dt, t_dt = row["settings"].get("dt"), row.get("threshold_dt")
        text = "defaults" if dt is None else f"dt = {fmt_sci(dt)} s"
        if t_dt is not None:
            dom = row.get("threshold_domain") or {}
            why = ("calibrated, this scene inside its domain" if dom.get("calibrated")
                   and dom.get("inside") else "reference step: scene outside the "
                   "calibration's domain" if dom.get("calibrated") else "reference step")
            text = (f"thresholds at dt = {fmt_sci(t_dt)} s ({why}); restitution and θ(t) "
                    f"at {text}" if t_dt != dt or dom else text)
        return _cell(text + "; all settings in the table below")

    spec = [("restitution vs Eq. 20, worst impact", f"≤ {fmt_pct(tols['restitution'])}",
             lambda r: verdict_cell(r, "restitution_eq20")),
            ("restitution vs Eq. 19 at the measured ψ",
             f"≤ {fmt_pct(tols['restitution_pendulum'])}",
             lambda r: verdict_cell(r, "restitution_eq19")),
            ("the paper's verdicts at A-D, status and mode", "all must agree", ad),
            ("θ(t) RMS error before the first impact", f"≤ {fmt_sci(tols['theta_rms_first'])} α",
             lambda r: verdict_cell(r, "theta_first_impact")),
            ("overturning thresholds agree up to", f"within {fmt_pct(tols['threshold'])}",
             thresholds),
            ("where thresholds disagree: measured cause", "", causes),
            ("cost per run: median CPU time at A-D", "", lambda r: cost(r, "run")),
            ("cost per threshold point and per spectrum", "", lambda r: cost(r, "spectrum")),
            ("settings that achieve it", "", settings),
            ("verdicts passed", "", lambda r: _cell(
                f"{r['verdicts']['passed']} of {r['verdicts']['total']}",
                r["verdicts"]["passed"] == r["verdicts"]["total"]))]
    rows = [[f"{name} ({tol})" if tol else name] + [fn(trust[e]) for e in engines]
            for name, tol, fn in spec]
    return header, rows


def verdict_rows(doc: dict) -> list[list]:
    bracket = doc.get("config", {}).get("rel_tol")

    def value(v):
        return _value(v, bracket if str(v.get("id", "")).startswith("threshold") else None)

    return [[v.get("id", ""), label(v["backend"]), _cell(value(v), v["passed"]), _tolerance(v),
             _cell("pass" if v["passed"] else "FAIL", v["passed"]),
             _cell(v["metric"], None, f"{v.get('detail', '')}. Tolerance: {v['reason']}")]
            for v in doc["verdicts"]]


def jump_rows(doc: dict) -> list[list]:
    return [[case.replace("_", " "), label(name), _num(j["amplitude"]),
             _num(j["omega_reference"]), _num(j["omega_engine"]), _num(j.get("shift")),
             str(j["n_runs"])]
            for case, spec in doc["spectra"].items()
            for name, j in spec.get("jump_shifts", {}).items()]


def history_rows(doc: dict) -> list[list]:
    tol = doc["config"]["tolerances"]["theta_rms_first"]
    rows = []
    for c in doc["comparisons"]:
        rms = c.get("theta_rms_first")
        rows.append([c["point"], "yes" if c["pendulum"] else "no", label(c["backend"]),
                     _status(c["status_reference"], c["mode_reference"]),
                     _cell(_status(c["status_test"], c["mode_test"]), c["verdict_agrees"]),
                     _cell("n/a" if rms is None else f"{fmt_sci(rms)} α",
                           None if rms is None else rms <= tol),
                     "n/a" if c.get("theta_max_all") is None else f"{fmt_sci(c['theta_max_all'])} α",
                     _uplift(c),
                     fmt_seconds(c["test"].get("wall_time"))])
    return rows


def _sample_interval(prov: dict) -> float | None:
    """An engine run's sample interval [s]: ``sample_every`` steps of ``dt``."""
    s = prov.get("settings") or {}
    dt, every = s.get("dt", prov.get("dt")), s.get("sample_every")
    return dt * every if (dt and every) else None


def _uplift(c: dict) -> str:
    """The uplift time error (both runs timed where ``|theta|`` first reaches
    1e-4 rad, linear between samples) with the coarser run's sample interval,
    the resolution of that reading."""
    err = c.get("uplift_time_error")
    if err is None:
        return "n/a"
    res = _sample_interval(c.get("test") or {})
    return f"{1e3 * err:+.2g} ms" + ("" if res is None else f" (samples every {1e3 * res:.2g} ms)")


def settings_rows(doc: dict) -> tuple[list[str], list[list]]:
    """The engines' settings side by side, one row per setting (nested
    dictionaries such as the run monitor flattened as ``monitor: uplift_angle``),
    values as numbers a person reads: ``1e-4``, yes/no, "engine default" for None."""
    engines = list(doc.get("config", {}).get("engines", []))
    flat = {e: _flatten(doc.get("settings", {}).get(e, {})) for e in engines}
    keys = list(dict.fromkeys(k for e in engines for k in flat[e]))
    rows = [[k.replace("_", " ")] + [_setting(flat[e].get(k, "—")) for e in engines]
            for k in keys]
    # Threshold searches start from each engine's calibrated threshold settings:
    # the values that differ from the table above, one row each.
    thr = {e: _flatten(doc.get("threshold_settings", {}).get(e, {})) for e in engines}
    for k in dict.fromkeys(k for e in engines for k in thr[e]):
        if any(k in thr[e] and thr[e][k] != flat[e].get(k) for e in engines):
            rows.append([f"{k.replace('_', ' ')} (threshold searches)"]
                        + [_setting(thr[e].get(k, "—")) for e in engines])
    return ["setting"] + [label(e) for e in engines], rows


def key_value_rows(d: dict) -> list[list]:
    """A flat (or nested) dictionary as ``[name, value]`` rows, values readable."""
    return [[k.replace("_", " "), _setting(v)] for k, v in _flatten(d).items()]


def _flatten(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flatten(v, f"{prefix}{k}: "))
        else:
            out[f"{prefix}{k}"] = v
    return out


def _setting(v) -> str:
    if v is None:
        return "engine default"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return fmt_sci(v, 3)
    if isinstance(v, (list, tuple)):
        return ", ".join(_setting(x) for x in v)
    return str(v)


def restitution_rows(doc: dict) -> list[list]:
    tols = doc["config"]["tolerances"]
    rows = []
    for r in doc["restitution"]:
        tol = tols["restitution_pendulum" if r["pendulum"] else "restitution"]
        err = r.get("max_rel_error")
        rows.append([label(r["backend"]), _num(r["lam"]), _num(r["mu"]), _num(r["gamma"]),
                     r["equation"], str(len(r["impacts"])),
                     _cell("no impact" if err is None or not r["impacts"] else fmt_pct(err, 3),
                           err is not None and bool(r["impacts"]) and err <= tol)])
    return rows


def timing_rows(doc: dict) -> list[list]:
    t = doc["timings"]
    counts = ("from_store", "n_jobs", "load_average")
    rows = [[_TIMINGS.get(k, k.replace("_", " ")) + " (wall)", fmt_seconds(v)]
            for k, v in t.items() if not isinstance(v, (dict, list)) and k not in counts]
    if "n_jobs" in t:
        rows.append(["jobs served by the run store", f"{t.get('from_store', 0)} of {t['n_jobs']}"])
    if t.get("load_average"):
        rows.append(["load average (1 min) at start, end",
                     ", ".join(f"{x:.2g}" for x in t["load_average"])])
    spent = t.get("spent_by_job", {})
    for key, v in t.get("cpu_by_job", {}).items():
        kind, _, name = key.partition(":")
        now = f"; {fmt_seconds(spent[key])} spent now" if key in spent else ""
        rows.append([f"{_JOBS.get(kind, kind)}, {label(name)} (CPU when computed)",
                     fmt_seconds(v) + now])
    return rows


def provenance_rows(doc: dict) -> list[list]:
    p = doc.get("provenance") or {}
    rows = [[k, str(p[k])] for k in ("date", "commit", "command") if k in p]
    if p.get("settings_file"):  # which file set the engine settings table's values
        f = p["settings_file"]
        rows.append(["settings file", f"{f['file']} (sha256 {f['sha256']})"])
    rows += [[f"version: {k}", str(v)] for k, v in p.get("versions", {}).items()]
    rows += [[f"machine: {k}", str(v)] for k, v in p.get("machine", {}).items()]
    rows.append(["scene", doc["config"]["scene"]])
    return rows or [["provenance", "not recorded"]]


HEADERS = {"verdicts": ["id", "engine", "value", "tolerance", "result",
                        "metric (detail and the tolerance's reason folded)"],
      "thresholds": ["case", "engine", "Ω [rad/s]", "A model", "A engine",
                     "error (bracket)", "mode (model / engine)", "model valid", "runs", "cause",
                     "CPU"],
      "jumps": ["case", "engine", "probe A [m/s²]", "Ω jump model", "Ω jump engine",
                "shift [rad/s]", "runs"],
      "histories": ["point", "pendulum", "engine", "verdict (model)", "verdict (engine)",
                    "θ RMS error before 1st impact", "θ max error (whole run)",
                    "uplift time error (resolution)", "wall"],
      "restitution": ["engine", "λ", "μ", "γ", "equation", "impacts", "worst error"],
      "timings": ["what", "time"],
      "errors": ["job", "engine", "pendulum", "label", "error"],
      "provenance": ["what", "value"]}


def error_rows(doc: dict) -> list[list]:
    return [[e["job"], label(e["backend"]), "yes" if e["pendulum"] else "no",
             " ".join(e["label"]), e["error"]] for e in doc["errors"]]
