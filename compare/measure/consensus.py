"""Where the model cannot speak: the engines checked against each other.

Where the model is invalid at a point (a contact of the paper's mechanism would
have to pull: the lintel lifts, a column hops), there is no reference threshold,
but an engineer still needs an answer.  The engines model those contacts as
contacts, so each engine's own threshold is measured and the engines are
compared with each other, never with the model:

1. **Each engine's own threshold** (:func:`own_threshold`): the first *failure*
   amplitude of the one robust search (:func:`compare.measure.thresholds.engine_threshold`,
   the same bracket, the same perturbations), where a failure is an overturn or a
   collapse (the frame the paper describes broke: the lintel thrown off, columns
   parted; :mod:`engines.monitor`), the kind recorded, since beyond the model's
   validity either ends the structure.  The search starts around the model's
   (invalid) number, its only guess, and widens as everywhere.
2. **Converged in the step**: the search runs at twice the engine's threshold
   step and at that step; two steps whose failing amplitudes agree within
   :data:`STEP_AGREE` (1 %) converge, and the finer one is the engine's answer.
   Otherwise the step is halved, up to :data:`MAX_HALVINGS` times; an engine that
   never converges has no answer (cause ``step``).  Measuring one coarser step
   costs half a search, so a consensus point costs ~1.5x the engine's
   model-bracketed point where the step converges at once.
3. **The consensus** (:func:`consensus`): the median failing amplitude of the
   converged engines, each engine's deviation from it, and the engines beyond
   :data:`OUTLIER_TOL` (2 %, the model-agreement tolerance) named as outliers
   with a measured cause (:func:`outlier_cause`): ``collapse`` (it failed by a
   collapse where the others overturned), ``sliding`` or ``penetration`` (that
   diagnostic beyond its noise level at its failing run), else ``contact
   model``.  Two engines give a consensus without outliers (neither is the odd
   one); one engine gives none.

Every result says what it is: engine against engine, never agreement with the
model.
"""
from __future__ import annotations

import dataclasses
import math
import statistics

from trilith_xval.compare.measure.thresholds import SEARCH, engine_threshold

__all__ = ["STEP_AGREE", "OUTLIER_TOL", "MAX_HALVINGS", "FAILURE_SEARCH", "own_threshold",
           "consensus", "outlier_cause", "consensus_at", "consensus_of",
           "where_model_cannot_judge"]

# Two steps agree when their failing amplitudes differ by at most 1 %: half the
# 2 % tolerance the engines are held to against the model, so a converged answer
# carries at most half the error budget in its step.
STEP_AGREE = 0.01
# An engine further than 2 % from the median of the others is an outlier: the
# same tolerance as agreement with the model.
OUTLIER_TOL = 0.02
# Halvings of the step after the first pair (threshold step and twice it): down
# to a quarter of the threshold step, as the cause search's convergence reruns.
MAX_HALVINGS = 2
# The one search, counting a collapse as a failure and going on through it.
FAILURE_SEARCH = dataclasses.replace(SEARCH, failure=("overturned", "collapsed"),
                                     stop_on_collapse=False)


def _failing_status(point) -> str | None:
    """'overturned' or 'collapsed': the verdict of the search's failing end."""
    if not point.bracketed:
        return None
    nominal = [p for p in point.probes if not p.perturbation and p.amplitude == point.a_engine]
    return nominal[-1].status if nominal else None


def _row(point, dt: float) -> dict:
    return {"dt": dt, "a_fails": point.a_engine if point.bracketed else None,
            "a_survives": point.a_survives if point.bracketed else None,
            "failure": _failing_status(point), "n_runs": point.n_runs,
            "cpu_s": point.cpu_s, "sim_s": point.sim_s}


