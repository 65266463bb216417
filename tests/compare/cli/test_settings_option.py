"""``--settings FILE``: refused whole at the door, applied to the runs, and part of
every store key (a changed setting never serves a stored result)."""
from __future__ import annotations

import hashlib
import json

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.run import runs

from tests.support.paths import ROOT

BAD = {
    "dt": ("[pymunk]\ndt = 0.5\n", "dt must be"),
    "key": ("[pymunk]\nstep = 1e-3\n", "no option 'step'"),
    "engine": ("[bullet]\ndt = 1e-3\n", "unknown engine table [bullet]"),
    "run_field": ("[pymunk]\ntheta0 = 0.1\n", "theta0 is set by each command"),
    "not_toml": ("[pymunk\n", "not TOML"),
    "other_engine": ("[mujoco]\ndt = 1e-3\n", "no table for pymunk"),
}
COMMANDS = {
    "simulate": ["simulate", "--engine", "pymunk", "-A", "3", "-w", "12"],
    "restitution": ["restitution", "--engine", "pymunk"],
    "spectrum": ["spectrum", "--engine", "pymunk", "--omega", "12"],
    "map": ["map", "--engine", "pymunk", "--omega", "8:12:2", "--amplitude", "2:6:2"],
    "report": ["report", "--engine", "pymunk", "--quick"],
    "campaign": ["campaign", "{campaign}"],
    "fragility": ["fragility", "--records", "sample", "--engine", "pymunk"],
    "spectrum_record": ["spectrum", "--engine", "pymunk", "--record", "{record}"],
    "record": ["record", "--engine", "pymunk", "--out", "{gif}"],
    "view": ["view", "--engine", "pymunk"],
    "atlas": ["atlas", "--engine", "pymunk"],
    "calibrate": ["calibrate", "--engine", "pymunk"],
}


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("settings")
    out = {}
    for name, (text, _) in BAD.items():
        (d / f"{name}.toml").write_text(text)
        out[name] = str(d / f"{name}.toml")
    (d / "study.toml").write_text('[campaign]\nname = "s"\nscenes = ["fig5"]\n'
                                  'engines = ["pymunk"]\npulses = ["sine"]\nomega = [12.0]\n'
                                  'steps = [0]\n')
    out["campaign"] = str(d / "study.toml")
    out["record"] = str(ROOT / "scenes" / "records" / "sample.csv")
    out["gif"] = str(d / "run.gif")
    return out


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize("bad", sorted(BAD))
def test_a_bad_settings_file_is_refused_before_any_run(command, bad, bad_files, no_work,
                                                       capsys, tmp_path):
    argv = [a.format(**bad_files) for a in COMMANDS[command]]
    if command in ("report", "campaign", "fragility"):
        argv += ["--out", str(tmp_path / "out")]
    assert main(argv + ["--settings", bad_files[bad]]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("error: --settings: "), err
    assert BAD[bad][1] in err[0], err[0]


def test_an_analytic_run_refuses_a_settings_file(bad_files, no_work, capsys):
    assert main(["simulate", "-A", "3", "-w", "12", "--settings", bad_files["other_engine"]]) == 2
    assert "no table for analytic" in capsys.readouterr().err


def _simulate_json(argv, capsys) -> dict:
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_file_changes_the_run_and_is_named_by_its_hash(tmp_path, capsys):
    path = tmp_path / "coarse.toml"
    path.write_text("# a coarser step\n[pymunk]\ndt = 0.001\niterations = 30\n")
    argv = ["simulate", "--engine", "pymunk", "-A", "3", "-w", "12"]
    default = _simulate_json(argv, capsys)
    coarse = _simulate_json(argv + ["--settings", str(path)], capsys)
    assert default["settings"]["dt"] == 1e-4 and coarse["settings"]["dt"] == 1e-3
    assert coarse["settings"]["iterations"] == 30
    described = coarse["inputs"]["settings_file"]
    assert described["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert described["tables"] == {"pymunk": {"dt": 0.001, "iterations": 30}}
    # Ten times fewer steps over the same run: the engine really stepped at 1e-3 s.
    assert coarse["diagnostics"]["steps"] * 5 < default["diagnostics"]["steps"]


def test_a_changed_setting_is_a_new_store_key(tmp_path, capsys):
    path = tmp_path / "coarse.toml"
    path.write_text("[pymunk]\ndt = 0.001\n")
    argv = ["restitution", "--engine", "pymunk", "--n-impacts", "1", "--json",
            "--cache", str(tmp_path / "store")]

    def measured(extra):
        assert main(argv + extra) == 0
        doc = json.loads(capsys.readouterr().out)
        return doc["impacts"][0]["measured"], {k: runs.STATS.get(k, 0)
                                               for k in ("hits", "computed")}
    default, first = measured([])
    coarse, second = measured(["--settings", str(path)])
    assert second["hits"] == 0 and second["computed"] >= 1  # not served the 1e-4 s run
    assert coarse != default
    again, third = measured(["--settings", str(path)])
    assert third["hits"] >= 1 and third["computed"] == 0 and again == coarse


def test_campaign_jobs_carry_the_file_into_their_keys():
    from trilith_xval.compare.campaign.study import Study, threshold_description, threshold_jobs
    from trilith_xval.compare.campaign.validation import CampaignConfig, _job_description
    from trilith_xval.compare.run.keys import digest

    study = Study("s", ("fig5",), ("pymunk",), ("sine",), (12.0,), (0.0,))
    refs = {("fig5", "pendulum", "sine", 12.0): (20.0, "no-impact")}
    plain_job, = threshold_jobs(study, refs)
    filed_job, = threshold_jobs(study, refs, {"pymunk": {"dt": 1e-3}})
    assert threshold_description(filed_job)["settings"]["dt"] == 1e-3
    assert digest(threshold_description(plain_job)) != digest(threshold_description(filed_job))
    from trilith_xval.compare.campaign.validation_jobs import RestitutionJob
    from trilith_xval.compare.campaign.config import campaign_run
    from trilith_xval.scenes import load_scene
    a = CampaignConfig(engines=("pymunk",))
    b = CampaignConfig(engines=("pymunk",), engine_settings={"pymunk": {"dt": 1e-3}})
    fig5 = load_scene("fig5")
    job_a = RestitutionJob(campaign_run("pymunk", a, fig5), a)
    job_b = RestitutionJob(campaign_run("pymunk", b, fig5), b)
    assert job_b.run.settings.dt == 1e-3 != job_a.run.settings.dt
    assert digest(_job_description(job_a)) != digest(_job_description(job_b))
    with pytest.raises(ValueError, match="iterations"):
        CampaignConfig(engines=("pymunk",), engine_settings={"pymunk": {"iterations": 0}})


def test_recordings_run_with_the_file_options():
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.compare.show.record import RecordSettings, recording_run
    from trilith_xval.engines import configure
    from trilith_xval.scenes import load_scene
    fig5, pulse = load_scene("fig5"), Pulse(19.0, 15.0)
    filed = RunSpec.resolve("pymunk", fig5, pulse, file_options={"dt": 1e-3}, file_name="f.toml")
    settings = RecordSettings(runs=(filed,))
    assert settings.run_of("pymunk") is filed and settings.run_of("mujoco") is None
    run = recording_run("pymunk", fig5, pulse, 2.0, settings.run_of("pymunk"))
    assert (run.settings.dt, run.settings.t_max, run.settings.early_stop) == (1e-3, 2.0, False)
    assert dict(run.origin) == {"dt": "--settings f.toml", "t_max": "the recorded span",
                                "early_stop": "the recorded span"}
    # Without a given run: the backend's defaults over the span, as before.
    plain = recording_run("mujoco", fig5, pulse, 2.0)
    assert plain.settings == configure("mujoco", t_max=2.0, early_stop=False)


@pytest.mark.parametrize("command", ["simulate", "map"])
def test_a_friction_given_below_the_no_sliding_bound_is_refused_at_the_door(
        command, tmp_path, no_work, capsys):
    """A friction the user gives is the user's: never raised behind their back
    (compare.run.spec), and refused before any run where a pulse of the command
    would need more (the pivots would slide: not the mechanism compared)."""
    path = tmp_path / "slippery.toml"
    # 0.27: above fig5's static bound (0.23), below what 3 m/s^2 needs (0.31)
    path.write_text("[pymunk]\nfriction = 0.27\n")
    assert main(COMMANDS[command] + ["--settings", str(path)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "friction must be >=" in err[0], err
    assert f"(from --settings {str(path)!r})" in err[0]


def test_a_friction_given_above_the_bound_is_kept_as_given(tmp_path, capsys):
    from trilith_xval.analytic.bounds import required_friction
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.scenes import load_scene
    need = required_friction(load_scene("fig5"), Pulse(3.0, 12.0))
    path = tmp_path / "just.toml"
    path.write_text(f"[pymunk]\nfriction = {1.05 * need!r}\n")  # below the 1.2x margin
    doc = _simulate_json(COMMANDS["simulate"] + ["--settings", str(path)], capsys)
    assert doc["settings"]["friction_used"] == 1.05 * need


def test_record_resolves_each_backends_run_from_the_file(tmp_path):
    """trilith record / view hand each backend's RunSpec (defaults, then the
    --settings table) to the recording: the run a panel shows is that spec with
    the recorded span over it."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.cli.main import build_parser
    from trilith_xval.compare.cli.record import watch_inputs
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.compare.show.record import recording_run
    from trilith_xval.scenes import load_scene
    path = tmp_path / "s.toml"
    path.write_text("[pymunk]\ndt = 0.0005\n")
    parser, _ = build_parser()
    args = parser.parse_args(["record", "--engine", "analytic,pymunk", "--settings", str(path),
                              "--duration", "1", "--out", str(tmp_path / "x.gif")])
    scene, excitation, settings = watch_inputs(args)
    assert excitation == Pulse(19.0, 15.0) and scene == load_scene("fig5")
    assert [r.backend for r in settings.runs] == ["analytic", "pymunk"]
    filed = RunSpec.resolve("pymunk", scene, excitation, file_options={"dt": 5e-4},
                            file_name=repr(str(path)))
    assert settings.run_of("pymunk").key() == filed.key()
    assert settings.run_of("analytic").key() == RunSpec.resolve("analytic", scene,
                                                                excitation).key()
    shown = recording_run("pymunk", scene, excitation, 1.0, settings.run_of("pymunk"))
    assert (shown.settings.dt, shown.settings.t_max) == (5e-4, 1.0)
