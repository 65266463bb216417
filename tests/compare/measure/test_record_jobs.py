"""The record jobs (fragility, spectrum --record, the campaign's record rows, the
report's record section, trust --record) are values holding RunSpecs, and their
stored results are keyed as they were: the model's IDA and stripes by the
compiled backend's settings over the record's window, an engine's by its run's
settings with the window over them."""
from __future__ import annotations

import numpy as np
import pytest

from trilith_xval.analytic.excitation import SampledRecord
from trilith_xval.analytic.ida import IDASettings
from trilith_xval.compare.measure import record_jobs
from trilith_xval.compare.measure.record_jobs import IDAJob, RobustJob, StripeJob, model_run
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.keys import digest, excitation_dict, scene_dict, settings_dict
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.engines import configure
from trilith_xval.scenes import load_scene

ST = IDASettings(im="pga", im_lo=1.0, im_hi=10.0, tail=2.0)


def record() -> SampledRecord:
    t = np.arange(0.0, 1.5, 0.01)
    return SampledRecord(tuple(t), tuple(np.where(t <= 0.7, np.sin(9.0 * t), 0.0)), "pulse")


@pytest.fixture
def described(monkeypatch):
    """The description each job memoises its result under (nothing computed)."""
    seen = []

    def memo(kind, what, compute, label="", code=runs.MODEL_CODE):
        seen.append((kind, what, code))
        return {}
    monkeypatch.setattr(runs, "memo", memo)
    return seen


def test_the_model_jobs_keep_their_stored_keys(described):
    """The model's IDA and stripes are keyed by the compiled backend's settings
    over the window and by the model's code only: results stored before are
    served."""
    scene, rec = load_scene("fig5"), record()
    IDAJob(model_run(scene), rec, ST)()
    StripeJob(model_run(scene), rec, (2.0, 5.0), "pga", ST.tail)()
    window = settings_dict(configure("analytic-fast", t_max=rec.end_time + ST.tail))
    common = {"backend": "analytic", "scene": scene_dict(scene),
              "record": digest(excitation_dict(rec))}
    assert described == [
        ("ida", {**common, "ida": ST.describe(), "settings": window}, runs.MODEL_CODE),
        ("msa", {**common, "stripes": [2.0, 5.0], "im": "pga", "settings": window},
         runs.MODEL_CODE)]


def test_an_engine_job_is_keyed_by_its_runs_settings(described):
    scene, rec = load_scene("fig5"), record()
    run = RunSpec.resolve("pymunk", scene, file_options={"dt": 5e-4}, file_name="'f.toml'")
    RobustJob(run, rec, ST, 6.0)()
    ((kind, what, code),) = described
    assert kind == "robust-ida" and what["im_model"] == 6.0 and code == runs.ALL_CODE
    # The settings fragility always keyed it by: configure(t_max=window, **options).
    assert what["settings"] == settings_dict(configure("pymunk", t_max=rec.end_time + ST.tail,
                                                       dt=5e-4))


def test_fragility_builds_its_record_runs_from_run_specs(monkeypatch, tmp_path):
    """trilith fragility's robust jobs hold each engine's RunSpec: its defaults,
    then the --settings table, resolved once before any work."""
    from trilith_xval.compare.campaign.settings_file import read_settings_file
    from trilith_xval.compare.cli import fragility
    path = tmp_path / "s.toml"
    path.write_text("[pymunk]\ndt = 0.0005\n")
    loaded = read_settings_file(path)
    scene, suite = load_scene("fig5"), [record(), record()]
    batches = []

    def answer(jobs, workers, scheduler):
        batches.append(jobs)
        return [{"censored": False, "im_overturn": 5.0}] * len(jobs)
    monkeypatch.setattr(fragility, "_run_all", answer)
    fragility.intensities(scene, suite, fragility.engine_runs(scene, ["pymunk"], loaded), ST, 1,
                          None)
    model, robust = batches
    assert all(isinstance(j, IDAJob) and j.run.backend == "analytic" for j in model)
    want = RunSpec.resolve("pymunk", scene, file_options={"dt": 5e-4},
                           file_name=repr(str(path)))
    assert [type(j) for j in robust] == [RobustJob, RobustJob]
    for job in robust:
        assert job.run.key() == want.key() and job.im_model == 5.0
        assert dict(job.run.origin) == {"dt": f"--settings {str(path)!r}"}


def test_a_bad_record_run_is_refused_at_the_door(tmp_path):
    """A --settings friction below the scene's no-sliding bound stops fragility
    before any job, naming the file."""
    from trilith_xval.compare.campaign.settings_file import read_settings_file
    from trilith_xval.compare.cli.fragility import engine_runs
    path = tmp_path / "slide.toml"
    path.write_text("[pymunk]\nfriction = 0.01\n")
    with pytest.raises(ValueError, match=r"friction must be >= .*\(from --settings .*slide"):
        engine_runs(load_scene("fig5"), ["pymunk"], read_settings_file(path))
    assert record_jobs.run_job(lambda: 3) == 3


def test_fragility_refuses_a_bad_run_before_any_job(tmp_path, monkeypatch, capsys):
    from trilith_xval.compare.cli import fragility
    from trilith_xval.compare.cli.main import main
    path = tmp_path / "slide.toml"
    path.write_text("[pymunk]\nfriction = 0.01\n")
    monkeypatch.setattr(fragility, "_run_all", lambda *a: pytest.fail("a job ran"))
    argv = ["fragility", "--records", "synthetic", "--engine", "pymunk", "--settings", str(path),
            "--out", str(tmp_path / "out"), "--no-cache"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: friction must be >=") and "slide.toml" in err
    assert err.count("\n") == 1