def own_threshold(spec, omega: float, a_guess: float, kind="sine", *,
                  rel_tol: float = SEARCH.rel_tol, motion=None) -> dict:
    """One engine's own first-failure amplitude at ``omega`` [rad/s], converged in
    the step (module docstring, steps 1-2).

    Parameters
    ----------
    spec : RunSpec
        The engine's run on the scene (its calibrated or reference threshold
        step), resolved at the largest pulse the search may try
        (:func:`compare.measure.engine_spectrum.point_spec`).
    omega : float
        Pulse frequency [rad/s].
    a_guess : float
        Where the search starts [m/s^2]: the model's number (invalid there, the
        only guess); the bracket's resolution is ``rel_tol`` of it.
    kind : str or PulseShape
        The pulse.
    rel_tol : float
        Final bracket width relative to ``a_guess`` (default 0.5 %).
    motion : callable, optional
        ``motion(value) -> excitation``: search the scale of a ground motion
        instead of the pulse's amplitude
        (:func:`compare.measure.thresholds.engine_threshold`); ``omega`` is then a
        label (NaN allowed), ``a_guess`` and the results are intensities.

    Returns
    -------
    dict
        ``engine``, ``omega``, ``converged``, ``a_fails`` / ``a_survives`` [m/s^2]
        (the finest converged step's bracket, None without one), ``failure``
        ('overturned' or 'collapsed'), ``dt`` (that step), ``steps`` (one row
        per step measured, coarse to fine), ``cpu_s``, ``cause`` (None, or
        'step' / 'no failure' when there is no answer) and ``detail``.
    """
    search = FAILURE_SEARCH.with_rel_tol(rel_tol)
    base = spec.settings.dt
    ladder = [2.0 * base, base] + [base / 2 ** k for k in range(1, MAX_HALVINGS + 1)]
    rows, points, centre = [], [], a_guess
    for i, dt in enumerate(ladder):
        run = spec.with_options("the consensus's step", dt=dt)
        p = engine_threshold(spec.backend, spec.scene, omega, centre, run.settings, kind=kind,
                             search=search, motion=motion)
        rows.append(_row(p, dt))
        points.append(p)
        if p.bracketed:
            centre = p.a_engine  # the next step searches around its coarser neighbour
        if i == 0:
            continue
        a, b = rows[-2]["a_fails"], rows[-1]["a_fails"]
        if a is not None and b is not None and abs(a - b) <= STEP_AGREE * b:
            out = rows[-1]
            return {"engine": spec.backend, "omega": omega, "converged": True,
                    "a_fails": out["a_fails"], "a_survives": out["a_survives"],
                    "failure": out["failure"], "dt": dt, "steps": rows,
                    "cpu_s": _sum(r["cpu_s"] for r in rows), "cause": None,
                    "detail": f"dt = {dt:.3g} s and {rows[-2]['dt']:.3g} s agree within "
                              f"{100 * abs(a - b) / b:.2g} %"}
    bracketed = [r for r in rows if r["a_fails"] is not None]
    cause = "step" if bracketed else "no failure"
    detail = ("no two successive steps agree within "
              f"{100 * STEP_AGREE:g} % down to dt = {ladder[-1]:.3g} s" if bracketed
              else f"no failure bracketed at any step down to dt = {ladder[-1]:.3g} s")
    return {"engine": spec.backend, "omega": omega, "converged": False, "a_fails": None,
            "a_survives": None, "failure": None, "dt": None, "steps": rows,
            "cpu_s": _sum(r["cpu_s"] for r in rows), "cause": cause, "detail": detail}


def _sum(values) -> float:
    values = list(values)
    return math.fsum(values) if all(v is not None and math.isfinite(v) for v in values) \
        else math.nan


def consensus(owns: dict, causes: dict | None = None) -> dict:
    """The engines' consensus at one point (module docstring, step 3).

    ``owns``: engine -> :func:`own_threshold` result; ``causes``: engine -> the
    measured cause of an outlier (:func:`outlier_cause`), asked for only the
    outliers.  Returns ``status`` ('consensus', 'disagree' for two engines
    beyond :data:`OUTLIER_TOL` of each other, 'one engine', 'none'), ``median``
    [m/s^2], ``engines`` (converged, each with its deviation), ``outliers``
    (engine, deviation, cause) and ``no_answer`` (engine, cause, detail).
    """
    ok = {e: o for e, o in owns.items() if o["converged"]}
    no_answer = [{"engine": e, "cause": o["cause"], "detail": o["detail"]}
                 for e, o in owns.items() if not o["converged"]]
    if not ok:
        return {"status": "none", "median": None, "engines": {}, "outliers": [],
                "no_answer": no_answer, "failure": None}
    median = statistics.median(o["a_fails"] for o in ok.values())
    deviation = {e: (o["a_fails"] - median) / median for e, o in ok.items()}
    kinds = [o["failure"] for o in ok.values()]
    failure = max(set(kinds), key=kinds.count)
    status = "consensus" if len(ok) >= 2 else "one engine"
    outliers = []
    if len(ok) == 2 and max(abs(d) for d in deviation.values()) > OUTLIER_TOL:
        status = "disagree"  # two engines apart: neither is the odd one out
    elif len(ok) >= 3:
        for e, d in deviation.items():
            if abs(d) > OUTLIER_TOL:
                outliers.append({"engine": e, "deviation": d,
                                 "cause": (causes or {}).get(e, "unknown")})
    return {"status": status, "median": median, "failure": failure,
            "engines": {e: {"a_fails": ok[e]["a_fails"], "deviation": deviation[e],
                            "failure": ok[e]["failure"], "dt": ok[e]["dt"]} for e in ok},
            "outliers": outliers, "no_answer": no_answer}


