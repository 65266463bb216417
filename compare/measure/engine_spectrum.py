"""Engine overturning spectra: the one threshold measurement per point, with its
causes.

:func:`measure_point` is the one measurement every command uses (``trilith
report``, ``spectrum --engine``, ``campaign``, ``map --engine``): the robust
threshold search (:func:`compare.measure.thresholds.engine_threshold` with
:data:`compare.measure.thresholds.SEARCH`), the model's validity at the point,
the explanation of every isolated overturn, and, where the point fails
(disagrees beyond the tolerance, no bracket, a collapse below), first the step
rule (:func:`compare.measure.step_rule.rule_out_step`: finer steps down to the
engine's reference step; a finer step that passes makes the cause
'discretisation'), then every candidate cause and the primary one at the finest
step measured (:func:`compare.measure.causes.classify`).  Its result, :class:`EnginePoint`,
is the one result type (``to_dict`` is the summary's
:class:`compare.campaign.summary.ThresholdResult`).

:func:`engine_spectrum` measures every frequency of a reference spectrum's grid,
both curves.  No cause depends on the grid: a mode jump is located on the
model's own curve around each point.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from trilith_xval.analytic.pulses import pulse_of

from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.compare.measure.causes import (PRIMARY_ORDER, classify, explain_isolated, model_validity,
                                    sensitivity_detail)
from trilith_xval.compare.measure.step_rule import passes, rule_out_step
from trilith_xval.compare.measure.threshold_point import ThresholdPoint
from trilith_xval.compare.measure.thresholds import SEARCH, engine_threshold

__all__ = ["EnginePoint", "EngineSpectrum", "PointJob", "engine_spectrum", "engine_points",
           "measure_point", "point_search", "point_spec", "threshold_spec", "pulse_settings", "CAUSES", "DEFAULT_TOL",
           "DEFAULT_REL_TOL"]

CAUSES = ("agrees", *PRIMARY_ORDER, "unknown")
DEFAULT_TOL = 0.02  # agreement tolerance on the threshold (2 %)
DEFAULT_REL_TOL = SEARCH.rel_tol  # final bracket width / A_analytic: 0.5 %


@dataclass(frozen=True)
class EnginePoint:
    """One engine threshold point with its causes (module docstring).

    ``point`` is the robust search's result; ``cause`` the primary cause
    ('agrees' within ``tol``), ``causes`` every applying one, ``valid`` the
    model at the decisive amplitude, ``validity`` every check, ``isolated`` the
    search's isolated overturns with what made them (``detail``).  ``steps``: the
    step rule's rows (:mod:`compare.measure.step_rule`: this step, then each finer
    step tried; empty when the point passed at its step) and ``agreeing_dt`` the
    coarsest finer step that passes (the cause is then 'discretisation').
    """

    case: str
    point: ThresholdPoint
    cause: str
    cause_detail: str
    causes: tuple = ()
    valid: bool | None = None
    validity: tuple = ()
    convergence: tuple = ()
    isolated: tuple = ()
    steps: tuple = ()
    agreeing_dt: float | None = None

    def __getattr__(self, name):  # omega, a_engine, a_survives, rel_error, ... of the point
        if name == "point":
            raise AttributeError(name)
        return getattr(self.point, name)

    @property
    def cpu_s(self) -> float:
        """CPU seconds of the point's runs when computed, the reruns (finer steps of
        the step rule, cause reruns) included."""
        extra = [r.get("cpu_s", math.nan) for r in (*self.steps[1:], *self.convergence[1:])]
        return self.point.cpu_s + math.fsum(extra) if extra else self.point.cpu_s

    def to_dict(self) -> dict:
        out = self.point.to_dict()
        out.update(case=self.case, cause=self.cause, cause_detail=self.cause_detail,
                   causes=list(self.causes), valid=self.valid, validity=list(self.validity),
                   convergence=list(self.convergence), isolated=list(self.isolated),
                   steps=list(self.steps), agreeing_dt=self.agreeing_dt,
                   cpu_s=self.cpu_s, search_cpu_s=self.point.cpu_s)
        return out


def point_search(rel_tol: float = DEFAULT_REL_TOL, rel_bracket: float | None = None):
    """The search :func:`measure_point` runs: :data:`SEARCH` at ``rel_tol``, its
    first bracket's half-width ``rel_bracket`` when given."""
    search = SEARCH.with_rel_tol(rel_tol)
    return search if rel_bracket is None else dataclasses.replace(search, rel_bracket=rel_bracket)


