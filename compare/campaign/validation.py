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

from analytic.excitation import Pulse
from analytic.options import MAX_ENGINE_DT
from engines import ENGINES, configure
from scenes import POINTS, load_scene


from compare.measure import trajectories as metrics


from compare.run import runs
from compare.run.jsonable import plain
from compare.run.keys import backend_version
from compare.measure.restitution import RestitutionResult, measure_restitution
from compare.measure.reference_spectra import choose_frequencies, reference_spectrum
from compare.measure.jump_shift import engine_jump_frequency

__all__ = ["Tolerances", "CampaignConfig", "run_campaign", "backend_settings",
           "engine_options", "free_rocking_restitution"]


@dataclass(frozen=True)
class Tolerances:
    """Acceptance tolerances of the verdict table, each with its reason."""

    restitution: float = 0.005  # acceptance: Eq. 20 within 0.5 %
    restitution_pendulum: float = 0.005  # Eq. 19 at the measured psi: its relative slope in psi
    #   is <= 0.11 /rad on the lam 3-7 grid, so even a 0.01 rad psi error costs < 0.1 %
    threshold: float = 0.02  # acceptance: overturning amplitude within 2 % away from jumps
    theta_rms_first: float = 1e-3  # theta RMS / alpha before the first impact: worst measured
    #   3e-4 with calibrated defaults; grows ~linearly with dt (Pymunk, A: 1.2e-4, 7.6e-4, 1.6e-3,
    #   3.5e-3 at 1e-4, 5e-4, 1e-3, 2e-3 s), so 1e-3 rejects steps >= 1e-3 s
    verdict_mismatches: int = 0  # the paper's A-D verdicts (status and mode) must agree exactly

    def reasons(self) -> dict[str, str]:
        return {
            "restitution": "Eq. 20 within 0.5 %: the rocking energy kept per impact goes "
                           "as the velocity ratio squared, so 0.5 % on the ratio is 1 % of "
                           "the energy per impact, 4 % after the 4 measured impacts",
            "restitution_pendulum": "Eq. 19 at the measured psi: same 0.5 % as Eq. 20, since "
                                    "its relative slope in psi is <= 0.11/rad (a 0.01 rad psi "
                                    "error costs < 0.1 %)",
            "threshold": "2 % of the overturning amplitude, 4x the 0.5 % bracket of the "
                         "robust search (a miss is a measured difference, not bracket noise); "
                         "away from mode jumps, where the threshold is discontinuous in Omega",
            "theta_rms_first": "worst measured 3e-4 of alpha at the calibrated 1e-4 s step; the "
                               "error grows ~linearly with dt (3.5e-3 at 2e-3 s), 1e-3 rejects "
                               "steps >= 1e-3 s",
            "verdict_mismatches": "overturned/survived and the mode must match the model exactly",
        }


