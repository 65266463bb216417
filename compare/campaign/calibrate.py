"""The cheapest settings of an engine that agree with the model (``trilith calibrate``).

An engine's accuracy and its cost both follow from a few numerical settings: the
step ``dt`` above all, then the engine's own (solver iterations, contact
parameters).  What a step must be depends on what is measured: overturning
thresholds tolerate much coarser steps than impact restitution.  So the search is
per engine and per *metric*, on a stated validation set:

``restitution``
    free rocking from ``alpha/2``: the worst relative error of the first impacts'
    velocity ratios against Eq. 20 (no pendulum) and Eq. 19 (with it), over
    slenderness ``lam`` and lintel mass ratio ``mu``
    (:func:`compare.measure.restitution.free_rocking`).
``thresholds``
    the first-overturning amplitude under one-sine pulses (Eq. 22) at a few
    frequencies, both curves: the worst relative error against the analytic
    threshold, through the one engine threshold search
    (:func:`compare.measure.engine_spectrum.engine_spectrum`).  Points where the
    model itself is invalid (cause ``model``) are not counted against the engine.
``histories``
    theta(t) before the first impact at the paper's points A-D (both curves): the
    worst RMS error in units of ``alpha``, and a verdict that differs counts as an
    error of 1 (:func:`compare.measure.trajectories.compare_trajectories`).

Every candidate (the product of the values in the search space) is evaluated on
the whole set with the store bypassed, so that every cost is what the runs cost on
the machine that ran them.  Each finished scene of a candidate, and then the
finished candidate, is kept in the run store (when one is active): a killed
calibration resumes at the next scene, and a served candidate (``from_store``) keeps
the costs measured when its scenes ran.  Two
costs are kept: the engine's own (``engine_cpu_s``, the CPU seconds each engine
run measured inside its stepping loop, summed: what a user of these settings
pays) and the whole evaluation's (``cpu_s``: this process and the
workers it reaped, including the model's reference runs and the measurement).  The
result is the Pareto front of engine cost against worst error and the cheapest
candidate within the tolerance.

On a scene of another kind (drums, unequal columns, a block on a block) there is
no model: the thresholds metric measures each candidate against the engine's own
thresholds at a reference step (self-convergence,
:mod:`compare.campaign.calibrate_kinds`); the other metrics are refused.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
import os
from dataclasses import dataclass, field

from trilith_xval.analytic._workers import cpu_seconds
from trilith_xval.compare.campaign.calibrate_metrics import histories as _histories
from trilith_xval.compare.campaign.calibrate_metrics import restitution as _restitution
from trilith_xval.compare.campaign.calibrate_metrics import thresholds as _thresholds
from trilith_xval.compare.run.spec import RunSpec

__all__ = ["METRICS", "ValidationSet", "Evaluation", "Calibration", "calibrate",
           "default_space", "default_tolerance", "pareto_front"]

METRICS = ("restitution", "thresholds", "histories")
# Multiples of an engine's calibrated step tried by default: thresholds were seen
# to tolerate 10x (Pymunk's Fig. 5 spectrum at 1e-3 s kept 53 of 56 thresholds).
DT_FACTORS = (1.0, 2.0, 5.0, 10.0)
# Every candidate costs a whole validation set: a search is refused above this.
MAX_CANDIDATES = 64


@dataclass(frozen=True)
class ValidationSet:
    """What a candidate must reproduce.

    Parameters
    ----------
    scene : str or tuple of str
        Scene name or file (default ``fig5``, the paper's Fig. 5 trilith), or a
        tuple of them: the worst error is then over every scene's cases.
    releases : tuple of (lam, mu)
        Free-rocking cases for ``restitution`` (default lam 3 and 7 x mu 0.5 and
        2: the corners of the paper's range, where engines differ most), each
        without the pendulum, plus the scene itself with its pendulum (Eq. 19).
    n_impacts : int
        Impacts measured per release (default 3).
    omegas : tuple of float
        Pulse frequencies [rad/s] for ``thresholds`` (default 6, 12, 18: the
        rising, middle and upper part of the Fig. 5 curves, away from its jumps);
        empty: each scene's own band (:func:`compare.campaign.design.scene_omegas`).
    points : tuple of str
        The paper's points for ``histories`` (default A-D).
    """

    scene: str | tuple = "fig5"
    releases: tuple = ((3.0, 0.5), (3.0, 2.0), (7.0, 0.5), (7.0, 2.0))
    n_impacts: int = 3
    omegas: tuple = (6.0, 12.0, 18.0)
    points: tuple = ("A", "B", "C", "D")

    @property
    def scene_label(self) -> str:
        """The validation scenes as one short text (for titles)."""
        names = [self.scene] if isinstance(self.scene, str) else list(self.scene)
        return ", ".join(names) if len(names) <= 3 else f"{len(names)} scenes ({names[0]}, ...)"

    def describe(self) -> dict:
        return {"scene": self.scene if isinstance(self.scene, str) else list(self.scene),
                "releases": [list(r) for r in self.releases],
                "n_impacts": self.n_impacts, "omegas": list(self.omegas),
                "points": list(self.points)}


@dataclass(frozen=True)
class Evaluation:
    """One candidate on the whole validation set."""

    options: dict
    worst_error: float
    errors: tuple  # (case label, error) pairs; nan where the engine gave no answer
    engine_cpu_s: float  # the engine runs' own CPU, measured inside each run
    cpu_s: float  # the whole evaluation, reference runs and measurement included
    simulated_s: float  # simulated seconds of every engine run of the evaluation
    runs: int
    # Served by the run store, whole or scene by scene: its costs are those measured then.
    from_store: bool = False

    @property
    def real_time_factor(self) -> float:
        """Engine CPU seconds per simulated second (nan when not measured)."""
        return self.engine_cpu_s / self.simulated_s if self.simulated_s > 0 else math.nan

    def to_dict(self) -> dict:
        return {"options": dict(self.options), "worst_error": self.worst_error,
                "errors": [list(e) for e in self.errors], "engine_cpu_s": self.engine_cpu_s,
                "cpu_s": self.cpu_s,
                "simulated_s": self.simulated_s, "real_time_factor": self.real_time_factor,
                "runs": self.runs, "from_store": self.from_store}


@dataclass
class Calibration:
    """All candidates of one engine and metric, their front and the recommendation."""

    engine: str
    version: str
    metric: str
    tolerance: float
    validation: ValidationSet
    evaluations: list = field(default_factory=list)
    load_average: tuple = ()
    base: dict = field(default_factory=dict)  # settings every candidate starts from
    kind: str = "trilith"  # another kind: errors are against the engine's own reference
    self_reference: dict = field(default_factory=dict)  # dt_ref, thresholds (other kinds)

    @property
    def front(self) -> list:
        return pareto_front(self.evaluations)

    @property
    def recommended(self) -> Evaluation | None:
        """The cheapest candidate whose worst error is within the tolerance."""
        ok = [e for e in self.evaluations if e.worst_error <= self.tolerance]
        return min(ok, key=lambda e: e.engine_cpu_s) if ok else None

    def to_dict(self) -> dict:
        rec = self.recommended
        return {"engine": self.engine, "version": self.version, "metric": self.metric,
                "tolerance": self.tolerance, "validation": self.validation.describe(),
                "base": dict(self.base),
                "load_average": list(self.load_average),
                "recommended": rec.to_dict() if rec else None,
                "front": [e.to_dict() for e in self.front],
                "evaluations": [e.to_dict() for e in self.evaluations],
                **({} if self.kind == "trilith" else
                   {"kind": self.kind, "model": None, "self_reference": self.self_reference})}


def default_tolerance(metric: str) -> float:
    """The validation campaign's tolerance for ``metric`` (one source for both)."""
    from trilith_xval.compare.campaign.config import Tolerances
    t = Tolerances()
    return {"restitution": t.restitution, "thresholds": t.threshold,
            "histories": t.theta_rms_first}[metric]


def pareto_front(evaluations) -> list:
    """Candidates no other beats in both engine cost and worst error, cheapest first."""
    pts = sorted(evaluations, key=lambda e: (e.engine_cpu_s, e.worst_error))
    front, best = [], math.inf
    for e in pts:
        if e.worst_error < best:
            front.append(e)
            best = e.worst_error
    return front


def default_space(engine: str, step_only: bool = False, base: dict | None = None) -> dict:
    """``{'dt': [...], ...}``: the engine's calibrated step (or ``base``'s) times
    :data:`DT_FACTORS`, plus (unless ``step_only``) the engine's own declared
    search ranges (``calibration_space`` on its class: each includes the
    calibrated default)."""
    from trilith_xval import engines
    base = engines.configure(engine, **(base or {}))
    space = {"dt": [base.dt * f for f in DT_FACTORS]}
    if not step_only:
        space.update({name: list(values) for name, values in
                      (getattr(engines.get_backend(engine), "calibration_space", {}) or {}).items()})
    return space


def _candidates(space: dict) -> list[dict]:
    names = list(space)
    return [dict(zip(names, values)) for values in itertools.product(*(space[n] for n in names))]


# ------------------------------------------------------------------ the candidates
def _candidate_run(engine: str, scene, base: dict, varied: dict) -> RunSpec:
    """One candidate's run of ``engine`` on ``scene`` (no base motion): the
    engine's defaults, ``base`` (e.g. a settings file's table), then the
    candidate's own values; each metric resolves it again on its scenes and
    excitations (:meth:`RunSpec.at`)."""
    from trilith_xval.analytic.excitation import Still
    return RunSpec.resolve(engine, scene, Still(), overrides={**base, **varied},
                           overrides_from="the candidate settings")


def calibrate(engine: str, metric: str = "thresholds", *, validation: ValidationSet | None = None,
              space: dict | None = None, tolerance: float | None = None, workers: int = 1,
              progress=None, scene=None, base: dict | None = None,
              restitution_factor: float = 1.0, reference_dt: float | None = None
              ) -> Calibration:
    """Evaluate every candidate of ``space`` on ``validation`` for ``metric``.

    Parameters
    ----------
    engine : str
        A registered engine.
    metric : {'restitution', 'thresholds', 'histories'}
    validation : ValidationSet, optional
        Default :class:`ValidationSet()`.
    space : dict, optional
        Setting name -> values to try (every combination is evaluated); default
        :func:`default_space`.  Values are checked by the engine's ``Settings``
        before any run.
    tolerance : float, optional
        Largest acceptable worst error, in (0, 1]; default the validation
        campaign's own (:class:`compare.campaign.config.Tolerances`): 0.5 %
        for restitution, 2 % for thresholds, 1e-3 alpha for histories.
    workers : int
        Processes for the threshold search.
    progress : callable, optional
        ``progress(done, total, evaluation)`` after each candidate.
    scene : Scene or sequence of Scene, optional
        The scenes themselves (e.g. with overrides); default each of
        ``validation.scene`` loaded.  With several, each error is labelled with
        its scene's name and the worst is over all.
    base : dict, optional
        Settings every candidate starts from (e.g. a settings file's table for
        ``engine``); a candidate's own values replace them.  Default: none (the
        engine's calibrated defaults).
    restitution_factor : float
        In (0, 1]: the model every candidate is measured against has its impact
        ratio (Eq. 19/20) times this factor (a measured restitution); 1 (default)
        is the exact impact.  The restitution metric's target is then ``r`` x
        Eq. 19/20, the thresholds' the scaled model's spectrum, the histories'
        the scaled model's run.
    reference_dt : float, optional
        On scenes of another kind only: the step [s] of the engine's own
        reference thresholds (default the engine's reference step).

    Returns
    -------
    Calibration
    """
    from trilith_xval import engines
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict
    from trilith_xval.scenes import load_scene
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    if tolerance is None:
        tolerance = default_tolerance(metric)
    if isinstance(tolerance, bool) or not (isinstance(tolerance, (int, float))
                                            and 0.0 < tolerance <= 1.0):
        raise ValueError(f"tolerance must be in (0, 1], got {tolerance!r}")
    from trilith_xval.analytic.options import check_restitution_factor
    rf = check_restitution_factor("calibrate", restitution_factor)
    vs = validation or ValidationSet()
    names = (vs.scene,) if isinstance(vs.scene, str) else tuple(vs.scene)
    if scene is None:
        scenes = [load_scene(n) for n in names]
    else:
        scenes = list(scene) if isinstance(scene, (list, tuple)) else [scene]
    if not scenes:
        raise ValueError("scene: give at least one validation scene")
    from trilith_xval.compare.campaign.calibrate_kinds import scene_kind
    kind = scene_kind(scenes)
    if kind != "trilith" and (metric != "thresholds" or rf != 1.0):
        raise ValueError(f"metric {metric!r}{'' if rf == 1.0 else ', restitution_factor'}: "
                         f"there is no model of the {kind} kind (no Eq. 19/20, no model "
                         "theta); only 'thresholds', against the engine's own reference step")
    base = dict(base or {})
    space = default_space(engine, base=base) if space is None else dict(space)
    candidates = _candidates(space)
    for cand in candidates:  # every value checked before any run
        engines.configure(engine, **{**base, **cand})
    cal = Calibration(engine, engines.get_backend(engine).version(), metric, float(tolerance), vs,
                      load_average=os.getloadavg(), base=base)
    reference: dict = {}  # the model's spectra, once, only if a candidate needs them
    if kind != "trilith":  # the engine's own thresholds at its reference step, first
        from trilith_xval.compare.campaign.calibrate_kinds import kind_reference
        cal.kind, cal.self_reference = kind, kind_reference(
            [(sc, _candidate_run(engine, sc, base, {})) for sc in scenes], vs.omegas,
            reference_dt, reference)

    def one_scene(sc, varied: dict):
        run = _candidate_run(engine, sc, base, varied)
        if metric == "restitution":
            return _restitution(run, vs, rf)
        if kind != "trilith":
            from trilith_xval.compare.campaign.calibrate_kinds import self_thresholds
            return self_thresholds(run, reference[id(sc)])
        if metric == "thresholds":
            if id(sc) not in reference:
                from trilith_xval.analytic.spectrum import overturning_spectrum

                from trilith_xval.compare.campaign.design import scene_omegas
                model = {}
                if rf != 1.0:  # the target: the model with the measured restitution
                    from trilith_xval.analytic.spectrum import (SpectrumSettings,
                                                                search_run_settings)
                    model = {"settings": SpectrumSettings(
                        fast=search_run_settings(restitution_factor=rf))}
                reference[id(sc)] = overturning_spectrum(
                    sc, list(vs.omegas) if vs.omegas else scene_omegas(sc), **model)
            return _thresholds(run, reference[id(sc)], workers)
        return _histories(run, vs, rf)

    def scene_part(sc, cand: dict, description: dict):
        # One scene of one candidate, kept in the run store as soon as it is done
        # (keyed by that scene alone): a calibration killed mid-candidate (one
        # candidate over a design's scenes can take CPU hours) resumes at the next.
        # Measured with the store bypassed: its costs are what its runs cost then.
        key = {**description, "scenes": [scene_dict(sc)], "part": "scene",
               "validation": {**description["validation"], "scene": sc.name}}
        stored = runs.lookup("calibration-scene", key, code=runs.ALL_CODE)
        if stored is not None:
            return stored, True

        def measure():
            with runs.using(None):
                cpu0 = cpu_seconds()
                e, c, t, k = one_scene(sc, cand)
                return (tuple(tuple(x) for x in e), c, t, k, cpu_seconds() - cpu0)
        return runs.memo("calibration-scene", key, measure,
                         label=f"calibrate {engine} {metric} {sc.name}",
                         code=runs.ALL_CODE), False

    def evaluate(cand: dict, description: dict) -> Evaluation:
        errors, engine_cpu, simulated, n, cpu, served = [], 0.0, 0.0, 0, 0.0, False
        for sc in scenes:
            (e, c, t, k, s), hit = scene_part(sc, cand, description)
            errors += [(f"{sc.name}: {label}" if len(scenes) > 1 else label, err)
                       for label, err in e]
            engine_cpu, simulated, n, cpu = engine_cpu + c, simulated + t, n + k, cpu + s
            served = served or hit
        values = [e for _, e in errors]
        worst = max(values) if values and all(math.isfinite(v) for v in values) \
            else math.inf
        return Evaluation(dict(cand), worst, tuple(errors), engine_cpu, cpu, simulated, n,
                          from_store=served)

    for i, cand in enumerate(candidates):
        # A finished candidate is kept whole in the run store (its scenes, as they
        # finish, by scene_part); a served one keeps the costs measured when it ran.
        description = _candidate_description(engine, metric, vs, scenes, {**base, **cand})
        if rf != 1.0:  # absent at 1: candidates stored before the factor keep their keys
            description["restitution_factor"] = rf
        if kind != "trilith":  # the target is the engine's own, at this step
            description["reference_dt"] = cal.self_reference["dt_ref"]
        ev = runs.lookup("calibration-candidate", description, code=runs.ALL_CODE)
        if ev is not None:
            ev = dataclasses.replace(ev, from_store=True)
        else:
            ev = runs.memo("calibration-candidate", description,
                           lambda: evaluate(cand, description),
                           label=f"calibrate {engine} {metric}", code=runs.ALL_CODE)
        cal.evaluations.append(ev)
        if progress is not None:
            progress(i + 1, len(candidates), ev)
    return cal


def _candidate_description(engine: str, metric: str, vs: ValidationSet, scenes,
                           cand: dict) -> dict:
    """Everything that determines one candidate's evaluation (its store key)."""
    from trilith_xval.compare.run.keys import backend_version, scene_dict
    return {"engine": engine, "version": backend_version(engine), "metric": metric,
            "validation": dataclasses.asdict(vs), "scenes": [scene_dict(sc) for sc in scenes],
            "candidate": dict(sorted(cand.items()))}