def threshold_spec(engine: str, scene, omega: float, a_reference: float, kind="sine", *,
                   calibrated: bool = False, options: dict | None = None,
                   search=SEARCH) -> RunSpec:
    """The run of a threshold search at one point, resolved once
    (:meth:`compare.run.spec.RunSpec.resolve`): ``engine`` on ``scene`` under the
    largest ``kind`` pulse the search may try (``search.widest`` times
    ``a_reference`` [m/s^2] at ``omega`` [rad/s]), so the friction rule holds for
    every run of the search; ``calibrated`` starts from the engine's calibrated
    threshold settings where the scene lies in their domain; ``options`` go over
    them (the caller's own values)."""
    return RunSpec.resolve(engine, scene, pulse_of(kind, search.widest * a_reference, omega),
                           calibrated=calibrated, overrides=options,
                           overrides_from="the options given")


def point_spec(run: RunSpec, scene, omega: float, a_reference: float, kind="sine",
               search=SEARCH) -> RunSpec:
    """``run``'s layers at one threshold point: on ``scene`` under the largest
    pulse the search may try (as :func:`threshold_spec`)."""
    return run.at(scene, pulse_of(kind, search.widest * a_reference, omega))


def pulse_settings(engine: str, scene, a_max: float, omega: float, kind="sine",
                   options: dict | None = None):
    """The engine's settings (``options`` applied) for runs under ``kind`` pulses up
    to ``a_max`` [m/s^2] at ``omega``: a fixed friction is checked (or, set by a
    calibration, raised) for the largest of them, as in every threshold search
    (:meth:`compare.run.spec.RunSpec.resolve`)."""
    return RunSpec.resolve(engine, scene, pulse_of(kind, a_max, omega), overrides=options,
                           overrides_from="the options given").settings


def measure_point(spec: RunSpec, omega: float, a_reference: float,
                  mode_reference: str | None = None, *, case: str = "", kind="sine",
                  tol: float = DEFAULT_TOL, rel_tol: float = DEFAULT_REL_TOL,
                  rel_bracket: float | None = None, convergence: bool = True) -> EnginePoint:
    """The one engine threshold measurement (module docstring).

    Parameters
    ----------
    spec : RunSpec
        The search's run: engine, scene (its pendulum included or not) and
        settings, resolved at the largest pulse the search may try
        (:func:`threshold_spec`, or :meth:`RunSpec.at` of a template).
    omega, a_reference, mode_reference
        The frequency [rad/s], the model's threshold [m/s^2] and mode.
    case : str
        'pendulum' or 'no_pendulum', carried into the result.
    kind : str or PulseShape
        A name of :data:`analytic.pulses.PULSE_FAMILY` or a shape (M-P's gamma,
        nu); the model's jump and island causes need the compiled sine/cosine.
    tol : float
        Agreement tolerance on the relative error (default 2 %).
    rel_tol : float
        Robust bracket width relative to ``a_reference`` (default 0.5 %).
    rel_bracket : float, optional
        First bracket's half-width relative to ``a_reference`` (default
        ``0.45 rel_tol``, :class:`~compare.measure.thresholds.Search`).
    convergence : bool
        Rerun a disagreeing point at dt/2, dt/4 and doubled iterations (of the
        finest step the step rule measured).  The step rule itself always runs.
    """
    if not isinstance(spec, RunSpec):
        raise TypeError(f"spec must be a RunSpec (compare.run.spec; threshold_spec makes "
                        f"one), got {type(spec).__name__}")
    engine, scene, settings = spec.backend, spec.scene, spec.settings
    search = point_search(rel_tol, rel_bracket)
    p = engine_threshold(engine, scene, omega, a_reference, settings, kind=kind,
                         mode_reference=mode_reference, search=search)
    isolated = tuple({**i, "detail": explain_isolated(engine, scene, omega, i, settings, kind)}
                     for i in p.isolated)
    if passes(p, tol):
        validity = model_validity(scene, omega, kind,
                                  {"model threshold": a_reference, "engine survives":
                                   p.a_survives, "engine overturns": p.a_engine},
                                  settings.friction)
        causes = (({"name": "sensitivity", "detail": sensitivity_detail(p)},)
                  if p.isolated or p.flips else ())
        return EnginePoint(case, p, "agrees", f"within {100 * tol:g} %", causes,
                           validity[0]["valid"], tuple(validity), (), isolated)
    # The step is ruled out before any other cause is named.
    check = rule_out_step(engine, scene, omega, p, settings, kind=kind, tol=tol, search=search)
    if check.agreeing_dt is not None:
        ok = next(r for r in check.rows if r["dt"] == check.agreeing_dt)
        validity = model_validity(scene, omega, kind,
                                  {"model threshold": a_reference, "engine survives":
                                   ok["a_survives"], "engine overturns": ok["a_engine"]},
                                  settings.friction)
        detail = check.detail(tol)
        return EnginePoint(case, p, "discretisation", detail,
                           ({"name": "discretisation", "detail": detail},),
                           validity[0]["valid"], tuple(validity), (), isolated,
                           check.rows, check.agreeing_dt)
    c = classify(engine, scene, omega, check.point, check.settings, kind=kind, tol=tol,
                 search=search, convergence=convergence)
    detail = c.detail
    if len(check.rows) > 1:
        detail = (f"at the reference step dt = {check.settings.dt:.3g} s ({check.detail(tol)}): "
                  f"{detail}")
    return EnginePoint(case, p, c.cause, detail, c.causes, c.valid, c.validity,
                       c.convergence, isolated, check.rows if len(check.rows) > 1 else ())


