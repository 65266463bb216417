"""A threshold point on a scene the model does not cover (:mod:`analytic.kinds`):
the engines' consensus started from a scan instead of the model's number.

There is no model number to bisect around, so each frequency is answered by the
engines alone (:mod:`compare.measure.consensus`): each engine's own first-failure
amplitude (an overturn or a collapse, :mod:`engines.structure_monitor`),
converged in the step, and their consensus.  The consensus search starts from a
guess; without a model the guess is a scan: the first engine's verdicts at
amplitudes growing by :data:`SCAN_FACTOR` from the structure's static uplift
bound ``g w_min / (2 H)`` (:func:`uplift_bound`), the geometric mean of the last
survival and the first failure (:func:`scan_guess`); a ground motion's the same,
scaled to each intensity (:func:`kind_record`).  Used by ``trilith spectrum
--consensus`` and ``trilith trust`` on such a scene.
"""
from __future__ import annotations

import math

__all__ = ["uplift_bound", "scan", "scan_guess", "kind_point", "kind_record", "SCAN_FACTOR",
           "SCAN_STEPS", "FAILED"]

# Amplitude ratio of two scan probes: the threshold search then widens its bracket
# up to +-115 % around the guess (compare.measure.thresholds.Search.max_expand), so a
# scan bracket of 1.5 is well inside what it can reach.
SCAN_FACTOR = 1.5
# Probes of the scan: 1.5^14 ~ 290 times the uplift bound, past any one-sine
# threshold of a standing structure (Fig. 5's highest is ~40 times g/lam).
SCAN_STEPS = 14
FAILED = ("overturned", "collapsed")  # a failure of the structure (engines.structure_monitor)


def uplift_bound(scene) -> float:
    """``g w_min / (2 H)`` [m/s^2], ``w_min`` the narrowest body's width and ``H`` the
    structure's height: below the static uplift of any rigid part of it (about any
    corner its lever to its centre of mass is at least ``w_min / 2`` for centred
    bodies, the centre at most ``H`` above the pivot), so the scan starts below
    the first failure."""
    rects = scene.layout()
    top = max(r.top for r in rects)
    return 0.5 * scene.g * min(r.b for r in rects) / top


def scan(fails, start: float, top: float = math.inf) -> tuple[float | None, int]:
    """Where a search without a model starts: ``(guess or None, runs)``.

    ``fails(value) -> bool`` is probed at ``start`` times :data:`SCAN_FACTOR` to the
    ``k``, ``k < SCAN_STEPS``, the last probe clipped to ``top`` (a search's upper
    end: beyond it the answer is censored); the guess is the geometric mean of the
    last survival and the first failure (``start / SCAN_FACTOR`` standing for the
    survival when ``start`` already fails); None when nothing failed."""
    a, survived = start, None
    for k in range(SCAN_STEPS):
        a = min(a, top)
        if fails(a):
            low = survived if survived is not None else a / SCAN_FACTOR
            return math.sqrt(low * a), k + 1
        if a >= top:
            return None, k + 1
        survived = a
        a *= SCAN_FACTOR
    return None, SCAN_STEPS


def scan_guess(spec, omega: float, kind) -> tuple[float | None, int]:
    """``(guess [m/s^2] or None, runs)``: the geometric mean of the last surviving and
    the first failing amplitude of the scan (module docstring) on ``spec``'s engine."""
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.thresholds import overturns

    def fails(a):
        run = point_spec(spec, spec.scene, omega, a, kind)
        return overturns(run.backend, run.scene, omega, a, run.settings,
                         kind).status in FAILED
    return scan(fails, uplift_bound(spec.scene))


def _none(scene, engines, **where) -> dict:
    """The point where the scan found no failure: no engine has an answer."""
    top = uplift_bound(scene) * SCAN_FACTOR ** (SCAN_STEPS - 1)
    return {**where, "status": "none", "median": None, "failure": None, "a_guess": None,
            "engines": {}, "outliers": [], "own": {}, "no_answer": [
                {"engine": e, "cause": "no failure",
                 "detail": f"no failure up to the scan's end, {top:.4g} m/s^2"} for e in engines]}


def kind_point(runs: dict, scene, omega: float, kind="sine") -> tuple[dict, int]:
    """``(point, scan runs)``: the engines' consensus at ``omega`` [rad/s] on
    ``scene`` (:func:`compare.measure.consensus.consensus_at`) started from the
    first engine's scan (:func:`scan_guess`); ``runs`` maps engine -> its
    threshold-search :class:`~compare.run.spec.RunSpec`.  The point's ``a_guess``
    is the scan's guess (there is no model number); when the scan finds no
    failure every engine has no answer (cause 'no failure')."""
    from trilith_xval.compare.measure.consensus import consensus_at
    guess, n = scan_guess(next(iter(runs.values())), float(omega), kind)
    if guess is None:
        return _none(scene, runs, omega=float(omega)), n
    point = consensus_at(runs, scene, float(omega), guess, kind)
    point["a_guess"] = point.pop("a_model")  # a scan's guess, not a model's number
    return point, n


def kind_record(runs: dict, scene, motion, st) -> tuple[dict, int]:
    """``(point, scan runs)``: the engines' consensus on the first failing intensity
    ``st.im`` (PGA by default, m/s^2) of the ground motion ``motion`` on ``scene``:
    each engine's own, converged in the step
    (:func:`compare.measure.consensus.consensus_of`), every run over the record's
    fixed window ``end_time + st.tail``
    (:func:`compare.measure.record_threshold.record_run`), started from the first
    engine's scan of the record's intensity (module docstring) as :func:`kind_point`."""
    from trilith_xval.analytic.ida import scale_to
    from trilith_xval.compare.measure.consensus import FAILURE_SEARCH, consensus_of
    from trilith_xval.compare.measure.record_threshold import record_run
    from trilith_xval.compare.measure.thresholds import overturns_under
    first = next(iter(runs.values()))

    def scaled(value):
        return scale_to(motion, st.im, value)

    def fails(a):
        run = record_run(first, motion, st, a)
        return overturns_under(run.backend, run.scene, scaled(a), run.settings,
                               a).status in FAILED
    guess, n = scan(fails, uplift_bound(scene))
    where = {"record": motion.label, "im": st.im}
    if guess is None:
        return _none(scene, runs, **where), n
    specs = {e: record_run(r, motion, st, FAILURE_SEARCH.widest * guess)
             for e, r in runs.items()}
    return {**where, "a_guess": guess,
            **consensus_of(specs, math.nan, guess, motion=scaled)}, n
