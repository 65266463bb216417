"""``trilith trust``: how far each engine can be trusted on the user's own trilith.

The validation report answers for the paper's Fig. 5 trilith; this answers, in
minutes, for any scene:

1. **where the model can speak**: the model's overturning spectrum on a grid of
   :data:`GRID_OVER_P` x ``p`` (``p = sqrt(3 g / 4 R)``, the scene's rocking
   frequency parameter) and its validity on each threshold run
   (:func:`analytic.threshold_validity.spectrum_validity`);
2. **thresholds**: :data:`N_THRESHOLDS` frequencies spread over the valid band
   of each curve (both when the scene has a pendulum), each the one engine
   threshold measurement (:func:`compare.measure.engine_spectrum.measure_point`)
   at the engine's recommended settings (its calibrated step inside the
   calibration's domain, else its reference step) under the step rule;
3. **restitution**: free rocking from ``alpha/2`` against Eq. 20 (no pendulum)
   and Eq. 19 (with it) (:func:`compare.measure.restitution.measure_restitution`);
4. **time histories**: theta(t) before the first impact at two amplitudes
   around the model's threshold (0.9x and 1.1x) at the middle frequency
   (:func:`compare.measure.trajectories.compare_trajectories`);
5. **a ground motion** (optional): the first overturning intensity of each
   record, model against engine (:mod:`compare.measure.record_threshold`);
6. **where the model is invalid** (two engines or more): at :data:`N_CONSENSUS`
   frequencies per curve spread over the invalid band (not where the bob meets
   a column: the engines' bob collides with nothing), the engines against each
   other (:func:`compare.measure.consensus.consensus_at`), never the model.

Each engine gets a verdict per use (trusted, trusted at a finer step, or not,
with the measured cause) and its cost in CPU seconds per threshold point and per
simulated second.  Tolerances are the validation report's
(:class:`compare.campaign.config.Tolerances`).
"""
from __future__ import annotations

import dataclasses
import math
import os
import sys
import time

import numpy as np

__all__ = ["trust_scene", "StageProgress", "GRID_OVER_P", "N_THRESHOLDS", "HISTORY_FACTORS"]

# Omega / p of the model's grid: Fig. 5's 3-30 rad/s is 1.4-14 p.
GRID_OVER_P = tuple(float(x) for x in np.linspace(1.5, 13.5, 25))
N_THRESHOLDS = 6  # per curve: the "about 6 across the valid band"
N_CONSENSUS = 3  # per curve, where the model is invalid: the engines against each other
HISTORY_FACTORS = (0.9, 1.1)  # x the model's threshold: one survives, one overturns


class StageProgress:
    """One stderr line per stage: ``trust: stage k/N name ... done/total, elapsed``."""

    def __init__(self, n_stages: int, quiet: bool):
        self.n, self.k, self.quiet, self.t0 = n_stages, 0, quiet, time.perf_counter()

    def stage(self, name: str, done: int = 0, total: int = 0) -> None:
        if self.quiet:
            return
        count = f" {done}/{total}" if total else ""
        print(f"trust: {self.k}/{self.n} {name}{count}, {time.perf_counter() - self.t0:.0f} s",
              file=sys.stderr, flush=True)

    def next(self, name: str, total: int = 0) -> None:
        self.k += 1
        self.stage(name, 0, total)


def _band(scene, workers: int) -> dict:
    """The model's spectrum and validity; per curve the valid frequencies."""
    from trilith_xval.analytic.spectrum import overturning_spectrum
    from trilith_xval.analytic.threshold_validity import spectrum_validity
    p = math.sqrt(3.0 * scene.g / (4.0 * scene.R))
    omegas = [round(p * f, 4) for f in GRID_OVER_P]
    spec = overturning_spectrum(scene, omegas, workers=workers)
    validity = spectrum_validity(spec, workers=workers)
    curves = {"no_pendulum": (spec.a_no_pendulum, spec.mode_no_pendulum)}
    if scene.has_pendulum:
        curves["pendulum"] = (spec.a_pendulum, spec.mode_pendulum)
    out = {"p": p, "omegas": omegas, "curves": {}}
    for case, (amps, modes) in curves.items():
        rows = []
        for w, a, m, v in zip(omegas, amps, modes, validity[case]):
            rows.append({"omega": w, "a_model": float(a) if math.isfinite(a) else None,
                         "mode": m, "valid": v.get("model_valid"),
                         "reason": v.get("model_reason", "")})
        out["curves"][case] = rows
    return out