@dataclass(frozen=True)
class PointJob:
    """One point of a spectrum or a curve: :func:`measure_point` of ``spec`` (the
    point's run, resolved at its largest pulse) with these arguments."""

    spec: RunSpec
    case: str
    omega: float
    a_reference: float
    mode_reference: str | None
    kind: object = "sine"
    tol: float = DEFAULT_TOL
    rel_tol: float = DEFAULT_REL_TOL
    convergence: bool = False

    def run(self) -> EnginePoint:
        return measure_point(self.spec, self.omega, self.a_reference, self.mode_reference,
                             case=self.case, kind=self.kind, tol=self.tol,
                             rel_tol=self.rel_tol, convergence=self.convergence)


def _run_job(job: PointJob) -> EnginePoint:
    return job.run()


@dataclass
class EngineSpectrum:
    """Both curves of one engine on one grid; ``curves`` maps ``'pendulum'`` /
    ``'no_pendulum'`` to lists of :class:`EnginePoint`."""

    engine: str
    version: str
    settings: dict
    kind: str
    tol: float
    rel_tol: float
    curves: dict = field(default_factory=dict)

    def cost(self) -> dict:
        """CPU seconds of every point when computed (reruns included), spent now
        (0 for points the store served), points served whole by the store, and
        CPU seconds per simulated second of the searches."""
        pts = [p for v in self.curves.values() for p in v]
        sim = math.fsum(p.point.sim_s for p in pts)
        search = math.fsum(p.point.cpu_s for p in pts)
        return {"cpu_s": math.fsum(p.cpu_s for p in pts),
                "cpu_s_spent": math.fsum(p.point.cpu_s_spent for p in pts),
                "points": len(pts), "points_from_store": sum(p.point.from_store for p in pts),
                "runs": sum(p.point.n_runs for p in pts),
                "cpu_per_sim_s": search / sim if sim > 0 else math.nan}

    def to_dict(self) -> dict:
        return {"engine": self.engine, "version": self.version, "settings": self.settings,
                "pulse": self.kind, "tol": self.tol, "rel_tol": self.rel_tol,
                "cost": self.cost(),
                "curves": {k: [p.to_dict() for p in v] for k, v in self.curves.items()}}


