"""A declared study's scenes of another kind: the engines against each other.

A campaign file may list scenes the model does not cover (:mod:`analytic.kinds`:
drums, unequal columns, a block on a block).  There is no analytic reference
there, so each (scene, case, pulse, Omega) point is answered as ``trilith
spectrum --consensus`` answers it (:mod:`compare.measure.kind_scan`):

1. **The guess** (:class:`ScanJob`): the study's first engine's verdicts at
   amplitudes growing from the structure's static uplift bound, the geometric
   mean of the last survival and the first failure
   (:func:`compare.measure.kind_scan.scan_guess`); it replaces the model's number
   as the searches' start.
2. **Each engine's own first failure**, converged in the step
   (:class:`compare.campaign.atlas_consensus.ConsensusJob`, the atlas's job).
3. **The consensus** (:func:`compare.measure.consensus.consensus`): the median,
   each engine's deviation, outliers with a measured cause.

The study's ``steps`` do not apply: each engine starts at its threshold step
and halves it until two steps agree (:func:`compare.measure.consensus.own_threshold`).
Every job goes through the run store, so a killed campaign resumes.  Each row
says what it is: engine against engine, never agreement with the model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from trilith_xval.compare.run import runs

__all__ = ["ScanJob", "kind_points", "run_scan", "kind_rows", "ENGINE_AGAINST_ENGINE"]

ENGINE_AGAINST_ENGINE = "engine against engine (no model for this kind)"


@dataclass(frozen=True)
class ScanJob:
    """The scan that starts the searches at one point of a scene of another kind:
    scene name, case, pulse, Omega [rad/s] and the engine that scans."""

    scene: str
    case: str
    pulse: str
    omega: float
    engine: str

    def spec(self):
        """The engine's threshold run template on the point's scene."""
        from trilith_xval.compare.campaign.study import _scene
        from trilith_xval.compare.run.spec import RunSpec
        return RunSpec.resolve(self.engine, _scene(self.scene, self.case), calibrated=True)

    def description(self) -> dict:
        """Everything the scan's result depends on (its store key)."""
        from trilith_xval.compare.measure.kind_scan import SCAN_FACTOR, SCAN_STEPS
        from trilith_xval.compare.run.keys import backend_version, scene_dict, settings_dict
        spec = self.spec()
        return {"engine": self.engine, "version": backend_version(self.engine),
                "scene": scene_dict(spec.scene), "pulse": self.pulse, "omega": self.omega,
                "settings": settings_dict(spec.settings), "factor": SCAN_FACTOR,
                "steps": SCAN_STEPS}


def run_scan(job: ScanJob) -> dict:
    """``{'a_guess': [m/s^2] or None, 'runs': n}`` through the store; an exception
    becomes ``error``."""
    from trilith_xval.compare.measure.kind_scan import scan_guess

    def compute():
        guess, n = scan_guess(job.spec(), job.omega, job.pulse)
        return {"a_guess": guess, "runs": n}
    try:
        return runs.memo("consensus-scan", job.description(), compute,
                         label=f"scan {job.engine}", code=runs.ALL_CODE)
    except Exception as exc:  # noqa: BLE001 - one bad point must not sink the campaign
        return {"a_guess": None, "runs": 0, "error": f"{type(exc).__name__}: {exc}"}


def kind_points(study) -> list[tuple[str, str, str, float]]:
    """``(scene name, case, pulse, omega)`` of every point of the study's scenes of
    another kind; a case that is the same structure as an earlier one (no
    pendulum to remove) is listed once, under ``no_pendulum``."""
    from trilith_xval.compare.campaign.study import _scene
    out = []
    for name in study.kind_scenes:
        cases, has = [], _scene(name, "pendulum").has_pendulum
        for case in study.cases:
            label = case if has else "no_pendulum"
            if label not in cases:
                cases.append(label)
        out += [(name, c, p, w) for c in cases for p in study.pulses for w in study.omegas]
    return out


def kind_rows(study, workers: int = 1, on_done=None) -> list[dict]:
    """One row per point of :func:`kind_points`: the scan's guess, each engine's own
    first failure (``own``) and the consensus, marked :data:`ENGINE_AGAINST_ENGINE`.
    ``on_done(i, result)`` is called as jobs finish (a progress bar)."""
    from trilith_xval.compare.campaign.atlas_consensus import ConsensusJob, run_job
    from trilith_xval.compare.measure.consensus import consensus, outlier_cause

    points = kind_points(study)
    if not points:
        return []
    engines = study.engines
    scans = list(runs.run_many(run_scan, [ScanJob(*pt, engines[0]) for pt in points],
                               workers=workers, on_done=on_done))
    jobs, owners = [], []
    for i, (pt, scan) in enumerate(zip(points, scans)):
        if scan.get("a_guess") is not None:
            for e in engines:
                jobs.append(ConsensusJob(*pt, float(scan["a_guess"]), e, study.rel_tol))
                owners.append(i)
    results = list(runs.run_many(run_job, jobs, workers=workers, on_done=on_done))
    owns: dict[int, dict] = {}
    for i, job, res in zip(owners, jobs, results):
        owns.setdefault(i, {})[job.engine] = (job, res)
    rows = []
    for i, ((name, case, pulse, omega), scan) in enumerate(zip(points, scans)):
        row = {"scene": name, "case": case, "pulse": pulse, "omega": omega,
               "what": ENGINE_AGAINST_ENGINE, "a_guess": scan.get("a_guess"),
               "scan_runs": scan.get("runs", 0)}
        if i not in owns:
            why = scan.get("error") or "no failure up to the scan's end"
            rows.append({**row, "status": "none", "median": None, "engines": {},
                         "outliers": [], "own": {}, "no_answer": [
                             {"engine": e, "cause": "no failure", "detail": why}
                             for e in engines]})
            continue
        own = {e: res for e, (_, res) in owns[i].items()}
        first = consensus(own)
        causes = {o["engine"]: outlier_cause(owns[i][o["engine"]][0].spec(), omega,
                                             own[o["engine"]], first["failure"], pulse)
                  for o in first["outliers"]}
        rows.append({**row, **consensus(own, causes), "own": own,
                     "cpu_s": math.fsum(r["cpu_s"] for r in own.values()
                                        if math.isfinite(r.get("cpu_s", math.nan)))})
    return rows
