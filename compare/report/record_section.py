"""The record section of ``trilith report --record FILE|DIR``: per record and
engine, the first overturning intensity against the model's, with its cause.

The model's intensity is the window-aware IDA (:mod:`analytic.ida`), each
engine's the robust bracket around it (:mod:`compare.measure.record_threshold`),
both the stored jobs of ``trilith fragility``.  The cause of a row, by a fixed
rule in this order:

* ``agrees``: the engine's bracket meets the model's within ``TOL`` (2 %, the
  pulse thresholds' tolerance) beyond the model's own IDA bracket;
* ``both censored``: neither overturns up to ``im_hi``;
* ``model``: the model is invalid at its threshold (a contact would pull, or a
  friction demand above the engine's: :func:`analytic.bounds.check_model` on the
  record scaled there), so no engine is blamed;
* ``sensitivity``: the engine's bracket holds isolated overturns or flipped
  perturbed runs (a knife-edge: the search's robustness set disagrees);
* ``no-bracket``: no robust bracket;
* ``engine``: none of the above: the engine departs from a valid model.
"""
from __future__ import annotations

import html
import math

__all__ = ["record_section", "record_section_html", "TOL"]

TOL = 0.02  # agreement tolerance on the intensity, as the pulse thresholds'


def record_section(scene, suite, engines_: tuple, st, workers: int = 1) -> dict:
    """The section's data: ``ida`` settings, ``rows`` (one per record and engine)."""
    from trilith_xval.analytic.bounds import check_model
    from trilith_xval.analytic.ida import scale_to
    from trilith_xval.compare.measure.record_jobs import IDAJob, RobustJob, model_run, run_job
    from trilith_xval.compare.run.runs import run_many
    from trilith_xval.compare.run.spec import RunSpec

    model = list(run_many(run_job, [IDAJob(model_run(scene), r, st) for r in suite],
                          workers=workers))
    runs = [RunSpec.resolve(e, scene) for e in engines_]  # each engine at its defaults
    jobs = [RobustJob(run, r, st, None if m["censored"] else m["im_overturn"])
            for run in runs for r, m in zip(suite, model)]
    models = [m for _e in engines_ for m in model]  # each job's model result
    done = list(run_many(run_job, jobs, workers=workers)) if jobs else []
    validity = {}
    for r, m in zip(suite, model):
        if not m["censored"]:
            validity[r.label] = check_model(scene, scale_to(r, st.im, m["im_overturn"]))
    rows = []
    for job, m, res in zip(jobs, models, done):
        rows.append(_row(job.run.backend, job.record.label, m, res, validity.get(job.record.label),
                         st))
    return {"ida": st.describe(), "records": [m for m in model], "rows": rows}


def _row(engine: str, label: str, m: dict, res: dict, valid: dict | None, st) -> dict:
    ref, ref_safe, eng = m["im_overturn"], m["im_safe"], res["im_overturn"]
    if m["censored"] and res["censored"]:
        cause = "both censored"
    elif ref is not None and eng is not None and (
            (ref_safe if ref_safe is not None else ref) * (1 - TOL) <= eng <= ref * (1 + TOL)):
        cause = "agrees"
    elif valid is not None and not valid["valid"]:
        cause = "model"
    elif res["isolated"] or res["flips"]:
        cause = "sensitivity"
    elif not res["bracketed"]:
        cause = "no-bracket"
    else:
        cause = "engine"
    rel = eng / ref - 1.0 if ref and eng else None
    lr = res.get("long_run") or {}
    return {"record": label, "engine": engine, "im": st.im, "im_model": ref,
            "im_model_safe": ref_safe, "im_engine": eng, "im_engine_safe": res["im_safe"],
            "rel_error": rel, "cause": cause,
            "model_reason": "" if valid is None else valid["reason"],
            "isolated": len(res["isolated"]), "n_runs": res["n_runs"], "cpu_s": res["cpu_s"],
            "pivot_sliding_max": lr.get("pivot_sliding_max"),
            "lintel_rotation_max": lr.get("lintel_rotation_max"),
            "residual_tilt": lr.get("residual_tilt"),
            "model_residual_tilt": lr.get("model_residual_tilt")}


def _fmt(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return "nan" if not math.isfinite(value) else f"{value:.4g}"
    return str(value)


def record_section_html(section: dict) -> list[str]:
    """HTML fragments of the section (a heading, a sentence, one table)."""
    st = section["ida"]
    cols = ["record", "engine", "im_model", "im_engine", "rel_error", "cause", "model_reason",
            "isolated", "pivot_sliding_max", "lintel_rotation_max", "residual_tilt",
            "model_residual_tilt", "n_runs", "cpu_s"]
    head = "".join(f"<th>{html.escape(c)}</th>" for c in cols)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(_fmt(r.get(c)))}</td>" for c in cols)
                   + "</tr>" for r in section["rows"])
    unit = st.get("unit") or ""
    return ["<h2>Recorded ground motions</h2>",
            f"<p>First overturning {html.escape(st['im'])} [{html.escape(unit)}] of each record: "
            f"the model's by incremental dynamic analysis (grid step "
            f"{100 * st['rel_step']:g} %, bracket {100 * st['rtol']:g} %, window end + "
            f"{st['tail']:g} s), each engine's robust bracket around it (the perturbation set "
            f"of the pulse thresholds). Cause by a fixed rule: agrees within {100 * TOL:g} %, "
            "model invalid at its threshold, sensitivity (isolated overturns), no bracket, or "
            "the engine. Creep and drift: the engine's run at its highest robust survival, "
            "over the whole window.</p>",
            f"<table><tr>{head}</tr>{body}</table>"]
