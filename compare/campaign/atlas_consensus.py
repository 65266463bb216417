"""The atlas where the model cannot speak: the engines' consensus at its invalid points.

At an atlas point where the model is invalid (a contact would have to pull) no
engine is compared with the model.  :func:`add_consensus` measures there each
engine's own first-failure amplitude, converged in the step, and the engines'
consensus (:mod:`compare.measure.consensus`), and stores it with the point
(``point["consensus"]``, each engine's own result in ``point["own"]``), marked as
engine against engine.

A point where the model's bob meets a column is left without an answer: the
engines' bob collides with nothing (as the model's, :mod:`engines.base`), so
there the engines run through the same impossible motion and their agreement
would mean nothing.

Every engine job goes through the run store (``runs.memo('consensus', ...)``),
so a killed run resumes where it stopped.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

from trilith_xval.compare.run import runs

__all__ = ["ConsensusJob", "answerable", "consensus_jobs", "add_consensus"]

BOB_MEETS = "the bob meets"  # analytic.clearance's reason when the bob reaches a column


def answerable(point: dict) -> tuple[bool, str]:
    """Whether the engines can answer at an invalid ``point`` (module docstring),
    and why not."""
    if point.get("valid") is not False or point.get("a_reference") is None:
        return False, "the model is valid there (or overturns nowhere in range)"
    if BOB_MEETS in (point.get("model_reason") or ""):
        return False, ("the bob meets a column: the engines' bob collides with nothing, as "
                       "the model's, so they run through the same impossible motion")
    return True, ""


@dataclass(frozen=True)
class ConsensusJob:
    """One engine's own threshold at one atlas point: scene name, case, pulse,
    Omega [rad/s], the model's (invalid) number as the search's start [m/s^2],
    the engine and the atlas's bracket resolution."""

    scene: str
    case: str
    pulse: str
    omega: float
    a_guess: float
    engine: str
    rel_tol: float

    def spec(self):
        """The engine's run (its calibrated threshold step where the scene lies in
        its domain, else its reference step) at the point's largest pulse."""
        from trilith_xval.compare.campaign.study import _scene
        from trilith_xval.compare.measure.consensus import FAILURE_SEARCH
        from trilith_xval.compare.measure.engine_spectrum import point_spec
        from trilith_xval.compare.run.spec import RunSpec
        scene = _scene(self.scene, self.case)
        search = FAILURE_SEARCH.with_rel_tol(self.rel_tol)
        return point_spec(RunSpec.resolve(self.engine, scene, calibrated=True), scene,
                          self.omega, self.a_guess, self.pulse, search)

    def description(self) -> dict:
        """Everything the result depends on (its store key)."""
        from trilith_xval.compare.run.keys import backend_version, scene_dict, settings_dict
        spec = self.spec()
        return {"engine": self.engine, "version": backend_version(self.engine),
                "scene": scene_dict(spec.scene), "pulse": self.pulse, "omega": self.omega,
                "a_guess": self.a_guess, "settings": settings_dict(spec.settings),
                "rel_tol": self.rel_tol}


def run_job(job: ConsensusJob) -> dict:
    """One engine's own threshold (:func:`compare.measure.consensus.own_threshold`),
    through the store; an exception becomes the row's ``error``."""
    from trilith_xval.compare.measure.consensus import own_threshold
    try:
        return runs.memo("consensus", job.description(),
                         lambda: own_threshold(job.spec(), job.omega, job.a_guess, job.pulse,
                                               rel_tol=job.rel_tol),
                         label=f"consensus {job.engine}", code=runs.ALL_CODE)
    except Exception as exc:  # noqa: BLE001 - one bad run must not sink the pass
        return {"engine": job.engine, "omega": job.omega, "converged": False,
                "cause": "error", "detail": f"{type(exc).__name__}: {exc}", "steps": [],
                "cpu_s": math.nan, "a_fails": None, "failure": None, "dt": None}


def consensus_jobs(doc: dict, engines) -> tuple[list[int], list[ConsensusJob]]:
    """The answerable invalid points of the atlas ``doc`` (their indices) and one
    job per point and engine, point by point."""
    rel_tol = float(doc["config"].get("rel_tol", 4e-3))
    idx, jobs = [], []
    for i, pt in enumerate(doc["points"]):
        if answerable(pt)[0]:
            idx.append(i)
            jobs += [ConsensusJob(pt["scene"], pt["case"], pt["pulse"], float(pt["omega"]),
                                  float(pt["a_reference"]), e, rel_tol) for e in engines]
    return idx, jobs


def add_consensus(doc: dict, engines, workers: int = 1) -> dict:
    """``doc`` with the engines' consensus at every invalid point (module
    docstring); the document's ``consensus`` entry says which engines, how many
    points gained an answer, and the cost (CPU seconds, load average)."""
    from trilith_xval.compare.measure.consensus import consensus, outlier_cause
    from trilith_xval.compare.run.progress import bar
    engines = tuple(engines)
    t0, c0, load0 = time.perf_counter(), time.process_time(), os.getloadavg()[0]
    idx, jobs = consensus_jobs(doc, engines)
    progress = bar(len(jobs), "atlas: consensus", "jobs")
    try:
        results = list(runs.run_many(run_job, jobs, workers=max(1, workers),
                                     on_done=lambda i, r: progress.update(1)))
    finally:
        progress.close()
    points = [dict(pt) for pt in doc["points"]]
    for pt in points:
        ok, why = answerable(pt)
        if pt.get("valid") is False and not ok:
            pt["consensus"] = {"status": "not run", "why": why}
    # The jobs are point by point, engine by engine (consensus_jobs).
    pairs = iter(zip(jobs, results))
    by_point = {i: {e: next(pairs) for e in engines} for i in idx}
    for i, owns in by_point.items():
        own = {e: r for e, (_, r) in owns.items()}
        first = consensus(own)
        causes = {}
        for o in first["outliers"]:
            job = owns[o["engine"]][0]
            causes[o["engine"]] = outlier_cause(job.spec(), job.omega, own[o["engine"]],
                                                first["failure"], job.pulse)
        points[i]["consensus"] = consensus(own, causes)
        points[i]["own"] = own
    gained = sum(points[i]["consensus"]["status"] in ("consensus", "one engine") for i in idx)
    cpu = math.fsum(r["cpu_s"] for r in results if math.isfinite(r.get("cpu_s", math.nan)))
    summary = {"engines": list(engines), "invalid_points": sum(p.get("valid") is False
                                                               for p in points),
               "answerable": len(idx), "gained": gained,
               "status": _count(points[i]["consensus"]["status"] for i in idx),
               "cpu_s": cpu, "cpu_s_per_engine_point": cpu / len(jobs) if jobs else None,
               "wall_s": time.perf_counter() - t0, "parent_cpu_s": time.process_time() - c0,
               "load_average": [load0, os.getloadavg()[0]], "workers": workers}
    return {**doc, "points": points, "consensus": summary}


def _count(values) -> dict:
    out: dict = {}
    for v in values:
        out[v] = out.get(v, 0) + 1
    return out
