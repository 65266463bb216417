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

from trilith_xval.engines import configure

from trilith_xval.compare.measure.causes import (PRIMARY_ORDER, classify, explain_isolated, model_validity,
                                    sensitivity_detail)
from trilith_xval.compare.measure.step_rule import passes, rule_out_step
from trilith_xval.compare.measure.threshold_point import ThresholdPoint
from trilith_xval.compare.measure.thresholds import SEARCH, engine_threshold

__all__ = ["EnginePoint", "EngineSpectrum", "engine_spectrum", "engine_points", "measure_point",
           "pulse_settings", "CAUSES", "DEFAULT_TOL", "DEFAULT_REL_TOL"]

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


def pulse_settings(engine: str, scene, a_max: float, omega: float, kind: str = "sine",
                   **options):
    """The engine's settings (``options`` applied) with a fixed friction raised to
    :data:`engines.base.FRICTION_MARGIN` times the no-sliding bound of the largest
    pulse a bracket may try (a friction of None is the engine's own default for
    each run, which follows the same rule): :meth:`compare.run.spec.RunSpec.resolve`."""
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.compare.run.spec import RunSpec
    return RunSpec.resolve(engine, scene, pulse_of(kind, a_max, omega), overrides=options,
                           overrides_from="the options given").settings


def measure_point(engine: str, scene, omega: float, a_reference: float,
                  mode_reference: str | None = None, *, case: str = "", kind: str = "sine",
                  tol: float = DEFAULT_TOL, rel_tol: float = DEFAULT_REL_TOL,
                  rel_bracket: float | None = None, convergence: bool = True, settings=None,
                  **options) -> EnginePoint:
    """The one engine threshold measurement (module docstring).

    Parameters
    ----------
    engine, scene, omega, a_reference, mode_reference
        The engine, the scene (its pendulum included or not), the frequency
        [rad/s], the model's threshold [m/s^2] and mode.
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
    settings : EngineSettings, optional
        Default: :func:`pulse_settings` for pulses up to 2.2 ``a_reference``
        (the widest bracket) with ``options``.
    """
    if settings is None:
        settings = pulse_settings(engine, scene, 2.2 * a_reference, omega, kind, **options)
    search = SEARCH.with_rel_tol(rel_tol)
    if rel_bracket is not None:
        search = dataclasses.replace(search, rel_bracket=rel_bracket)
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


def _point_job(args) -> EnginePoint:
    engine, scene, case, omega, a_ref, mode_ref, kind, options, tol, rel_tol, convergence = args
    return measure_point(engine, scene, omega, a_ref, mode_ref, case=case, kind=kind, tol=tol,
                         rel_tol=rel_tol, convergence=convergence, **options)


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


def engine_spectrum(engine: str, scene, reference, *, kind: str = "sine", workers: int = 1,
                    tol: float = DEFAULT_TOL, rel_tol: float = DEFAULT_REL_TOL,
                    convergence: bool = False, **options) -> EngineSpectrum:
    """``engine``'s first-overturning amplitudes on the grid of ``reference``.

    Parameters
    ----------
    engine : str
        A registered engine (``engines.ENGINES``).
    scene : Scene
        With its pendulum; the no-pendulum curve uses ``scene.without_pendulum()``.
    reference : analytic.spectrum.Spectrum
        The analytic spectrum on the wanted grid (gives ``a_reference`` and the
        modes).
    kind : {'sine', 'cosine'}
    workers : int
        Processes (one frequency each).
    tol : float
        Agreement tolerance on the relative threshold error (default 2 %).
    rel_tol : float
        Final bracket width relative to the analytic threshold (default 0.5 %).
    convergence : bool
        Rerun failing points at ``dt/2``, ``dt/4`` and doubled iterations.
    **options
        Engine settings (:func:`engines.configure`), e.g. ``dt``.

    Returns
    -------
    EngineSpectrum
    """
    from trilith_xval.engines import get_backend
    settings = configure(engine, **options)  # validates the options up front
    omegas = [float(w) for w in reference.omega]
    jobs, keys = [], []
    curves = (("pendulum", scene, reference.a_pendulum, reference.mode_pendulum),
              ("no_pendulum", scene.without_pendulum(), reference.a_no_pendulum,
               reference.mode_no_pendulum))
    for curve, sc, amps, modes in curves:
        if curve == "pendulum" and not scene.has_pendulum:
            continue
        for w, a, m in zip(omegas, amps, modes):
            if not math.isfinite(a):
                continue
            jobs.append((engine, sc, curve, w, float(a), m, kind, options, tol, rel_tol,
                         convergence))
            keys.append(curve)
    results = _map(_point_job, jobs, workers, f"spectrum {engine}")
    out = EngineSpectrum(engine, get_backend(engine).version(), settings.describe(), kind, tol,
                         rel_tol)
    for key, point in zip(keys, results):
        out.curves.setdefault(key, []).append(point)
    return out


def engine_points(engine: str, scene, omegas, a_references, modes, *, case: str = "",
                  kind: str = "sine", workers: int = 1, tol: float = DEFAULT_TOL,
                  rel_tol: float = DEFAULT_REL_TOL, convergence: bool = False,
                  **options) -> list[EnginePoint]:
    """:func:`measure_point` at each ``(omega, a_reference, mode)`` of one curve of
    one scene (``case`` names it), in order, ``workers`` processes (one frequency
    each); frequencies whose model threshold is not finite are skipped."""
    configure(engine, **options)  # validates the options up front
    jobs = [(engine, scene, case, float(w), float(a), m, kind, options, tol, rel_tol,
             convergence) for w, a, m in zip(omegas, a_references, modes) if math.isfinite(a)]
    return _map(_point_job, jobs, workers, f"{engine} {case}".strip())


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
