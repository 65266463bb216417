"""The validation campaign's jobs are values holding their runs: every run comes
from one RunSpec resolved by compare.campaign.config.campaign_run, with the
settings the campaign always ran (defaults, the config's engine_settings, then
engine_dt; the calibration first for threshold searches).  No engine runs here:
the jobs are collected and answered by a stand-in."""
from __future__ import annotations

import pytest

from trilith_xval.analytic.excitation import Pulse, Still
from trilith_xval.analytic.pulses import pulse_of
from trilith_xval.compare.campaign import validation
from trilith_xval.compare.campaign import validation_jobs as jobs
from trilith_xval.compare.campaign.config import CampaignConfig, campaign_run
from trilith_xval.compare.campaign.settings_file import threshold_options
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.engines import configure
from trilith_xval.scenes import POINTS, load_scene

CONFIG = CampaignConfig.quick(engines=("pymunk",), points=("A",),
                              spectrum_cases=("no_pendulum",), jump_cases=("pendulum",),
                              restitution_lams=(5.0,), restitution_mus=(1.0,),
                              pendulum_lams=(5.0,), long_runs=True,
                              engine_settings={"pymunk": {"iterations": 20}}, engine_dt=5e-4,
                              workers=1)
OWN = {"iterations": 20, "dt": 5e-4}  # what CONFIG sets for pymunk, over its defaults


@pytest.fixture(scope="module")
def submitted():
    """The jobs run_campaign submits for CONFIG, each answered with an error."""
    seen = []

    def collect(batch, workers, lines=False):
        seen.extend(batch)
        return [(validation._JobError("stand-in"), 0.0, 0.0, False)] * len(batch)
    saved, validation._execute = validation._execute, collect
    try:
        result = validation.run_campaign(CONFIG)
    finally:
        validation._execute = saved
    return seen, result


def test_every_job_holds_a_run_spec_of_its_backend(submitted):
    seen, _ = submitted
    kinds = {type(j) for j in seen}
    assert {jobs.HistoryJob, jobs.RestitutionJob, jobs.ThresholdPointJob, jobs.JumpJob,
            jobs.LongRunJob} <= kinds
    for job in seen:
        assert isinstance(job.run, RunSpec)
        assert job.args()[0] == job.run.backend


def test_a_restitution_job_runs_the_spec_the_campaign_resolves(submitted):
    seen, _ = submitted
    restitution = [j for j in seen if isinstance(j, jobs.RestitutionJob)]
    assert len(restitution) == 2  # lam 5 mu 1 without the pendulum, lam 5 with it
    for job in restitution:
        same = RunSpec.resolve("pymunk", job.run.scene, Still(),
                               overrides={"iterations": 20},
                               overrides_from="the campaign's engine_settings"
                               ).with_options("the campaign's engine_dt", dt=5e-4)
        assert job.run.key() == same.key()
        assert job.run.settings == configure("pymunk", **OWN)  # as the campaign always ran
        assert dict(job.run.origin) == {"dt": "the campaign's engine_dt",
                                        "iterations": "the campaign's engine_settings"}


def test_histories_thresholds_and_long_runs_carry_their_excitations(submitted):
    seen, result = submitted
    fig5 = load_scene("fig5")
    for job in seen:
        if isinstance(job, jobs.HistoryJob):
            assert job.run.excitation == Pulse(*POINTS[job.point])
            want = configure(job.run.backend, **(OWN if job.run.backend == "pymunk" else {}))
            assert job.run.settings == want
        elif isinstance(job, jobs.ThresholdPointJob):
            assert job.run.excitation == pulse_of("sine", 2.2 * job.a_reference, job.omega)
            assert job.run.settings == configure("pymunk", **{
                **threshold_options("pymunk", fig5), **OWN})
        elif isinstance(job, jobs.JumpJob):  # the friction rule at its largest pulse
            assert job.run.excitation == pulse_of("sine", job.amplitude, job.omega_hi)
            assert job.run.settings == configure("pymunk", **OWN)
        elif isinstance(job, jobs.LongRunJob):
            assert job.run.scene == load_scene(job.scene_name)
            assert job.run.settings == configure("pymunk", **OWN)
    # What summary.json says the backends ran with is the same resolution.
    assert result.settings["pymunk"]["dt"] == 5e-4
    assert result.threshold_settings["pymunk"]["iterations"] == 20
    # A job's error record keeps its arguments as the campaign wrote them.
    error = next(e for e in result.errors if e["job"] == "restitution")
    assert error["args"][0] == "pymunk" and error["args"][1]["lam"] == 5.0


def test_job_descriptions_name_the_config_but_not_its_worker_count():
    fig5 = load_scene("fig5")
    a = jobs.RestitutionJob(campaign_run("pymunk", CONFIG, fig5), CONFIG)
    two = CampaignConfig.quick(**{**{k: getattr(CONFIG, k) for k in (
        "engines", "points", "spectrum_cases", "jump_cases", "restitution_lams",
        "restitution_mus", "pendulum_lams", "long_runs", "engine_settings", "engine_dt")},
        "workers": 2})
    b = jobs.RestitutionJob(campaign_run("pymunk", two, fig5), two)
    assert validation._job_description(a) == validation._job_description(b)
    finer = jobs.RestitutionJob(campaign_run("pymunk", CONFIG, fig5),
                                CampaignConfig(engines=("pymunk",), engine_dt=1e-4))
    assert validation._job_description(finer) != validation._job_description(a)


def test_a_bad_campaign_setting_names_its_layer():
    fig5 = load_scene("fig5")
    slippery = CampaignConfig(engines=("pymunk",), engine_settings={"pymunk": {"friction": 0.05}})
    with pytest.raises(ValueError, match=r"friction .*\(from the campaign's engine_settings\)"):
        campaign_run("pymunk", slippery, fig5)
