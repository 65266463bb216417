"""The record jobs of ``trilith fragility``, ``spectrum --record``, the campaign's
record rows and the report's record section: one record, one backend, each a
frozen value holding its run (:class:`compare.run.spec.RunSpec`).

* :class:`IDAJob`: the backend's incremental dynamic analysis of the record
  (:func:`analytic.ida.first_overturn_intensity`);
* :class:`RobustJob`: an engine's robust bracket around the model's intensity
  (:func:`compare.measure.record_threshold.engine_intensity`);
* :class:`KindJob`: an engine's own first failing intensity on a scene of another
  kind, without a model (:func:`compare.measure.record_kinds.own_intensity`);
* :class:`StripeJob`: the verdict at each stripe of a multiple-stripe analysis
  (:mod:`compare.measure.msa`).

Each result is memoised whole in the run store (an engine's runs each stored
too).  The model (backend ``'analytic'``) runs compiled, verdict only
(:func:`analytic.ida.model_verdict`), with the compiled backend's settings over
the same window, so its stored results are keyed as they always were.
:func:`run_job` is the function a parallel map calls.
"""
from __future__ import annotations

from dataclasses import dataclass

from trilith_xval.compare.run.spec import RunSpec

__all__ = ["IDAJob", "RobustJob", "KindJob", "StripeJob", "run_job", "model_run"]

MODEL = "analytic"  # the model's backend name in these jobs (run compiled)


def run_job(job):
    """``job()``: the function :func:`compare.run.runs.run_many` maps (picklable)."""
    return job()


def model_run(scene) -> RunSpec:
    """The model on ``scene``: the run of the model's jobs (its settings are the
    compiled backend's, set by each job for its window)."""
    return RunSpec.resolve(MODEL, scene)


def _model_settings(end_time: float, tail: float):
    from trilith_xval.engines import configure
    return configure("analytic-fast", t_max=end_time + tail)


def _record_digest(record) -> str:
    from trilith_xval.compare.run.keys import digest, excitation_dict
    return digest(excitation_dict(record))


@dataclass(frozen=True)
class IDAJob:
    """The IDA of ``record`` in ``run``'s backend (:class:`analytic.ida.IDAResult`
    as plain data); an engine's runs are resolved up to ``st.im_hi``
    (:func:`compare.measure.record_threshold.record_run`)."""

    run: RunSpec
    record: object
    st: object  # analytic.ida.IDASettings

    def __call__(self) -> dict:
        from trilith_xval.analytic.ida import first_overturn_intensity, model_verdict
        from trilith_xval.compare.measure.record_threshold import record_run
        from trilith_xval.compare.run import runs
        from trilith_xval.compare.run.keys import scene_dict, settings_dict
        backend, scene, record, st = self.run.backend, self.run.scene, self.record, self.st
        if backend == MODEL:
            settings = _model_settings(record.end_time, st.tail)
            overturns = model_verdict(scene, st.tail)
        else:
            settings = record_run(self.run, record, st, st.im_hi).settings

            def overturns(motion) -> bool:
                return runs.simulate(backend, scene, motion, settings).verdict.overturned

        def compute():
            res = first_overturn_intensity(record, overturns, st)
            return {**res.describe(), "runs": [[v, o] for v, o in res.runs]}
        what = {"backend": backend, "scene": scene_dict(scene), "record": _record_digest(record),
                "ida": st.describe(), "settings": settings_dict(settings)}
        return runs.memo("ida", what, compute, label=f"ida {backend} {record.label}")


@dataclass(frozen=True)
class RobustJob:
    """An engine's robust first overturning intensity of ``record`` around the
    model's ``im_model`` (None: censored at ``st.im_hi``)."""

    run: RunSpec
    record: object
    st: object  # analytic.ida.IDASettings
    im_model: float | None

    def __call__(self) -> dict:
        from trilith_xval.compare.measure.record_threshold import (engine_intensity, record_run,
                                                                   search_centre)
        from trilith_xval.compare.measure.thresholds import SEARCH
        from trilith_xval.compare.run import runs
        from trilith_xval.compare.run.keys import scene_dict, settings_dict
        run, record, st, im_model = self.run, self.record, self.st, self.im_model
        top = SEARCH.widest * search_centre(st, im_model)
        what = {"backend": run.backend, "scene": scene_dict(run.scene),
                "record": _record_digest(record), "ida": st.describe(), "im_model": im_model,
                "settings": settings_dict(record_run(run, record, st, top).settings)}
        return runs.memo("robust-ida", what,
                         lambda: engine_intensity(run, record, st, im_model),
                         label=f"robust ida {run.backend} {record.label}", code=runs.ALL_CODE)


@dataclass(frozen=True)
class KindJob:
    """An engine's own first failing intensity of ``record`` on a scene of another
    kind: a scan, then the robust bracket converged in the step."""

    run: RunSpec
    record: object
    st: object  # analytic.ida.IDASettings

    def __call__(self) -> dict:
        from trilith_xval.compare.measure.record_kinds import own_intensity
        from trilith_xval.compare.run import runs
        from trilith_xval.compare.run.keys import scene_dict, settings_dict
        run, record, st = self.run, self.record, self.st
        what = {"backend": run.backend, "scene": scene_dict(run.scene),
                "record": _record_digest(record), "ida": st.describe(),
                "settings": settings_dict(run.settings)}
        return runs.memo("kind-ida", what, lambda: own_intensity(run, record, st),
                         label=f"own ida {run.backend} {record.label}", code=runs.ALL_CODE)


@dataclass(frozen=True)
class StripeJob:
    """``run``'s verdict at every stripe (``record`` scaled to each intensity
    ``stripes`` in the measure ``im``), the whole set memoised.  Each run lasts
    the record plus ``tail`` seconds (the window of :mod:`analytic.ida`, so a
    stripe's run is the IDA's run at that intensity)."""

    run: RunSpec
    record: object
    stripes: tuple
    im: str
    tail: float

    def __call__(self) -> list[bool]:
        from trilith_xval.analytic.ida import model_verdict, scale_to
        from trilith_xval.compare.run import runs
        from trilith_xval.compare.run.keys import scene_dict, settings_dict
        backend, scene, record = self.run.backend, self.run.scene, self.record
        if backend == MODEL:
            # Compiled, as in the IDA jobs: the same verdict of the same window.
            settings = _model_settings(record.end_time, self.tail)
            overturns = model_verdict(scene, self.tail)
        else:
            settings = self.run.at(excitation=scale_to(record, self.im, max(self.stripes))) \
                .with_options("the record's window", t_max=record.end_time + self.tail).settings

            def overturns(motion) -> bool:
                return runs.simulate(backend, scene, motion, settings).verdict.overturned

        def compute():
            return [bool(overturns(scale_to(record, self.im, s))) for s in self.stripes]
        what = {"backend": backend, "scene": scene_dict(scene), "record": _record_digest(record),
                "stripes": list(self.stripes), "im": self.im, "settings": settings_dict(settings)}
        code = runs.MODEL_CODE if backend == MODEL else runs.ALL_CODE
        return runs.memo("msa", what, compute, label=f"msa {backend} {record.label}", code=code)
