"""The record rows of ``trilith campaign`` (``[campaign.records]``,
:mod:`compare.campaign.record_study`): per (scene, case, record) the model's IDA,
per (engine, step) the robust bracket around it; the jobs of ``trilith
fragility``, so the two commands share their stored results."""
from __future__ import annotations

import math

__all__ = ["record_rows"]


def record_rows(study, workers: int) -> tuple[list[dict], list[dict]]:
    """``(references, rows)``: the model's intensity of every (scene, case,
    record), and one row per engine, step and record with ``a_reference`` /
    ``a_engine`` the model's / the engine's first overturning intensity (in the
    unit of ``im``; None when censored at ``im_hi``) and ``rel_error`` their
    ratio minus one (NaN when either is censored), resolved to the model's IDA
    bracket ``rtol`` (``a_reference_safe`` its surviving end)."""
    from trilith_xval.compare.campaign.study import _scene
    from trilith_xval.compare.measure.record_jobs import IDAJob, RobustJob, model_run, run_job
    from trilith_xval.compare.run.runs import run_many
    from trilith_xval.compare.run.spec import RunSpec

    axis, st = study.records, study.records.ida
    records = axis.records()
    cells = [(n, c, r) for n in study.scenes for c in study.cases for r in records]
    model = list(run_many(run_job, [IDAJob(model_run(_scene(n, c)), r, st) for n, c, r in cells],
                          workers=workers))
    # Each engine's run per scene, case and step, resolved before any work.
    runs = {(n, c, e, dt): RunSpec.resolve(e, _scene(n, c), overrides={"dt": dt} if dt else None,
                                           overrides_from="the study's steps")
            for n in study.scenes for c in study.cases for e in study.engines
            for dt in study.steps}
    jobs, meta = [], []
    for (n, c, r), m in zip(cells, model):
        ref = None if m["censored"] else m["im_overturn"]
        for e in study.engines:
            for dt in study.steps:
                jobs.append(RobustJob(runs[(n, c, e, dt)], r, st, ref))
                meta.append((n, c, r.label, e, dt, ref, m["im_safe"]))
    done = list(run_many(run_job, jobs, workers=workers)) if jobs else []
    rows = []
    for (n, c, label, e, dt, ref, ref_safe), res in zip(meta, done):
        eng = res["im_overturn"]
        rows.append({"scene": n, "case": c, "pulse": "record", "record": label, "omega": None,
                     "im": st.im, "engine": e, "dt": dt or None, "a_reference": ref,
                     "a_reference_safe": ref_safe,
                     "a_engine": eng, "a_survives": res["im_safe"],
                     "rel_error": eng / ref - 1.0 if ref and eng else math.nan,
                     "bracketed": res["bracketed"], "censored": res["censored"],
                     "isolated": len(res["isolated"]), "n_runs": res["n_runs"],
                     "cpu_s": res["cpu_s"], "long_run": res["long_run"]})
    refs = [{"scene": n, "case": c, "pulse": "record", "record": r.label, "im": st.im,
             "a_reference": None if m["censored"] else m["im_overturn"],
             "islands": m["islands"]} for (n, c, r), m in zip(cells, model)]
    return refs, rows