def _spread(rows: list[dict], n: int) -> list[dict]:
    """``n`` rows spread evenly over the valid, overturning ones."""
    ok = [r for r in rows if r["a_model"] is not None and r["valid"] is not False]
    if len(ok) <= n:
        return ok
    return [ok[int(round(i))] for i in np.linspace(0, len(ok) - 1, n)]


def _thresholds(run, band, progress) -> list[dict]:
    """The threshold design of ``band`` measured from ``run`` (the engine's
    threshold-search :class:`~compare.run.spec.RunSpec` on the scene)."""
    from trilith_xval.compare.measure.engine_spectrum import measure_point, point_spec
    scene = run.scene
    jobs = [(case, r) for case, rows in band["curves"].items()
            for r in _spread(rows, N_THRESHOLDS)]
    out = []
    for i, (case, r) in enumerate(jobs):
        sc = scene if case == "pendulum" else scene.without_pendulum()
        ep = measure_point(point_spec(run, sc, r["omega"], r["a_model"]), r["omega"],
                           r["a_model"], r["mode"], case=case)
        out.append({"case": case, "omega": r["omega"], "a_model": r["a_model"],
                    "a_engine": ep.a_engine if ep.bracketed else None,
                    "rel_error": ep.rel_error if ep.bracketed else None,
                    "cause": ep.cause, "cause_detail": ep.cause_detail,
                    "agreeing_dt": ep.agreeing_dt, "dt": ep.point.provenance.dt,
                    "cpu_s": ep.cpu_s, "search_cpu_s": ep.point.cpu_s,
                    "cpu_per_sim_s": ep.point.cpu_per_sim_s,
                    "from_store": ep.point.from_store})
        progress.stage(f"{run.backend} thresholds", i + 1, len(jobs))
    return out


def _restitution(run, tol) -> list[dict]:
    """Free rocking of ``run`` (the engine at its defaults, which are calibrated for
    restitution) on its scene without and with the pendulum."""
    from trilith_xval.compare.measure.restitution import free_rocking
    scene = run.scene
    cases = [("Eq. 20", scene.without_pendulum(), tol.restitution)]
    if scene.has_pendulum:
        cases.append(("Eq. 19", scene, tol.restitution_pendulum))
    out = []
    for eq, sc, t in cases:
        r = free_rocking(run.at(scene=sc))
        err = r.max_rel_error if r.complete else None
        out.append({"equation": eq, "max_rel_error": err, "tolerance": t,
                    "passed": err is not None and abs(err) <= t, "impacts": len(r.impacts),
                    "cpu_s": r.diagnostics.get("cpu_time")})
    return out


