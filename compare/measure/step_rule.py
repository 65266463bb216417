"""The step is ruled out first: a threshold that fails at a step coarser than the
engine's reference step is remeasured at finer steps before any other cause is named.

A calibrated threshold step (``dt`` coarser than the engine's reference step, the
step its accuracy was established at) holds where it was calibrated.  On another
structure it can move a threshold out of the tolerance, lose the bracket or break
the frame; the cause search would then name the model, a collapse or a missing
bracket for what is a too-coarse step.  So every caller of the one threshold
measurement (:func:`compare.measure.engine_spectrum.measure_point`: ``spectrum
--engine``, ``map --engine``, ``report``, ``campaign``, ``atlas``, ``fragility``,
calibrate's validation) passes a point that *fails* (disagrees beyond the
tolerance, has no robust bracket, or collapsed below its first overturn) through
:func:`rule_out_step`:

1. the point is remeasured at each step of :func:`finer_steps`, coarse to fine,
   down to the reference step (the same robust search, the same settings but
   ``dt``);
2. the first (coarsest) finer step at which the point *passes* (bracketed, within
   the tolerance, no collapse below) ends the rule: the cause is
   ``discretisation``, reported with that step and its bracket;
3. when no finer step passes, the step is ruled out and the reference step's
   point is the one whose causes are searched.

Only failing points are rerun, so the rule costs nothing where a step agrees.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from trilith_xval.engines import configure
from trilith_xval.engines.calibration import reference_dt as reference_step

from trilith_xval.compare.measure.threshold_point import ThresholdPoint
from trilith_xval.compare.measure.thresholds import SEARCH, Search, engine_threshold

__all__ = ["StepCheck", "finer_steps", "passes", "reference_step", "rule_out_step",
           "LADDER"]

# Multiples of the reference step tried between a coarse step and the reference:
# the 1-2-5 series, the atlas's own step factors, so a rerun at one of them is
# served by the run store where the atlas measured it.
LADDER = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0)
# Two steps closer than this ratio are one step (float noise of dt * factor).
_SAME_STEP = 1.0 + 1e-9


def finer_steps(dt: float, reference_dt: float) -> list[float]:
    """Steps strictly finer than ``dt`` down to ``reference_dt``, coarse to fine:
    ``reference_dt`` times :data:`LADDER`.

    >>> finer_steps(1e-3, 1e-4)
    [0.0005, 0.0002, 0.0001]
    >>> finer_steps(1e-4, 1e-4)
    []
    """
    if not dt > reference_dt * _SAME_STEP:
        return []
    out = [reference_dt * f for f in reversed(LADDER) if reference_dt * f * _SAME_STEP < dt]
    return [float(f"{s:.12g}") for s in out]


def passes(point: ThresholdPoint, tol: float) -> bool:
    """A robust bracket within ``tol`` of the model and no collapse below it."""
    return point.bracketed and abs(point.rel_error) <= tol and not point.collapsed_below


def _row(point: ThresholdPoint, dt: float, tol: float) -> dict:
    return {"dt": dt, "a_engine": point.a_engine, "a_survives": point.a_survives,
            "rel_error": point.rel_error, "bracketed": point.bracketed,
            "collapsed_below": point.collapsed_below, "passes": passes(point, tol),
            "cpu_s": point.cpu_s}


@dataclass(frozen=True)
class StepCheck:
    """What :func:`rule_out_step` found.

    ``rows``: the step's own point then each finer step tried (dicts: dt,
    a_engine, a_survives, rel_error, bracketed, collapsed_below, passes, cpu_s);
    ``agreeing_dt``: the coarsest finer step that passes (None when none does, or
    when no finer step exists); ``point`` and ``settings``: the point whose causes
    are to be searched (the finest step measured when none passes, else the
    step's own).
    """

    rows: tuple
    agreeing_dt: float | None
    point: ThresholdPoint
    settings: object

    @property
    def rerun_cpu_s(self) -> float:
        """CPU seconds of the finer steps' searches when computed."""
        return math.fsum(r["cpu_s"] for r in self.rows[1:] if math.isfinite(r["cpu_s"]))

    def detail(self, tol: float) -> str:
        """One line: the error at each step tried, and the step that passes."""
        def err(r):
            if not r["bracketed"]:
                return "no bracket"
            return f"{100 * r['rel_error']:+.2f} %" + (" (collapse below)"
                                                       if r["collapsed_below"] else "")
        steps = "; ".join(f"dt = {r['dt']:.3g} s: {err(r)}" for r in self.rows)
        if self.agreeing_dt is None:
            return f"{steps}; no step down to the reference meets {100 * tol:g} %"
        ok = next(r for r in self.rows if r["dt"] == self.agreeing_dt)
        return (f"{steps}; dt <= {self.agreeing_dt:.3g} s meets {100 * tol:g} % "
                f"(bracket {ok['a_survives']:.5g}-{ok['a_engine']:.5g} m/s^2)")


def rule_out_step(engine: str, scene, omega: float, point: ThresholdPoint, settings, *,
                  kind="sine", tol: float, search: Search = SEARCH,
                  reference_dt: float | None = None, **search_kwargs) -> StepCheck:
    """Remeasure a failing ``point`` at finer steps (module docstring).

    Parameters
    ----------
    engine, scene, omega, point, settings
        The engine, the scene, the frequency [rad/s], the point measured at
        ``settings`` (whose ``dt`` is the step under test).
    kind : str or PulseShape
        The pulse, as the point's search.
    tol : float
        Agreement tolerance on the relative error.
    search : Search
        The robust search the point used (the reruns use the same).
    reference_dt : float, optional
        Default :func:`reference_step` of the engine.
    **search_kwargs
        Passed on to :func:`~compare.measure.thresholds.engine_threshold` as the
        point's search had them (e.g. ``motion=`` for a ground motion).

    Returns
    -------
    StepCheck
        Nothing rerun (``rows`` holds the point alone) when the point passes or
        its step is already the reference.
    """
    ref = reference_step(engine) if reference_dt is None else float(reference_dt)
    rows = [_row(point, settings.dt, tol)]
    if passes(point, tol):
        return StepCheck(tuple(rows), None, point, settings)
    last, last_settings = point, settings
    for dt in finer_steps(settings.dt, ref):
        finer = configure(engine, settings, dt=dt)
        p = engine_threshold(engine, scene, omega, point.a_reference, finer, kind=kind,
                             mode_reference=point.mode_reference, search=search,
                             **search_kwargs)
        rows.append(_row(p, dt, tol))
        if passes(p, tol):
            return StepCheck(tuple(rows), dt, point, settings)
        last, last_settings = p, finer
    return StepCheck(tuple(rows), None, last, last_settings)
