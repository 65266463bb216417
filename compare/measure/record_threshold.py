"""An engine's first overturning intensity of a ground motion, by the one robust
threshold search.

The model's intensity comes from the window-aware IDA
(:func:`analytic.ida.first_overturn_intensity`).  An engine's is the robust
bracket of :func:`compare.measure.thresholds.engine_threshold` with the motion
scaled to each probed intensity (``motion=``): the same perturbation set as the
pulse spectra (neighbours at ``1 +/- 1e-4`` of the intensity, an initial tilt of
1e-6 rad one step further out), isolated overturns kept apart and never taken as
the threshold.  The bracket is centred on the model's intensity (on ``im_hi``
when the model never overturned up to it) and widened by doubling where the
engine disagrees.

Both backends run the same fixed window, ``t_max = end_time + tail``; every run
goes through the run store.

The result's ``im_overturn`` is the engine's robust overturning end; a record
censored at ``im_hi`` when the engine robustly survives there (no robust
overturn at or below ``im_hi``); ``bracketed`` False when the search found no
robust bracket at all (a collapse above the model, or too many isolated
overturns): such a record is listed, never given an intensity.

Creep and drift over a whole record (``long_run``): the nominal run at the
engine's highest robust survival (``im_safe``, or the highest intensity run when
censored) is rerun over the whole window (no early stop: the model and the
engines alike run to ``end_time + tail``, so the tilt left is a residual, not
the rocking at the instant the verdict became certain), and its diagnostics
(:mod:`engines.diagnostics`) tell what the engine accumulates over the record:
``pivot_sliding_max`` [m] (a pivot creeping along the ground),
``lintel_rotation_max`` [rad] (the lintel drifting off the columns' rigid
motion), ``penetration_max`` [m], and the residual tilt ``|theta|`` at the
window's end [rad] beside the model's at the same intensity.
"""
from __future__ import annotations

import math

__all__ = ["engine_intensity", "record_run", "search_centre", "STEP_TOL"]

# Agreement with the model's intensity that ends the step rule: the threshold
# tolerance of the pulse spectra (2 %).
STEP_TOL = 0.02


def record_run(run, motion, st, top: float):
    """``run`` (a :class:`compare.run.spec.RunSpec` of an engine on its scene) for
    runs under ``motion`` scaled up to intensity ``top``: the friction rule at the
    motion scaled to ``top`` (the largest a search may try), then one more layer,
    the fixed window ``t_max = end_time + st.tail`` of every run of the record."""
    from trilith_xval.analytic.ida import scale_to
    return run.at(excitation=scale_to(motion, st.im, top)).with_options(
        "the record's window", t_max=motion.end_time + st.tail)


def search_centre(st, im_model: float | None) -> float:
    """The intensity the robust search is centred on: the model's, or ``im_hi``
    when the model never overturned up to it."""
    return im_model if im_model is not None and math.isfinite(im_model) else st.im_hi


