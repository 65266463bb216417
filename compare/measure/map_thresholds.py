"""An engine's robust threshold at every frequency of its overturn map's grid.

``trilith map --engine`` draws each engine's verdict grid beside the model's map and,
per frequency column, the engine's robust first-overturning bracket from the one
measurement every command uses (:func:`compare.measure.engine_spectrum.measure_point`,
result :class:`~compare.measure.engine_spectrum.EnginePoint`), around the model's
threshold at that frequency (:func:`analytic.first_overturn.first_overturn_amplitude`,
the spectrum's search, to its 0.01 m/s^2 default).
"""
from __future__ import annotations

import math

__all__ = ["LEAST_RUNS", "model_thresholds", "map_thresholds", "threshold_cost"]

# The fewest runs a robust threshold point costs: the guard 3 % below the model,
# the first bracket's two ends, and the four robustness runs (two per end).  A
# point where the engine disagrees costs more (widening, bisection, isolated
# overturns; with convergence the search again at dt/2, dt/4 and doubled
# iterations), so a budget counted with it is a lower bound.
LEAST_RUNS = 7


def _model_point(args):
    from trilith_xval.analytic.first_overturn import first_overturn_amplitude
    from trilith_xval.analytic.spectrum import SpectrumSettings
    scene, omega, kind, rf = args
    settings = SpectrumSettings(pulse=kind)
    if rf != 1.0:  # the engines' target: the model with the measured restitution
        from trilith_xval.analytic.first_overturn import search_run_settings
        settings = SpectrumSettings(pulse=kind, fast=search_run_settings(restitution_factor=rf))
    a, _, mode, _, _ = first_overturn_amplitude(scene, omega, settings)
    return float(a), mode


def model_thresholds(scene, omegas, kind: str = "sine", workers: int = 1,
                     restitution_factor: float = 1.0):
    """``[(a_reference, mode)]``: the model's first overturning amplitude [m/s^2]
    and mode at each of ``omegas`` (NaN, None when nothing overturns), its impacts
    scaled by ``restitution_factor`` (Eq. 19/20 times it; 1 = exact)."""
    from trilith_xval.compare.measure.engine_spectrum import _map
    return _map(_model_point, [(scene, float(w), kind, float(restitution_factor))
                               for w in omegas], workers)


def map_thresholds(engine: str, scene, omegas, kind: str = "sine", *, workers: int = 1,
                   convergence: bool = False, t_max: float | None = None, reference=None,
                   spec=None):
    """The engine's :class:`EnginePoint` at each of ``omegas`` (frequencies where
    the model does not overturn are skipped).

    ``reference``: the model's ``[(a_reference, mode)]`` on ``omegas`` when already
    computed (:func:`model_thresholds`).  ``t_max`` fixes every run's window with no
    early stop, as in the map's cells.  ``spec``: the engine's run on ``scene``
    (:class:`compare.run.spec.RunSpec`; default: its defaults), resolved again at
    each point's largest pulse.
    """
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.measure.engine_spectrum import engine_points
    from trilith_xval.compare.run.spec import RunSpec
    reference = model_thresholds(scene, omegas, kind, workers) if reference is None else reference
    if spec is None:
        spec = RunSpec.resolve(engine, scene, Still())
    if t_max is not None:  # the map's window, over every other layer
        spec = spec.with_options("--t-max", t_max=t_max, early_stop=False)
    return engine_points(spec, [float(w) for w in omegas],
                         [a for a, _ in reference], [m for _, m in reference],
                         case="pendulum" if scene.has_pendulum else "no_pendulum", kind=kind,
                         workers=workers, convergence=convergence)


def threshold_cost(points) -> dict:
    """Runs and CPU seconds of ``points`` (when computed, reruns included; spent now)."""
    return {"points": len(points), "runs": sum(p.point.n_runs for p in points),
            "cpu_s": math.fsum(p.cpu_s for p in points),
            "cpu_s_spent": math.fsum(p.point.cpu_s_spent for p in points)}