def engine_spectrum(spec: RunSpec, reference, *, kind="sine", workers: int = 1,
                    tol: float = DEFAULT_TOL, rel_tol: float = DEFAULT_REL_TOL,
                    convergence: bool = False) -> EngineSpectrum:
    """An engine's first-overturning amplitudes on the grid of ``reference``.

    Parameters
    ----------
    spec : RunSpec
        The engine's run on the scene (with its pendulum; the no-pendulum curve
        uses ``scene.without_pendulum()``): its layers are resolved again at
        every point (:meth:`RunSpec.at`, the point's largest pulse), all before
        any run, so a bad value stops the command at the door.
    reference : analytic.spectrum.Spectrum
        The analytic spectrum on the wanted grid (gives ``a_reference`` and the
        modes).
    kind : {'sine', 'cosine'} or PulseShape
    workers : int
        Processes (one frequency each).
    tol : float
        Agreement tolerance on the relative threshold error (default 2 %).
    rel_tol : float
        Final bracket width relative to the analytic threshold (default 0.5 %).
    convergence : bool
        Rerun failing points at ``dt/2``, ``dt/4`` and doubled iterations.

    Returns
    -------
    EngineSpectrum
    """
    from trilith_xval.engines import get_backend
    scene, omegas = spec.scene, [float(w) for w in reference.omega]
    curves = (("pendulum", scene, reference.a_pendulum, reference.mode_pendulum),
              ("no_pendulum", scene.without_pendulum(), reference.a_no_pendulum,
               reference.mode_no_pendulum))
    jobs = []
    for curve, sc, amps, modes in curves:
        if curve == "pendulum" and not scene.has_pendulum:
            continue
        jobs += _jobs(spec, sc, curve, omegas, amps, modes, kind, tol, rel_tol, convergence)
    results = _map(_run_job, jobs, workers, f"spectrum {spec.backend}")
    out = EngineSpectrum(spec.backend, get_backend(spec.backend).version(),
                         spec.settings.describe(), kind, tol, rel_tol)
    for job, point in zip(jobs, results):
        out.curves.setdefault(job.case, []).append(point)
    return out


def engine_points(spec: RunSpec, omegas, a_references, modes, *, case: str = "",
                  kind="sine", workers: int = 1, tol: float = DEFAULT_TOL,
                  rel_tol: float = DEFAULT_REL_TOL, convergence: bool = False
                  ) -> list[EnginePoint]:
    """:func:`measure_point` at each ``(omega, a_reference, mode)`` of one curve of
    ``spec``'s scene (``case`` names it), in order, ``workers`` processes (one
    frequency each); frequencies whose model threshold is not finite are skipped.
    Every point's run is resolved before any runs (:func:`engine_spectrum`)."""
    jobs = _jobs(spec, spec.scene, case, omegas, a_references, modes, kind, tol, rel_tol,
                 convergence)
    return _map(_run_job, jobs, workers, f"{spec.backend} {case}".strip())


def _jobs(spec, scene, case, omegas, amps, modes, kind, tol, rel_tol, convergence) -> list:
    """A :class:`PointJob` per finite model threshold, each run resolved at its
    largest pulse (:meth:`SEARCH.widest <compare.measure.thresholds.Search.widest>`)."""
    search = point_search(rel_tol)
    return [PointJob(point_spec(spec, scene, float(w), float(a), kind, search), case,
                     float(w), float(a), m, kind, tol, rel_tol, convergence)
            for w, a, m in zip(omegas, amps, modes) if math.isfinite(a)]


def _map(fn, items: list, workers: int, desc: str = "points") -> list:
    """``[fn(x) for x in items]``, in order, through :func:`compare.run.runs.run_many`:
    local workers that die with their parent and stop at Ctrl-C, or the Dask
    cluster of ``--scheduler``; each engine run inside goes through the run store.
    Progress: :func:`compare.run.progress.bar` named ``desc``."""
    from trilith_xval.compare.run.progress import bar
    from trilith_xval.compare.run.runs import run_many
    progress = bar(len(items), desc, "points")
    try:
        return list(run_many(fn, items, workers=max(1, workers),
                             on_done=lambda i, r: progress.update(1)))
    finally:
        progress.close()