# The diagnostics an outlier's cause is read from, with their noise levels
# (compare.measure.causes): the largest ratio names the cause.
_CAUSE_OF = {"pivot_sliding_max": "sliding", "penetration_max": "penetration"}


def outlier_cause(spec, omega: float, own: dict, failure: str, kind="sine",
                  motion=None) -> str:
    """Why an engine's converged answer lies off the others': ``collapse`` when it
    failed by another verdict than the majority's ``failure``; else the
    diagnostic farthest beyond its noise level at its failing run at its own
    step (``sliding``, ``penetration``) when beyond it; else ``contact model``
    (the contact law itself, the remaining explanation once the step converged).
    ``motion``: as :func:`own_threshold`'s."""
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.compare.measure.causes import _NOISE
    from trilith_xval.compare.run import runs
    if own["failure"] != failure:
        return "collapse" if own["failure"] == "collapsed" else "overturn"
    run = spec.with_options("the consensus's step", dt=own["dt"], verdict_only=True)
    ground = pulse_of(kind, own["a_fails"], omega) if motion is None else motion(own["a_fails"])
    tr = runs.simulate(spec.backend, spec.scene, ground, run.settings)
    ratios = {k: (tr.diagnostics.get(k) or 0.0) / _NOISE[k] for k in _CAUSE_OF}
    key = max(ratios, key=ratios.get)
    return _CAUSE_OF[key] if ratios[key] > 1.0 else "contact model"


def consensus_at(runs: dict, scene, omega: float, a_guess: float, kind="sine", *,
                 rel_tol: float = SEARCH.rel_tol) -> dict:
    """The engines' consensus at one point of ``scene`` (module docstring).

    ``runs``: engine -> its threshold-search :class:`~compare.run.spec.RunSpec`
    (a template: resolved here at the point's largest pulse); ``a_guess`` the
    model's number there [m/s^2].  Returns :func:`consensus`'s dict with
    ``omega``, ``a_model`` and ``own`` (each engine's :func:`own_threshold`)."""
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    search = FAILURE_SEARCH.with_rel_tol(rel_tol)
    specs = {e: point_spec(r, scene, omega, a_guess, kind, search) for e, r in runs.items()}
    return {"omega": omega, "a_model": a_guess,
            **consensus_of(specs, omega, a_guess, kind, rel_tol=rel_tol)}


def consensus_of(specs: dict, omega: float, a_guess: float, kind="sine", *,
                 rel_tol: float = SEARCH.rel_tol, motion=None) -> dict:
    """:func:`consensus` of the engines' own thresholds (:func:`own_threshold`),
    the outliers' causes measured (:func:`outlier_cause`); ``specs``: engine ->
    its run resolved for the search (``motion`` as :func:`own_threshold`'s).
    Returns :func:`consensus`'s dict with ``own``."""
    owns = {e: own_threshold(s, omega, a_guess, kind, rel_tol=rel_tol, motion=motion)
            for e, s in specs.items()}
    first = consensus(owns)
    causes = {o["engine"]: outlier_cause(specs[o["engine"]], omega, owns[o["engine"]],
                                         first["failure"], kind, motion)
              for o in first["outliers"]}
    return {**consensus(owns, causes), "own": owns}


def where_model_cannot_judge(curves) -> list[tuple[str, float, float]]:
    """``(curve, omega, a_model)`` of every engine point
    (:class:`~compare.measure.engine_spectrum.EnginePoint`) of ``curves`` (pairs
    ``(curve name, points)``, any number per curve: one per engine) where the
    point found the model invalid (cause ``model``), once each, in order."""
    seen: dict = {}
    for curve, points in curves:
        for p in points:
            if p.cause == "model":
                seen.setdefault((curve, float(p.omega)), float(p.a_reference))
    return [(c, w, a) for (c, w), a in seen.items()]