def _histories(run, band, tol) -> list[dict]:
    """Time histories of ``run`` (the engine at its defaults) against the model's,
    at multiples of the band's thresholds."""
    from trilith_xval import engines
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.measure.trajectories import compare_trajectories
    from trilith_xval.compare.run import runs
    scene, out = run.scene, []
    for case, rows in band["curves"].items():
        picked = _spread(rows, 3)
        if not picked:
            continue
        r = picked[len(picked) // 2]
        sc = scene if case == "pendulum" else scene.without_pendulum()
        for f in HISTORY_FACTORS:
            pulse = Pulse(f * r["a_model"], r["omega"])
            ref = runs.simulate("analytic", sc, pulse, engines.configure("analytic"))
            test = runs.simulate(run.backend, sc, pulse, run.at(sc, pulse).settings)
            c = compare_trajectories(ref, test)
            rms = c.theta_rms_first if math.isfinite(c.theta_rms_first) else None
            out.append({"case": case, "omega": r["omega"], "amplitude": pulse.amplitude,
                        "factor": f, "theta_rms_first": rms, "verdict_agrees": c.verdict_agrees,
                        "model": ref.verdict.status, "engine": test.verdict.status,
                        "passed": bool(c.verdict_agrees and rms is not None
                                       and rms <= tol.theta_rms_first)})
    return out


def _records(run, records) -> list[dict]:
    """Each record's first overturning intensity: the model's (window-aware IDA,
    the accurate model) against the robust one of ``run`` (the engine's
    threshold-search :class:`~compare.run.spec.RunSpec` on the scene) under the
    step rule."""
    from trilith_xval.analytic.ida import IDASettings, first_overturn_intensity, model_verdict
    from trilith_xval.compare.measure.record_threshold import STEP_TOL, engine_intensity
    st = IDASettings()
    out = []
    for rec in records:
        model = first_overturn_intensity(rec, model_verdict(run.scene, st.tail), st)
        im_model = model.im_overturn if math.isfinite(model.im_overturn) else None
        res = engine_intensity(run, rec, st, im_model)
        im = res["im_overturn"]
        err = (im - im_model) / im_model if (im is not None and im_model) else None
        out.append({"record": res["label"], "im": st.im, "im_model": im_model, "im_engine": im,
                    "rel_error": err, "censored": res["censored"], "dt": res["dt"],
                    "passed": err is not None and abs(err) <= STEP_TOL,
                    "cpu_s": res["cpu_s"]})
    return out


def _verdict(points: list[dict]) -> dict:
    """Thresholds: trusted (every point agrees), trusted at a finer step (every
    failing point is 'discretisation'), or not (the first other cause); points
    where the model is no fair reference (the report's excused causes: invalid,
    a mode jump, an overturning window) are listed, never held against it."""
    from trilith_xval.compare.report.trust import EXCUSED
    judged = [p for p in points if p["cause"] not in EXCUSED]
    excused = [p for p in points if p["cause"] in EXCUSED]
    note = (f"; {len(excused)} point(s) where the model is no fair reference: "
            + ", ".join(f"Omega {p['omega']:.3g} ({p['cause']})" for p in excused)
            if excused else "")
    failing = [p for p in judged if p["cause"] != "agrees"]
    if not judged:
        return {"trusted": None, "why": "the model is no fair reference at any point" + note}
    if not failing:
        return {"trusted": True, "why": f"{len(judged)} of {len(judged)} points agree" + note}
    if all(p["cause"] == "discretisation" and p["agreeing_dt"] for p in failing):
        finest = min(p["agreeing_dt"] for p in failing)
        return {"trusted": True, "finer_dt": finest,
                "why": f"{len(judged) - len(failing)} of {len(judged)} agree at the "
                       f"recommended step; the rest agree at dt <= {finest:g} s" + note}
    worst = failing[0]
    err = "no bracket" if worst["rel_error"] is None else f"{100 * worst['rel_error']:+.2f} %"
    return {"trusted": False, "why": f"{len(failing)} of {len(judged)} points fail; first at "
                                     f"Omega {worst['omega']:g} rad/s ({worst['case']}): "
                                     f"{err}, cause {worst['cause']}" + note}


def trust_scene(scene, engines, *, records=(), workers: int = 1, quiet: bool = False) -> dict:
    """The trust document of ``scene`` for ``engines`` (module docstring)."""
    from trilith_xval.engines import configure, get_backend
    from trilith_xval.engines.calibration import threshold_choice

    from trilith_xval.compare.campaign.config import Tolerances
    from trilith_xval.compare.run.keys import project_version
    tol = Tolerances()
    t0, c0, load0 = time.perf_counter(), _cpu(), os.getloadavg()[0]
    progress = StageProgress(1 + 3 * len(engines) + (len(engines) if records else 0)
                         + (len(engines) >= 2), quiet)
    progress.next("model: spectrum and validity")
    band = _band(scene, workers)
    doc = {"schema_version": 1, "what": "trust of each engine on one scene",
           "scene": scene.to_dict(), "band": band, "tolerances": dataclasses.asdict(tol),
           "engines": {}, "project": project_version()}
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.run.spec import RunSpec
    runs = {e: RunSpec.resolve(e, scene, Still(), calibrated=True) for e in engines}
    defaults = {e: RunSpec.resolve(e, scene) for e in engines}  # restitution, histories
    for e in engines:
        choice = threshold_choice(e, scene)
        settings = runs[e].settings
        entry = {"label": get_backend(e).label, "version": get_backend(e).version(),
                 "threshold_dt": settings.dt, "reference_dt": configure(e).dt,
                 "calibrated_inside": choice.inside, "note": choice.note}
        progress.next(f"{e} thresholds", N_THRESHOLDS * len(band["curves"]))
        entry["thresholds"] = _thresholds(runs[e], band, progress)
        entry["threshold_verdict"] = _verdict(entry["thresholds"])
        progress.next(f"{e} restitution")
        entry["restitution"] = _restitution(defaults[e], tol)
        progress.next(f"{e} time histories")
        entry["histories"] = _histories(defaults[e], band, tol)
        if records:
            progress.next(f"{e} records", len(records))
            entry["records"] = _records(runs[e], records)
        entry["cost"] = _cost(entry)
        doc["engines"][e] = entry
    if len(engines) >= 2:
        doc["consensus"] = _consensus(runs, scene, band, progress)
    doc["cost"] = {"wall_s": time.perf_counter() - t0, "cpu_s": _cpu() - c0,
                   "load_average": [load0, os.getloadavg()[0]]}
    return doc


def _invalid(rows: list[dict], n: int) -> list[dict]:
    """``n`` rows spread over the invalid ones the engines can answer."""
    from trilith_xval.compare.campaign.atlas_consensus import BOB_MEETS
    bad = [r for r in rows if r["valid"] is False and r["a_model"] is not None
           and BOB_MEETS not in (r["reason"] or "")]
    if len(bad) <= n:
        return bad
    return [bad[int(round(i))] for i in np.linspace(0, len(bad) - 1, n)]


def _consensus(runs: dict, scene, band: dict, progress) -> list[dict]:
    from trilith_xval.compare.measure.consensus import consensus_at
    jobs = [(case, r) for case, rows in band["curves"].items()
            for r in _invalid(rows, N_CONSENSUS)]
    progress.next("consensus where the model is invalid", len(jobs))
    out = []
    for i, (case, r) in enumerate(jobs):
        sc = scene if case == "pendulum" else scene.without_pendulum()
        out.append({"case": case, **consensus_at(runs, sc, r["omega"], r["a_model"])})
        progress.stage("consensus where the model is invalid", i + 1, len(jobs))
    return out


def _cost(entry: dict) -> dict:
    pts = [p for p in entry["thresholds"] if not p["from_store"]]
    per = [p["search_cpu_s"] for p in pts if p["search_cpu_s"] is not None
           and math.isfinite(p["search_cpu_s"])]
    rtf = [p["cpu_per_sim_s"] for p in pts if p["cpu_per_sim_s"] is not None
           and math.isfinite(p["cpu_per_sim_s"])]
    # Finer steps of the step rule and the cause search's reruns of failing points.
    step = [p["cpu_s"] - p["search_cpu_s"] for p in pts
            if math.isfinite(p["cpu_s"]) and math.isfinite(p["search_cpu_s"])]
    return {"threshold_point_cpu_s": float(np.median(per)) if per else None,
            "cpu_per_sim_s": float(np.median(rtf)) if rtf else None,
            "rerun_cpu_s": math.fsum(step) if step else 0.0,
            "points_computed": len(pts)}


def _cpu() -> float:
    from trilith_xval.analytic._workers import cpu_seconds
    return cpu_seconds()
