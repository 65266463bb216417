"""An engine's own first failing intensity of a ground motion on a scene the model
does not cover (:mod:`analytic.kinds`: drums, unequal columns, a block on a block):
the record counterpart of :func:`compare.measure.consensus.own_threshold`.

There is no model IDA to centre the bracket on, so

1. **a scan** (:func:`compare.measure.kind_scan.scan`) of the engine's own
   verdicts (a failure: an overturn or a collapse, :mod:`engines.structure_monitor`)
   at intensities growing by 1.5 from the structure's static uplift bound
   ``g w_min / (2 H)`` (:func:`compare.measure.kind_scan.uplift_bound`, a PGA,
   expressed in the intensity measure), up to ``im_hi``: a record whose scan
   survives ``im_hi`` is censored there, as the model's IDA censors;
2. **the robust bracket** around the scan's guess, the one search of the pulse
   and record thresholds (:func:`compare.measure.thresholds.engine_threshold`,
   the same perturbations, isolated failures kept apart), **converged in the
   step** as the consensus converges it (:func:`compare.measure.consensus.own_threshold`:
   twice the engine's step and that step, halved until two agree within 1 %).

Every run lasts the record plus ``st.tail`` (the fixed window of the IDA) and goes
through the run store.  The result is the engine's alone: engine against engine,
never agreement with the model.
"""
from __future__ import annotations

import math

__all__ = ["own_intensity"]


def own_intensity(run, motion, st) -> dict:
    """``run``'s engine's own first failing intensity of ``motion`` (module docstring).

    Parameters
    ----------
    run : compare.run.spec.RunSpec
        The engine on a scene of another kind, with its settings (its step ``dt``
        is the finer of the first pair the step convergence compares).
    motion : SampledRecord
    st : analytic.ida.IDASettings
        The intensity measure, ``im_hi`` (censoring) and ``tail`` (the window).

    Returns
    -------
    dict
        The keys of :func:`compare.measure.record_threshold.engine_intensity`'s
        result that the fragility summary reads (``label``, ``im``,
        ``im_overturn`` (the first *failing* intensity, an overturn or a
        collapse), ``im_safe``, ``censored``, ``bracketed`` (False: no answer,
        listed and left out of the fit), ``bracket``, ``islands`` (empty: the
        scan does not look above the first failure), ``n_runs``, ``cpu_s``,
        ``dt``) and ``failure`` ('overturned' or 'collapsed'), ``converged``,
        ``cause`` / ``detail`` (why there is no answer), ``steps`` (one row per
        step measured) and ``scan`` (``start``, ``guess``, ``runs``).
    """
    from trilith_xval.analytic.ida import intensity_of, scale_to
    from trilith_xval.compare.measure.consensus import own_threshold
    from trilith_xval.compare.measure.kind_scan import scan, uplift_bound
    from trilith_xval.compare.measure.record_threshold import record_run
    from trilith_xval.compare.measure.thresholds import SEARCH
    from trilith_xval.compare.run import runs

    # One resolution for the scan and the search: the friction rule at the
    # largest intensity the search may try around the highest scan probe.
    spec = record_run(run, motion, st, SEARCH.widest * st.im_hi)
    scaled = lambda v: scale_to(motion, st.im, v)  # noqa: E731
    start = uplift_bound(run.scene) / motion.pga * intensity_of(motion, st.im)

    def fails(value: float) -> bool:
        tr = runs.simulate(spec.backend, spec.scene, scaled(value), spec.settings)
        return tr.verdict.status in ("overturned", "collapsed")
    guess, n_scan = scan(fails, start, top=st.im_hi)
    row = {"label": motion.label, "im": st.im, "im_overturn": None, "im_safe": None,
           "islands": [], "isolated": [], "collapsed": [],
           "scan": {"start": start, "guess": guess, "runs": n_scan}}
    if guess is None:
        return {**row, "censored": True, "bracketed": True, "bracket": None,
                "failure": None, "converged": True, "cause": None,
                "detail": f"censored: no failure in the scan up to {st.im_hi:g}", "steps": [],
                "n_runs": n_scan, "cpu_s": None, "dt": spec.settings.dt}
    own = own_threshold(spec, math.nan, guess, motion=scaled)
    n_runs = n_scan + sum(r["n_runs"] for r in own["steps"])
    out = {**row, "failure": own["failure"], "converged": own["converged"],
           "cause": own["cause"], "detail": own["detail"], "steps": own["steps"],
           "n_runs": n_runs, "cpu_s": own["cpu_s"], "dt": own["dt"]}
    if not own["converged"]:
        return {**out, "censored": False, "bracketed": False, "bracket": None}
    over = own["a_fails"] <= st.im_hi
    return {**out, "censored": not over, "bracketed": True,
            "bracket": [own["a_survives"], own["a_fails"]],
            "im_overturn": own["a_fails"] if over else None,
            "im_safe": own["a_survives"] if over else None}