@dataclass(frozen=True)
class CampaignConfig:
    """What the campaign runs.  ``quick()`` is the 2-minute variant."""

    scene: str = "fig5"  # the paper's Fig. 5 trilith (lam 5, b 0.6 m, mu 1, gamma 0.3)
    engines: tuple[str, ...] = ENGINES  # the engines under validation
    reference: str = "analytic"  # accurate scipy path for time histories
    spectrum_backend: str = "analytic-fast"  # compiled path: a spectrum costs ~1 s
    points: tuple[str, ...] = ("A", "B", "C", "D")  # the paper's labelled cases
    restitution_lams: tuple[float, ...] = (3.0, 5.0, 7.0)  # lam 3-7 x mu 0.5-2, the paper's range
    restitution_mus: tuple[float, ...] = (0.5, 1.0, 2.0)  # lam 3-7 x mu 0.5-2, the paper's range
    pendulum_lams: tuple[float, ...] = (3.0, 5.0, 7.0)  # Eq. 19 runs (scene's mu, gamma)
    theta0_fraction: float = 0.5  # release tilt / alpha: well inside the well, fast impacts
    n_impacts: int = 4  # per free-rocking run: two of each side, as compare/measure/restitution.py
    spectrum_cases: tuple[str, ...] = ("pendulum", "no_pendulum")  # Fig. 5: both curves
    n_frequencies: int = 6  # engine threshold frequencies per case (away from jumps); 10-min budget
    omega_range: tuple[float, float] = (5.0, 26.0)  # rad/s: most of the Fig. 5 axis (3-30); the
    #   ends cost most (long pulses) or need > 8 g pulses
    spectrum_step: float = 0.5  # rad/s: reference spectrum grid, locates the jumps
    jump_margin: float = 1.5  # rad/s kept between a threshold frequency and a jump
    jump_cases: tuple[str, ...] = ("pendulum",)  # the paper's Omega_1 jump (Fig. 5, circled)
    rel_bracket: float = 0.03  # frequencies are chosen where the model is monotone 2x this above
    rel_tol: float = 5e-3  # robust bracket width (the one search's, compare.measure.thresholds)
    engine_dt: float | None = None  # override every engine's time step (None: calibrated)
    engine_settings: dict = field(default_factory=dict)  # {engine: {field: value}}, a settings
    #   file's tables (compare/campaign/settings_file.py), under engine_dt and each job's own
    long_run_t_max: float = 20.0  # s, fixed window of the long runs (compare/measure/long_runs.py)
    long_runs: bool = True  # the trust table's long-run line (rest, after a pulse)
    workers: int = 2  # the target machine has 2 cores
    tolerances: Tolerances = Tolerances()

    def __post_init__(self) -> None:
        for name in self.engines:
            if name not in ENGINES:
                raise ValueError(f"engines: unknown engine {name!r}; allowed: {', '.join(ENGINES)}")
        if not self.engines:
            raise ValueError("engines must name at least one of: " + ", ".join(ENGINES))
        for p in self.points:
            if p not in POINTS:
                raise ValueError(f"points: unknown point {p!r}; allowed: {', '.join(POINTS)}")
        if not 0.05 <= self.theta0_fraction <= 0.9:
            raise ValueError(f"theta0_fraction must be in [0.05, 0.9], got {self.theta0_fraction!r}")
        if self.n_frequencies < 0 or self.n_impacts < 1 or self.workers < 1:
            raise ValueError("n_frequencies must be >= 0, n_impacts >= 1 and workers >= 1")
        if self.engine_dt is not None and not (math.isfinite(self.engine_dt)
                                               and 0.0 < self.engine_dt <= MAX_ENGINE_DT):
            raise ValueError(f"engine_dt must be in (0, {MAX_ENGINE_DT:g}] s, "
                             f"got {self.engine_dt!r}")
        for name, options in self.engine_settings.items():
            if name not in ENGINES:
                raise ValueError(f"engine_settings: unknown engine {name!r}; allowed: "
                                 f"{', '.join(ENGINES)}")
            configure(name, **options)  # refused here, naming the field, not in a worker
        for case in (*self.spectrum_cases, *self.jump_cases):
            if case not in ("pendulum", "no_pendulum"):
                raise ValueError(f"spectrum_cases: unknown case {case!r}; allowed: pendulum, "
                                 "no_pendulum")
        lo, hi = self.omega_range
        if not 0.0 < lo < hi:
            raise ValueError(f"omega_range must satisfy 0 < lo < hi, got {self.omega_range!r}")

    @classmethod
    def quick(cls, **changes) -> "CampaignConfig":
        """Smaller grids for ``--quick`` (< 2 min on 2 cores)."""
        base = dict(restitution_lams=(3.0, 7.0), restitution_mus=(1.0,), pendulum_lams=(5.0,),
                    n_impacts=3, n_frequencies=1, jump_cases=(), long_runs=False)
        base.update(changes)
        return cls(**base)

    def to_dict(self) -> dict:
        return plain(self)


def engine_options(name: str, config: CampaignConfig, thresholds: bool = False) -> dict:
    """The options the campaign sets for backend ``name``: for a threshold search
    (``thresholds``) the engine's calibrated threshold settings
    (:func:`compare.campaign.settings_file.threshold_options`) first, then its
    settings-file table, then ``engine_dt`` (engines only)."""
    from compare.campaign.settings_file import threshold_options
    options = threshold_options(name) if thresholds and name in ENGINES else {}
    options.update(config.engine_settings.get(name, {}))
    if config.engine_dt is not None and name in ENGINES:
        options["dt"] = config.engine_dt
    return options


def backend_settings(name: str, config: CampaignConfig, **options):
    """``name``'s calibrated settings (:func:`engines.configure`) with
    :func:`engine_options` applied, then ``options``."""
    return configure(name, **{**engine_options(name, config), **options})


# ----------------------------------------------------------------------- jobs
def _job_history(name, scene, point, config):
    amp, omega = POINTS[point]
    settings = backend_settings(name, config)
    return runs.simulate(name, scene, Pulse(amp, omega), settings)


