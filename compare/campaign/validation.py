"""The validation campaign: every engine against the analytic model, one config.

:func:`run_campaign` runs, for a :class:`CampaignConfig`,

* time histories at the paper's points A-D (Fig. 5-7) in every backend, with and
  without the pendulum, compared with :func:`compare.measure.trajectories.compare_trajectories`;
* free-rocking restitution over a lam x mu grid against Eq. 20, and with the
  pendulum against Eq. 19 at the measured psi;
* engine overturning thresholds at frequencies away from the model's mode jumps
  (bisection bracketed by the analytic spectrum) and the jump frequency shift;
* a verdict table (metric, backend, value, tolerance, passed, reason).

Independent runs go to :func:`compare.run.runs.run_many` (local processes or a Dask
cluster; results in submission order, so the numbers do not depend on
scheduling), every engine run through the run store (:mod:`compare.run.runs`).
Progress bar on a terminal only.
"""
from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, field

from trilith_xval.scenes import load_scene

from trilith_xval.compare.measure import trajectories as metrics

from trilith_xval.compare.campaign.config import CampaignConfig, campaign_run
from trilith_xval.compare.campaign.config import Tolerances  # noqa: F401  (in __all__)
from trilith_xval.compare.campaign.validation_jobs import (JumpJob, RestitutionJob, ReverifyJob,
                                                           ThresholdPointJob,
                                                           free_rocking_restitution, history_job,
                                                           long_run_job)
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.compare.run.keys import backend_version
from trilith_xval.compare.measure.reference_spectra import choose_frequencies, reference_spectrum

__all__ = ["Tolerances", "CampaignConfig", "run_campaign", "campaign_run",
           "free_rocking_restitution"]


# ----------------------------------------------------------------------- jobs
def _domain_entry(engine: str, scene) -> dict:
    """Whether ``scene`` lies in the domain of ``engine``'s calibrated threshold
    step, the domain and the held-out result it was validated with."""
    from trilith_xval.engines.calibration import calibrated, threshold_choice
    cal, choice = calibrated(engine), threshold_choice(engine, scene)
    return {"calibrated": bool(cal.options), "inside": choice.inside, "note": choice.note,
            "domain": cal.domain.as_dict() if cal.options else None,
            "calibration": dict(cal.record), "source": cal.command}


def _run_one(job):
    """Run one job (:mod:`compare.campaign.validation_jobs`): ``(result, cpu_s when
    computed, cpu_s spent now, from_store)``.  An exception becomes an error record
    (one bad engine run must not sink a 10-minute campaign; the verdict table then
    reports it unmeasured)."""
    c0 = time.process_time()

    def compute():  # stored with its CPU cost, so a store hit can say what it cost
        t0 = time.process_time()
        value = job()
        return {"value": value, "cpu_s": _own_cost(value, time.process_time() - t0)}
    try:  # through the store: a finished job is not redone (compare/ code in its key)
        hits = runs.STATS["hits"]
        out = runs.memo("campaign-job", _job_description(job), compute, code=runs.ALL_CODE)
        stored = runs.STATS["hits"] > hits
        return out["value"], out["cpu_s"], time.process_time() - c0, stored
    except Exception as exc:  # noqa: BLE001 - reported in summary.json "errors"
        return _JobError(f"{type(exc).__name__}: {exc}"), 0.0, time.process_time() - c0, False


def _own_cost(value, spent: float) -> float:
    """CPU seconds a job's result cost when its engine runs were computed: the
    result's own record (a threshold point's probes, a run's ``cpu_time``, a long
    run's row) where it has one, since runs served by the store cost nothing now;
    else ``spent``."""
    own = getattr(value, "cpu_s", None)
    if own is None and hasattr(value, "diagnostics"):
        own = (value.diagnostics or {}).get("cpu_time")
    if own is None and isinstance(value, dict):
        own = value.get("cpu_s")
    return float(own) if own is not None and math.isfinite(float(own)) else spent


