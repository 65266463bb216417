"""Threshold searches start from each engine's shipped calibrated threshold
settings on a scene inside their domain and from the reference settings outside
it; restitution and time histories keep the engine's defaults; a settings file
and ``--dt`` go over them, in that order."""
from __future__ import annotations

import dataclasses

import pytest

from trilith_xval import engines as engines_pkg
from trilith_xval.compare.campaign.settings_file import domain_notes, read_settings_file, threshold_options
from trilith_xval.analytic.pulses import pulse_of
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.compare.campaign.validation import CampaignConfig, campaign_run
from trilith_xval.engines import configure
from trilith_xval.engines.calibration import calibrated, scene_coordinates, threshold_choice
from trilith_xval.scenes import load_scene

ENGINES = engines_pkg.ENGINES


def job_settings(engine, dt, scene, a_ref, omega, options=()):
    """A threshold search's settings as a study's job resolves them: calibration
    (in its domain), a settings file's table, then ``dt`` (0: none)."""
    return RunSpec.resolve(engine, scene, pulse_of("sine", 2.2 * a_ref, omega), calibrated=True,
                           file_options=dict(options), file_name="file",
                           overrides={"dt": dt} if dt else None).settings


@pytest.mark.parametrize("engine", ENGINES)
def test_every_engine_ships_its_calibration_as_package_data(engine):
    cal = calibrated(engine)
    assert cal.source.endswith("thresholds.toml") and f"{engine}_" in cal.source
    # The regenerating command is the file's first line.
    assert cal.command.startswith(f"trilith calibrate --engine {engine} --metric thresholds")
    configure(engine, **cal.options)  # valid settings of the engine
    if cal.options:  # a calibrated step holds in a stated domain
        assert cal.domain.ranges
        assert cal.domain.outside(load_scene("fig5")) is None


def test_a_missing_calibration_is_an_error_not_a_fallback(monkeypatch):
    import trilith_xval.engines.calibration as c
    calibrated.cache_clear()

    class Missing:
        def read_text(self, encoding=None):
            raise FileNotFoundError("thresholds.toml")
    monkeypatch.setattr(c, "_resource", lambda engine, metric: Missing())
    try:
        with pytest.raises(ValueError, match="missing from the engine's package"):
            threshold_options("pymunk", load_scene("fig5"))
    finally:
        monkeypatch.undo()
        calibrated.cache_clear()


@pytest.mark.parametrize("engine", ENGINES)
def test_only_threshold_searches_use_them(engine):
    scene = load_scene("fig5")
    stored = threshold_options(engine, scene)
    config = CampaignConfig(engines=(engine,))
    assert campaign_run(engine, config, scene, thresholds=True).settings == configure(engine,
                                                                                      **stored)
    assert campaign_run(engine, config, scene).settings == configure(engine)  # histories
    assert campaign_run(engine, config, scene).origin == ()
    assert job_settings(engine, 0.0, scene, 10.0, 12.0).dt == stored.get("dt",
                                                                          configure(engine).dt)


def _outside(cal):
    """A scene just past the upper end of the domain's first varied range."""
    name, (lo, hi) = next((n, r) for n, r in cal.domain.ranges if n in ("lam", "mu"))
    return load_scene("fig5").replace(**{name: hi * 1.05 + 0.01})


@pytest.mark.parametrize("engine", [e for e in ENGINES if calibrated(e).options])
def test_outside_its_domain_the_reference_step_runs_and_says_so(engine):
    cal = calibrated(engine)
    scene = _outside(cal)
    choice = threshold_choice(engine, scene)
    assert not choice.inside and choice.options == {}
    assert "outside the domain" in choice.note and f"{configure(engine).dt:g}" in choice.note
    assert job_settings(engine, 0.0, scene, 10.0, 12.0).dt == configure(engine).dt
    notes = domain_notes([engine], [scene, load_scene("fig5")])
    assert len(notes) == 1 and "\n" not in notes[0]
    # A value the calibration kept fixed (the column's inertia) is outside too.
    inertia = dataclasses.replace(load_scene("fig5"), J_G=None).replace(
        J_G=1.5 * scene_coordinates(load_scene("fig5"))["J_G_over_uniform"]
        * load_scene("fig5").m1 * (0.6 ** 2 + 3.0 ** 2) / 12.0)
    assert "calibration kept" in threshold_choice(engine, inertia).note