def free_rocking_restitution(name: str, scene, config: CampaignConfig | None = None
                             ) -> RestitutionResult:
    """Release ``scene`` at rest from ``theta0_fraction * alpha`` in backend ``name``
    (no base motion) and measure the first ``n_impacts`` impacts against Eq. 19/20."""
    config = config or CampaignConfig()
    return measure_restitution(name, scene, config.theta0_fraction * scene.alpha,
                               backend_settings(name, config), n_impacts=config.n_impacts)


def _pulse_settings(name: str, config: CampaignConfig, scene, a_max: float, omega: float):
    """Calibrated settings (with the campaign's ``engine_dt``) and the friction raised
    for the largest pulse of the job (:func:`compare.measure.engine_spectrum.pulse_settings`)."""
    from compare.measure.engine_spectrum import pulse_settings
    return pulse_settings(name, scene, a_max, omega, **engine_options(name, config))


def _job_threshold(name, scene, case, omega, a_ref, mode_ref, config):
    """The one threshold measurement (:func:`compare.measure.engine_spectrum.measure_point`)."""
    from compare.measure.engine_spectrum import measure_point
    return measure_point(name, scene, omega, a_ref, mode_ref, case=case,
                         tol=config.tolerances.threshold, rel_tol=config.rel_tol,
                         convergence=True, **engine_options(name, config, thresholds=True))


def _job_jump(name, scene, amplitude, w_lo, w_hi, config):
    return engine_jump_frequency(name, scene, amplitude, w_lo, w_hi,
                                 _pulse_settings(name, config, scene, amplitude, w_hi),
                                 reference_backend=config.spectrum_backend)


def _job_long_run(name, label, scene_name, amplitude, omega, config):
    from compare.measure.long_runs import long_run
    return long_run(name, label, scene_name, amplitude, omega, config.long_run_t_max,
                    backend_settings(name, config))


_JOBS = {"history": _job_history, "restitution": free_rocking_restitution,
         "threshold": _job_threshold, "jump": _job_jump, "long_run": _job_long_run}


def _run_one(item):
    """Run one job: ``(result, cpu_s when computed, cpu_s spent now, from_store)``.
    An exception becomes an error record (one bad engine run must not sink a
    10-minute campaign; the verdict table then reports it unmeasured)."""
    kind, args = item
    c0 = time.process_time()

    def compute():  # stored with its CPU cost, so a store hit can say what it cost
        t0 = time.process_time()
        value = _JOBS[kind](*args)
        return {"value": value, "cpu_s": _own_cost(value, time.process_time() - t0)}
    try:  # through the store: a finished job is not redone (compare/ code in its key)
        hits = runs.STATS["hits"]
        out = runs.memo("campaign-job", _job_description(item), compute, code=runs.ALL_CODE)
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


def _job_description(item) -> dict:
    kind, args = item
    config = next((a for a in args if isinstance(a, CampaignConfig)), None)
    described = None if config is None else {k: v for k, v in config.to_dict().items()
                                             if k != "workers"}
    return {"kind": kind, "args": _describe_args(args), "config": described}


def _lookup(item):
    """A finished job from the store (nothing spent now), or None."""
    out = runs.lookup("campaign-job", _job_description(item), code=runs.ALL_CODE)
    return None if out is None else (out["value"], out["cpu_s"], 0.0, True)


@dataclass(frozen=True)
class _JobError:
    message: str


def _progress(total: int):
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(total=total, desc="campaign", unit="run", disable=not sys.stderr.isatty(),
                leave=False)


def _execute(jobs: list, workers: int) -> list:
    """Run ``jobs`` ((kind, args) pairs); results in job order."""
    bar = _progress(len(jobs))
    try:
        return list(runs.run_many(_run_one, jobs, workers=workers, lookup=_lookup,
                                  on_done=None if bar is None else lambda i, r: bar.update()))
    finally:
        if bar is not None:
            bar.close()


def _memo(kind: str, scene, config: CampaignConfig, compute):
    """A model-side result (reference spectrum, chosen frequencies) through the run
    store, keyed by the scene and the config (but its worker count: no number
    depends on it)."""
    from compare.run.keys import scene_dict
    described = {k: v for k, v in config.to_dict().items() if k != "workers"}
    return runs.memo(kind, {"scene": scene_dict(scene), "config": described}, compute,
                     code=runs.ALL_CODE)


def _case(pendulum: bool) -> str:
    return "pendulum" if pendulum else "no_pendulum"