def _job_description(job) -> dict:
    """What a job's stored result is keyed by: its kind, :meth:`args` and the
    config (but :attr:`CampaignConfig.SELECTION`)."""
    described = None if job.config is None else job.config.job_key()
    return {"kind": job.kind, "args": _describe_args(job.args()), "config": described}


def _lookup(job):
    """A finished job from the store (nothing spent now), or None."""
    out = runs.lookup("campaign-job", _job_description(job), code=runs.ALL_CODE)
    return None if out is None else (out["value"], out["cpu_s"], 0.0, True)


@dataclass(frozen=True)
class _JobError:
    message: str


def _progress(total: int, lines: bool = False):
    """tqdm at a terminal; with ``lines`` and no terminal, a line at each tenth
    (:class:`compare.run.progress.Lines`)."""
    if lines and not sys.stderr.isatty():
        from trilith_xval.compare.run.progress import Lines
        return Lines(total, "report", "jobs")
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(total=total, desc="campaign", unit="run", disable=not sys.stderr.isatty(),
                leave=False)


# Submission order: the kinds with the longest single jobs first, so the last jobs
# are short ones and no core idles at the end (measured: the long runs and the
# re-verifications, submitted last, took the last 30 % of the default report's wall
# time on one busy core).  Results come back in job order whatever this order.
_FIRST = ("long_run", "reverify", "threshold", "jump", "restitution", "history")


def _execute(jobs: list, workers: int, lines: bool = False) -> list:
    """Run ``jobs`` (:mod:`compare.campaign.validation_jobs`); results in job order."""
    order = sorted(range(len(jobs)), key=lambda i: _FIRST.index(jobs[i].kind)
                   if jobs[i].kind in _FIRST else len(_FIRST))
    bar = _progress(len(jobs), lines)
    try:
        out = list(runs.run_many(_run_one, [jobs[i] for i in order], workers=workers,
                                 lookup=_lookup,
                                 on_done=None if bar is None else lambda i, r: bar.update()))
    finally:
        if bar is not None:
            bar.close()
    results = [None] * len(jobs)
    for k, i in enumerate(order):
        results[i] = out[k]
    return results


def _memo(kind: str, scene, config: CampaignConfig, compute):
    """A model-side result (reference spectrum, chosen frequencies) through the run
    store, keyed by the scene and the config (but its worker count: no number
    depends on it)."""
    from trilith_xval.compare.run.keys import scene_dict
    return runs.memo(kind, {"scene": scene_dict(scene), "config": config.job_key()}, compute,
                     code=runs.ALL_CODE)


def _case(pendulum: bool) -> str:
    return "pendulum" if pendulum else "no_pendulum"


def _describe_args(args) -> list:
    """Job arguments for the store key and the error record (scenes as their fields)."""
    return plain([a.to_dict() if hasattr(a, "to_dict") else a for a in args])


# ------------------------------------------------------------------ campaign
@dataclass
class CampaignResult:
    """Everything the report needs; ``to_dict()`` is ``summary.json``."""

    config: CampaignConfig
    scene: object
    settings: dict
    versions: dict
    histories: dict = field(default_factory=dict)  # (point, pendulum, backend) -> Trajectory
    comparisons: list = field(default_factory=list)  # TrajectoryComparison dicts + labels
    restitution: list = field(default_factory=list)
    spectra: dict = field(default_factory=dict)
    verdicts: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    errors: list = field(default_factory=list)  # jobs that raised, with the message
    long_runs: list = field(default_factory=list)  # compare.measure.long_runs rows
    threshold_settings: dict = field(default_factory=dict)  # engine -> its threshold searches'
    threshold_domain: dict = field(default_factory=dict)  # engine -> calibration domain, inside
    sources: dict = field(default_factory=dict)  # what was recomputed, what shown from storage

    def to_dict(self) -> dict:
        return {"config": self.config.to_dict(), "scene": self.scene.to_dict(),
                "settings": self.settings, "versions": self.versions,
                "comparisons": self.comparisons, "restitution": self.restitution,
                "spectra": self.spectra, "verdicts": self.verdicts, "timings": self.timings,
                "errors": self.errors, "long_runs": self.long_runs,
                "threshold_settings": self.threshold_settings,
                "threshold_domain": self.threshold_domain,
                **({"sources": self.sources} if self.sources else {})}