def test_a_calibration_file_is_a_settings_file(tmp_path):
    text = calibrated("pymunk").source
    from pathlib import Path
    f = tmp_path / "cal.toml"
    f.write_text(Path(text).read_text())
    assert set(read_settings_file(f).tables) == {"pymunk"}


def test_a_settings_file_then_dt_go_over_the_calibrated_step():
    scene = load_scene("fig5")
    assert job_settings("pymunk", 0.0, scene, 10.0, 12.0, (("dt", 5e-4),)).dt == 5e-4
    assert job_settings("pymunk", 2e-4, scene, 10.0, 12.0, (("dt", 5e-4),)).dt == 2e-4
    config = CampaignConfig(engines=("pymunk",), engine_settings={"pymunk": {"iterations": 30}},
                            engine_dt=3e-4)
    run = campaign_run("pymunk", config, scene, thresholds=True)
    assert (run.settings.dt, run.settings.iterations) == (3e-4, 30)
    assert dict(run.origin) == {"dt": "the campaign's engine_dt",
                                "iterations": "the campaign's engine_settings"}


def test_the_report_names_the_threshold_step():
    from trilith_xval.compare.report.tables import settings_rows
    doc = {"config": {"engines": ["pymunk"]}, "settings": {"pymunk": {"dt": 1e-4}},
           "threshold_settings": {"pymunk": {"dt": 2e-3}}}
    head, rows = settings_rows(doc)
    assert rows == [["dt", "1e-4"], ["dt (threshold searches)", "2e-3"]]
    doc["threshold_settings"]["pymunk"]["dt"] = 1e-4  # the same step: no extra row
    assert settings_rows(doc)[1] == [["dt", "1e-4"]]


def test_a_threshold_job_is_a_value_resolved_once():
    """A job's run is resolved once, layer by layer, and names where a bad value
    came from."""
    from trilith_xval.compare.campaign.study import ThresholdJob
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.analytic.pulses import pulse_of

    job = ThresholdJob("fig5", "pendulum", "sine", 12.0, 10.0, None, "pymunk", 0.0, 0.03,
                       5e-3, (("iterations", 40),))
    assert job.spec is job.spec  # resolved once
    fig5 = load_scene("fig5")
    assert job.spec.settings.dt == threshold_options("pymunk", fig5)["dt"]
    assert dict(job.spec.origin) == {"dt": "the calibration of pymunk",
                                     "iterations": "--settings file"}
    assert job.description()["settings"]["iterations"] == 40
    with pytest.raises(ValueError, match=r"dt .*\(from the command line\)"):
        RunSpec.resolve("pymunk", fig5, pulse_of("sine", 10.0, 12.0), overrides={"dt": -1.0})
    with pytest.raises(ValueError, match=r"\(from --settings my.toml\)"):
        RunSpec.resolve("pymunk", fig5, pulse_of("sine", 10.0, 12.0),
                        file_options={"iterations": -3}, file_name="my.toml")
    # A friction the user gives is kept as given, and refused below the
    # no-sliding bound of the largest pulse (the pivots would slide) ...
    from trilith_xval.analytic.bounds import required_friction
    from trilith_xval.compare.run.spec import _friction_rule
    from trilith_xval.engines.base import FRICTION_MARGIN
    pulse = pulse_of("sine", 60.0, 12.0)
    need = required_friction(fig5, pulse)
    with pytest.raises(ValueError, match=r"friction must be >= .*\(from the command line\)"):
        RunSpec.resolve("pymunk", fig5, pulse, overrides={"friction": 0.5 * need})
    spec = RunSpec.resolve("pymunk", fig5, pulse, overrides={"friction": 1.05 * need})
    assert spec.settings.friction == 1.05 * need
    assert dict(spec.origin)["friction"] == "the command line"
    # ... one a calibration fixed is raised to the margin over it.
    settings, origin = _friction_rule("pymunk", fig5, pulse, configure("pymunk", friction=0.05),
                                      {"friction": "the calibration of pymunk"})
    assert settings.friction == pytest.approx(FRICTION_MARGIN * need)
    assert origin["friction"] == "the friction rule"
    # The same layers on another excitation resolve by the same rules.
    assert spec.at(excitation=pulse_of("sine", 1.0, 12.0)).settings.friction == 1.05 * need
    with pytest.raises(ValueError, match="friction must be >="):
        spec.at(excitation=pulse_of("sine", 120.0, 12.0))
    assert spec.with_options("the step rule", dt=5e-5).settings.dt == 5e-5