def _describe_args(args) -> list:
    """Job arguments for the error record (scenes and configs by name)."""
    out = []
    for a in args:
        if isinstance(a, CampaignConfig):
            continue
        out.append(a.to_dict() if hasattr(a, "to_dict") else a)
    return plain(out)


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

    def to_dict(self) -> dict:
        return {"config": self.config.to_dict(), "scene": self.scene.to_dict(),
                "settings": self.settings, "versions": self.versions,
                "comparisons": self.comparisons, "restitution": self.restitution,
                "spectra": self.spectra, "verdicts": self.verdicts, "timings": self.timings,
                "errors": self.errors, "long_runs": self.long_runs,
                "threshold_settings": self.threshold_settings}


def run_campaign(config: CampaignConfig | None = None) -> CampaignResult:
    """Run the validation campaign described by ``config`` (default: full)."""
    from compare.campaign.verdicts import build_verdicts

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
        settings={b: plain(backend_settings(b, config)) for b in backends},
        threshold_settings={e: plain(configure(e, **engine_options(e, config, thresholds=True)))
                            for e in config.engines},
        versions={b: backend_version(b) for b in (*backends, config.spectrum_backend)})

    # Reference spectra first (in this process: the compiled kernels are then
    # inherited by the forked workers).
    t0 = time.perf_counter()
    ref_spectra = {pend: _memo("reference-spectrum", sc, config,
                               lambda sc=sc: reference_spectrum(sc, config))
                   for pend, sc in scenes.items()
                   if _case(pend) in (*config.spectrum_cases, *config.jump_cases)}
    result.timings["reference_spectra"] = time.perf_counter() - t0

    jobs, labels = [], []
    for pend, spec in ref_spectra.items():
        sc = scenes[pend]
        freqs = _memo("frequencies", sc, config, lambda: choose_frequencies(spec, config, sc)) \
            if _case(pend) in config.spectrum_cases else []
        for omega, a_ref, mode in freqs:
            for name in config.engines:
                jobs.append(("threshold", (name, sc, _case(pend), omega, a_ref, mode, config)))
                labels.append(("threshold", pend, name))
        if _case(pend) in config.jump_cases and (spec.get("jump") or {}).get("probe_amplitude"):
            jmp = spec["jump"]
            for name in config.engines:
                jobs.append(("jump", (name, sc, jmp["probe_amplitude"], jmp["omega_lo"],
                                      jmp["omega_hi"], config)))
                labels.append(("jump", pend, name))
    for pend, sc in scenes.items():
        for point in config.points:
            for name in backends:
                jobs.append(("history", (name, sc, point, config)))
                labels.append(("history", pend, name, point))
    base = scene.without_pendulum()
    for name in config.engines:
        for lam in config.restitution_lams:
            for mu in config.restitution_mus:
                jobs.append(("restitution", (name, base.replace(lam=lam, mu=mu), config)))
                labels.append(("restitution", False, name))
        if scene.has_pendulum:
            for lam in config.pendulum_lams:
                jobs.append(("restitution", (name, scene.replace(lam=lam), config)))
                labels.append(("restitution", True, name))

    if config.long_runs:
        from compare.measure.long_runs import LONG_RUNS
        for name in config.engines:
            for label, scene_name, amplitude, omega in LONG_RUNS:
                jobs.append(("long_run", (name, label, scene_name, amplitude, omega, config)))
                labels.append(("long_run", False, name))
    t0 = time.perf_counter()
    outputs = _execute(jobs, config.workers)
    result.timings["engine_runs_wall"] = time.perf_counter() - t0
    cpu: dict[str, float] = {}
    spent: dict[str, float] = {}
    n_stored = 0
    for label, job, (out, cpu_s, spent_s, stored) in zip(labels, jobs, outputs):
        kind, pend, name = label[:3]
        cpu[f"{kind}:{name}"] = cpu.get(f"{kind}:{name}", 0.0) + cpu_s
        spent[f"{kind}:{name}"] = spent.get(f"{kind}:{name}", 0.0) + spent_s
        n_stored += bool(stored)
        if isinstance(out, _JobError):
            result.errors.append({"job": kind, "backend": name, "pendulum": pend,
                                  "label": [str(x) for x in label[3:]],
                                  "args": _describe_args(job[1]), "error": out.message})
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
    result.verdicts = build_verdicts(result)
    result.timings.update(cpu_by_job=cpu, spent_by_job=spent, from_store=n_stored,
                          n_jobs=len(jobs), total=time.perf_counter() - t_start,
                          load_average=[load_start, os.getloadavg()[0]])
    return result