def run_campaign(config: CampaignConfig | None = None, progress: bool = False) -> CampaignResult:
    """Run the validation campaign described by ``config`` (default: full);
    ``progress``: a stderr line per tenth of the jobs when stderr is no terminal
    (tqdm's bar when it is)."""
    from trilith_xval.compare.campaign.verdicts import build_verdicts

    config = config or CampaignConfig()
    t_start = time.perf_counter()
    load_start = os.getloadavg()[0]
    scene = load_scene(config.scene)
    scenes = {True: scene, False: scene.without_pendulum()}
    if not scene.has_pendulum:
        scenes = {False: scene}
    # Every backend in the histories: the compiled path too (milliseconds), so the
    # report shows the spectrum's backend against the accurate one as well.
    backends = tuple(dict.fromkeys((config.reference, config.spectrum_backend, *config.engines)))
    result = CampaignResult(
        config=config, scene=scene,
        settings={b: plain(campaign_run(b, config, scene).settings) for b in backends},
        threshold_settings={e: plain(campaign_run(e, config, scene, thresholds=True).settings)
                            for e in config.engines},
        versions={b: backend_version(b) for b in (*backends, config.spectrum_backend)},
        threshold_domain={e: _domain_entry(e, scene) for e in config.engines})

    # Reference spectra first (in this process: the compiled kernels are then
    # inherited by the forked workers).
    t0 = time.perf_counter()
    ref_spectra = {pend: _memo("reference-spectrum", sc, config,
                               lambda sc=sc: reference_spectrum(sc, config))
                   for pend, sc in scenes.items()
                   if _case(pend) in (*config.spectrum_cases, *config.jump_cases)}
    result.timings["reference_spectra"] = time.perf_counter() - t0

    # The default report: a sample of threshold points, the rest from the stored run.
    from trilith_xval.compare.campaign import stored_parts
    stored_run, source, unused = None, None, ""
    if config.stored is not None:
        stored_run, unused = stored_parts.load_stored(config.stored, scene, config)
        source = stored_parts.source_of(config.stored, (stored_run or {}).get("provenance"))
    recomputed = {}
    jobs, labels = [], []
    for pend, spec in ref_spectra.items():
        sc = scenes[pend]
        freqs = _memo("frequencies", sc, config, lambda: choose_frequencies(spec, config, sc)) \
            if _case(pend) in config.spectrum_cases else []
        for name in config.engines:
            wanted = stored_parts.recompute_omegas(stored_run, name, _case(pend),
                                                   [f[0] for f in freqs])
            recomputed[(_case(pend), name)] = wanted
            for omega, a_ref, mode in freqs:
                if float(omega) in wanted:
                    jobs.append(ThresholdPointJob.at(name, sc, _case(pend), omega, a_ref, mode,
                                                     config))
                    labels.append(("threshold", pend, name))
        if stored_run is not None and "jump" in config.stored_jobs:
            pass  # the jump shifts come from the stored run (stored_parts.merge)
        elif _case(pend) in config.jump_cases and (spec.get("jump") or {}).get("probe_amplitude"):
            jmp = spec["jump"]
            for name in config.engines:
                jobs.append(JumpJob.at(name, sc, jmp["probe_amplitude"], jmp["omega_lo"],
                                       jmp["omega_hi"], config))
                labels.append(("jump", pend, name))
    for pend, sc in scenes.items():
        for point in config.points:
            for name in backends:
                jobs.append(history_job(name, sc, point, config))
                labels.append(("history", pend, name, point))
    base = scene.without_pendulum()
    for name in config.engines:
        for lam in config.restitution_lams:
            for mu in config.restitution_mus:
                jobs.append(RestitutionJob(campaign_run(name, config, base.replace(lam=lam, mu=mu)),
                                           config))
                labels.append(("restitution", False, name))
        if scene.has_pendulum:
            for lam in config.pendulum_lams:
                jobs.append(RestitutionJob(campaign_run(name, config, scene.replace(lam=lam)),
                                           config))
                labels.append(("restitution", True, name))

    for name, point, src in (stored_parts.reverify_jobs(config.engines, scene) if config.reverify
                             else []):
        jobs.append(ReverifyJob(name, scene, point, src))
        labels.append(("reverify", True, name))
    if stored_parts.uses_stored_long_runs(stored_run, config):
        pass  # the long runs come from the stored run (stored_parts.merge)
    elif config.long_runs:
        from trilith_xval.compare.measure.long_runs import LONG_RUNS
        for name in config.engines:
            for label, scene_name, amplitude, omega in LONG_RUNS:
                jobs.append(long_run_job(name, label, scene_name, amplitude, omega, config))
                labels.append(("long_run", False, name))
    t0 = time.perf_counter()
    if progress and not sys.stderr.isatty():
        print(f"report: reference spectra done, {len(jobs)} jobs to run", file=sys.stderr,
              flush=True)
    outputs = _execute(jobs, config.workers, progress)
    result.timings["engine_runs_wall"] = time.perf_counter() - t0
    cpu: dict[str, float] = {}
    spent: dict[str, float] = {}
    n_stored = 0
    reverified = []
    for label, job, (out, cpu_s, spent_s, stored) in zip(labels, jobs, outputs):
        kind, pend, name = label[:3]
        cpu[f"{kind}:{name}"] = cpu.get(f"{kind}:{name}", 0.0) + cpu_s
        spent[f"{kind}:{name}"] = spent.get(f"{kind}:{name}", 0.0) + spent_s
        n_stored += bool(stored)
        if isinstance(out, _JobError):
            result.errors.append({"job": kind, "backend": name, "pendulum": pend,
                                  "label": [str(x) for x in label[3:]],
                                  "args": _describe_args(job.args()), "error": out.message})
            continue
        if kind == "history":
            result.histories[(label[3], pend, name)] = out
        elif kind == "restitution":
            result.restitution.append({"backend": name, "pendulum": pend, **out.to_dict()})
        elif kind == "threshold":
            ref_spectra[pend].setdefault("engines", {}).setdefault(name, []).append(
                {**out.to_dict(), "from_store": bool(stored)})
        elif kind == "long_run":
            result.long_runs.append(out)
        elif kind == "jump":
            ref_spectra[pend].setdefault("jump_shifts", {})[name] = out.to_dict()
        elif kind == "reverify":
            reverified.append(out)
    # Sorted by the key's text (str of the whole item would print every array).
    for (point, pend, name), traj in sorted(result.histories.items(),
                                            key=lambda kv: str(kv[0])):
        ref = result.histories.get((point, pend, config.reference))
        if name == config.reference or ref is None:
            continue
        comp = metrics.compare_trajectories(ref, traj, scenes[pend].alpha)
        result.comparisons.append({"point": point, "pendulum": pend, "backend": name,
                                   **comp.to_dict()})
    result.spectra = {_case(p): s for p, s in ref_spectra.items()}
    if config.stored is not None or config.reverify:
        stored_parts.merge(result, stored_run, source, recomputed, reverified, unused)
    result.verdicts = stored_parts.annotate(build_verdicts(result), result.sources)
    result.timings.update(cpu_by_job=cpu, spent_by_job=spent, from_store=n_stored,
                          n_jobs=len(jobs), total=time.perf_counter() - t_start,
                          load_average=[load_start, os.getloadavg()[0]])
    return result