def engine_intensity(run, motion, st, im_model: float | None) -> dict:
    """The robust first overturning intensity of ``run``'s engine under ``motion``.

    Parameters
    ----------
    run : compare.run.spec.RunSpec
        The engine on its scene, with its settings (e.g. a ``dt``); resolved
        again here for the record (:func:`record_run`, up to the largest
        intensity the search may try, :attr:`~compare.measure.thresholds.Search.widest`
        times its centre).
    motion : SampledRecord or any motion with ``scaled``, ``pga``, ``pgv``
    st : analytic.ida.IDASettings
        The intensity measure, ``im_hi`` (censoring) and ``tail`` (the window).
    im_model : float or None
        The model's first overturning intensity (None: censored at ``im_hi``).

    Returns
    -------
    dict
        ``label``, ``im``, ``im_overturn`` / ``im_safe`` (None when censored or
        not bracketed), ``censored``, ``bracketed``, ``bracket`` (``[survives,
        overturns]`` even above ``im_hi``), ``collapsed`` (intensities whose
        nominal run ended 'collapsed': the frame broke), ``isolated`` (overturns not
        reproduced by their perturbed neighbours), ``flips``, ``n_runs``,
        ``cpu_s`` (CPU seconds of the runs when computed), ``im_reference``,
        ``dt`` (the step of the result) and ``step_rule`` (None, or the rows of
        :func:`compare.measure.step_rule.rule_out_step` when the asked step
        missed the model's intensity by more than :data:`STEP_TOL`: the result is
        then the coarsest finer step's that agrees, or the reference step's).
    """
    from trilith_xval import engines
    from trilith_xval.analytic.ida import scale_to
    from trilith_xval.compare.measure.step_rule import rule_out_step
    from trilith_xval.compare.measure.thresholds import SEARCH, engine_threshold

    centre = search_centre(st, im_model)
    backend, scene = run.backend, run.scene
    settings = record_run(run, motion, st, SEARCH.widest * centre).settings
    scaled = lambda v: scale_to(motion, st.im, v)  # noqa: E731
    p = engine_threshold(backend, scene, math.nan, centre, settings, motion=scaled)
    step = None
    if im_model is not None and math.isfinite(im_model):
        # The step is ruled out first: a coarse step that misses the model's
        # intensity is remeasured finer; the coarsest step that agrees is used.
        check = rule_out_step(backend, scene, math.nan, p, settings, tol=STEP_TOL,
                              motion=scaled)
        if len(check.rows) > 1:
            step = {"dt": settings.dt, "rows": list(check.rows),
                    "agreeing_dt": check.agreeing_dt, "detail": check.detail(STEP_TOL)}
            if check.agreeing_dt is not None:
                settings = engines.configure(backend, settings, dt=check.agreeing_dt)
                p = engine_threshold(backend, scene, math.nan, centre, settings, motion=scaled)
            else:
                p, settings = check.point, check.settings
    over = p.bracketed and p.a_engine <= st.im_hi
    censored = p.bracketed and not over or (not p.bracketed and _survives_all(p, st.im_hi))
    long_run = _long_run(backend, scene, motion, st, settings, p, over)
    return {"label": motion.label, "im": st.im,
            "im_overturn": p.a_engine if over else None,
            "im_safe": p.a_survives if over else None,
            "censored": bool(censored), "bracketed": bool(p.bracketed),
            "bracket": [p.a_survives, p.a_engine] if p.bracketed else None,
            "collapsed": [q.amplitude for q in p.probes
                          if q.status == "collapsed" and not q.perturbation],
            "isolated": list(p.isolated), "flips": [f.to_dict() for f in p.flips],
            "n_runs": p.n_runs, "cpu_s": p.cpu_s, "im_reference": centre,
            "islands": [], "long_run": long_run, "dt": settings.dt, "step_rule": step}


def _long_run(backend, scene, motion, st, settings, p, over: bool) -> dict | None:
    """The diagnostics of the nominal run at the highest robust survival (module
    docstring), beside the model's residual tilt at the same intensity."""
    from trilith_xval import engines
    from trilith_xval.analytic.ida import scale_to
    from trilith_xval.analytic import fast
    from trilith_xval.compare.run import runs

    alive = [q.amplitude for q in p.probes if not q.perturbation and q.status == "survived"
             and (not over or q.amplitude <= p.a_survives)]
    if not alive:
        return None
    value = max(alive)
    scaled = scale_to(motion, st.im, value)
    tr = runs.simulate(backend, scene, scaled, engines.configure(
        backend, settings, verdict_only=False, early_stop=False))
    # The model's residual over the same whole window, compiled (a recorded
    # compiled run with a fixed window always runs on to t_max).
    model = fast.simulate(scene, scaled, fast.Settings(t_max=settings.t_max, sample_dt=0.01))
    d = tr.diagnostics
    sim_s = float(tr.t[-1]) if len(tr.t) else 0.0
    cpu = d.get("cpu_time")
    return {"im_value": value, "status": tr.verdict.status, "t_end": sim_s,
            "pivot_sliding_max": d.get("pivot_sliding_max"),
            "lintel_rotation_max": d.get("lintel_rotation_max"),
            "penetration_max": d.get("penetration_max"),
            "residual_tilt": float(abs(tr.theta[-1])) if len(tr.theta) else None,
            "model_status": model.verdict.status,
            "model_residual_tilt": float(abs(model.theta[-1])) if len(model.theta) else None,
            "cpu_s": cpu, "cpu_per_sim_s": cpu / sim_s if cpu and sim_s > 0 else None}


def _survives_all(p, im_hi: float) -> bool:
    """No bracket, but every nominal run up to ``im_hi`` and beyond survived: the
    engine never overturned in the searched range (censored, as the model's
    records that never overturn)."""
    nominal = [q for q in p.probes if not q.perturbation]
    return bool(nominal) and all(q.status == "survived" for q in nominal) and max(
        q.amplitude for q in nominal) >= im_hi
