"""`trilith calibrate`: the Pareto front, settings files and a real small calibration."""
import math

import pytest

from trilith_xval import engines
from trilith_xval.compare.campaign.calibrate import Evaluation, ValidationSet, calibrate, pareto_front
from trilith_xval.compare.campaign.settings_file import load_settings_file, settings_toml
from trilith_xval.compare.cli.main import main


def _ev(cpu, err):
    return Evaluation({"dt": cpu}, err, (), cpu, 2.0 * cpu, 0.0, 1)


def test_pareto_front_keeps_only_undominated_candidates():
    evs = [_ev(1.0, 0.02), _ev(2.0, 0.01), _ev(3.0, 0.015), _ev(4.0, 0.001), _ev(0.5, 0.5)]
    front = pareto_front(evs)
    assert [(e.engine_cpu_s, e.worst_error) for e in front] == [(0.5, 0.5), (1.0, 0.02), (2.0, 0.01),
                                                          (4.0, 0.001)]


def test_settings_file_round_trip_is_bit_identical(tmp_path):
    options = {"dt": 0.1 + 0.2 - 0.3 + 4e-4, "iterations": 17}
    p = tmp_path / "s.toml"
    p.write_text(settings_toml("pymunk", options, "a comment\nsecond line"))
    loaded = load_settings_file(p)
    assert loaded == {"pymunk": options}
    assert engines.configure("pymunk", **loaded["pymunk"]).dt == options["dt"]


@pytest.mark.parametrize("text, words", [
    ("[bullet]\ndt = 1e-4\n", "unknown engine table [bullet]"),
    ("[pymunk]\nstep = 1e-4\n", "has no option 'step'"),
    ("[pymunk]\ndt = -1.0\n", "dt"),
    ("[pymunk]\ndt = nan\n", "must be finite"),
    ("[pymunk\n", "not TOML"),
    ("pymunk = 3\n", "must be a table"),
])
def test_bad_settings_files_are_refused_naming_file_and_key(tmp_path, text, words):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(ValueError) as err:
        load_settings_file(p)
    assert "bad.toml" in str(err.value) and words in str(err.value)


def test_restitution_calibration_prefers_the_step_that_meets_eq20():
    # Pymunk's restitution error grows about linearly with the step (0.23 % at
    # 1e-4 s, ~1.4 % at 2e-3 s on lam 3 mu 0.5): the 0.5 % tolerance keeps the fine
    # step even though the coarse one is cheaper.
    vs = ValidationSet(releases=((3.0, 0.5),), n_impacts=2)
    from trilith_xval.scenes import load_scene
    cal = calibrate("pymunk", "restitution", validation=vs, space={"dt": [1e-4, 2e-3]},
                    scene=load_scene("fig5", gamma=0.0))
    by_dt = {e.options["dt"]: e for e in cal.evaluations}
    assert by_dt[1e-4].worst_error < cal.tolerance < by_dt[2e-3].worst_error
    assert cal.recommended is by_dt[1e-4]
    assert all(0 < e.engine_cpu_s < e.cpu_s and e.simulated_s > 0
               and math.isfinite(e.real_time_factor) for e in cal.evaluations)
    # ten times fewer steps: the engine's own cost falls, whatever the measurement costs
    assert by_dt[2e-3].engine_cpu_s < by_dt[1e-4].engine_cpu_s


@pytest.mark.parametrize("argv, words", [
    (["--vary", "iterations"], "--vary must be NAME=V1,V2"),
    (["--dt", "1e-4,abc"], "--dt: 'abc' is not a number"),
    (["--vary", "bogus=1,2"], "has no option 'bogus'"),
    (["--step-only", "--dt", "1e-4,2e-4,3e-4,4e-4,5e-4,6e-4,7e-4,8e-4,9e-4", "--vary",
      "iterations=" + ",".join(str(i) for i in range(10, 18))], "72 combinations"),
    # Pymunk's declared slop range doubles the search: 9 x 8 x 2.
    (["--dt", "1e-4,2e-4,3e-4,4e-4,5e-4,6e-4,7e-4,8e-4,9e-4", "--vary", "iterations=" +
      ",".join(str(i) for i in range(10, 18))], "144 combinations"),
])
def test_calibrate_door(argv, words, capsys):
    assert main(["calibrate", "--engine", "pymunk", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0]


def test_threshold_calibration_measures_its_cost_per_simulated_second():
    # One frequency, both curves, one coarse step: the robust search's runs are
    # counted, their CPU and simulated time summed, so the real-time factor is the
    # engine's own (a threshold search simulates seconds per probe).
    cal = calibrate("pymunk", "thresholds", validation=ValidationSet(omegas=(12.0,)),
                    space={"dt": [2e-3]})
    (ev,) = cal.evaluations
    assert {label for label, _ in ev.errors} <= {"pendulum Omega 12", "no_pendulum Omega 12"}
    assert ev.runs >= 4 and ev.simulated_s > 0
    assert 0 < ev.engine_cpu_s < ev.cpu_s and math.isfinite(ev.real_time_factor)


def test_a_calibration_resumes_from_the_store_with_its_measured_costs(tmp_path, monkeypatch):
    from trilith_xval.compare.campaign import calibrate as module
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.store import RunStore

    vs = ValidationSet(omegas=(12.0,))
    space = {"dt": [2e-3, 1e-3]}
    previous = runs.activate(RunStore(tmp_path / "store"))
    try:
        first = calibrate("pymunk", "thresholds", validation=vs, space=space)
        assert not any(e.from_store for e in first.evaluations)

        # A rerun (e.g. after kill -9) evaluates nothing again ...
        def no_engine(*args, **kwargs):
            raise AssertionError("a stored candidate was evaluated again")
        monkeypatch.setattr(module, "_thresholds", no_engine)
        again = calibrate("pymunk", "thresholds", validation=vs, space=space)
    finally:
        runs.activate(previous)
    # ... and reports the errors and the costs that were measured, saying so.
    assert all(e.from_store for e in again.evaluations)
    keep = ("options", "worst_error", "errors", "engine_cpu_s", "cpu_s", "simulated_s", "runs")
    assert [[getattr(e, k) for k in keep] for e in again.evaluations] == \
        [[getattr(e, k) for k in keep] for e in first.evaluations]
    assert again.recommended.options == first.recommended.options


def test_a_calibration_killed_mid_candidate_resumes_at_the_next_scene(tmp_path, monkeypatch):
    # One candidate over a design's scenes can take CPU hours (Drake at 1e-4 s):
    # each scene is kept as soon as it is done, so a kill loses one scene at most.
    from trilith_xval.compare.campaign import calibrate as module
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.store import RunStore
    from trilith_xval.scenes import load_scene

    scenes = [load_scene("fig5"), load_scene("fig11_mu1")]
    vs = ValidationSet(omegas=(12.0,))
    measure, seen = module._thresholds, []

    def killed_at_the_second(run, reference, workers):
        if run.scene.name == "fig11_mu1":
            raise KeyboardInterrupt  # as Ctrl-C (or kill -9) mid-candidate
        out = measure(run, reference, workers)
        seen.append(out)
        return out

    def counted(run, reference, workers):
        seen.append(run.scene.name)
        return measure(run, reference, workers)

    previous = runs.activate(RunStore(tmp_path / "store"))
    try:
        monkeypatch.setattr(module, "_thresholds", killed_at_the_second)
        with pytest.raises(KeyboardInterrupt):
            calibrate("pymunk", "thresholds", validation=vs, space={"dt": [2e-3]}, scene=scenes)
        (first_scene,) = seen
        seen.clear()
        monkeypatch.setattr(module, "_thresholds", counted)
        cal = calibrate("pymunk", "thresholds", validation=vs, space={"dt": [2e-3]},
                        scene=scenes)
    finally:
        runs.activate(previous)
    assert seen == ["fig11_mu1"]  # the finished scene is not measured again
    (ev,) = cal.evaluations
    assert ev.from_store  # its costs are partly those measured before the kill
    assert [(f"fig5: {label}", err) for label, err in first_scene[0]] == \
        [e for e in ev.errors if e[0].startswith("fig5: ")]
    assert {e[0].split(":")[0] for e in ev.errors} == {"fig5", "fig11_mu1"}


def test_a_validation_set_of_several_scenes_takes_the_worst_over_all(tmp_path, capsys):
    import json
    out = tmp_path / "cal.json"
    # A glob and a name it already matched: two scenes, each once, in order.
    code = main(["calibrate", "--engine", "pymunk", "--scene", "fig11_mu[12]", "--scene",
                 "fig11_mu1", "--metric", "histories", "--dt", "2e-3", "--step-only",
                 "--no-cache", "--json", str(out)])
    assert code in (0, 1)  # 1: no candidate met the tolerance (a verdict, not an error)
    doc = json.loads(out.read_text())
    assert doc["validation"]["scene"] == ["fig11_mu1", "fig11_mu2"]
    (ev,) = doc["evaluations"]
    labels = [label for label, _ in ev["errors"]]
    assert {label.split(":")[0] for label in labels} == {"fig11_mu1", "fig11_mu2"}
    assert len(labels) == 16  # A-D, with and without the pendulum, per scene
    assert ev["worst_error"] == max(err for _, err in ev["errors"])
    assert ev["runs"] == 16


def test_a_settings_file_is_the_base_every_candidate_starts_from(tmp_path, capsys):
    base = tmp_path / "base.toml"
    base.write_text(settings_toml("pymunk", {"iterations": 60}, "a base"))
    out = tmp_path / "out.toml"
    code = main(["calibrate", "--engine", "pymunk", "--settings", str(base), "--metric",
                 "histories", "--dt", "2e-3", "--step-only", "--tolerance", "1", "--no-cache",
                 "--settings-out", str(out)])
    assert code == 0  # tolerance 1: every candidate is acceptable, one is written
    # The file written is complete: the base's value kept beside the step searched,
    # and the command that regenerates it names the base.
    assert load_settings_file(out) == {"pymunk": {"iterations": 60, "dt": 2e-3}}
    assert f"--settings {base}" in out.read_text()
    # A file with nothing for the engine calibrated changes nothing: refused.
    other = tmp_path / "other.toml"
    other.write_text(settings_toml("mujoco", {"dt": 1e-3}, "not pymunk"))
    assert main(["calibrate", "--engine", "pymunk", "--settings", str(other), "--no-cache"]) == 2
    assert "has no table for pymunk" in capsys.readouterr().err


def test_a_scene_glob_that_matches_nothing_is_refused(capsys):
    assert main(["calibrate", "--engine", "pymunk", "--scene", "fig99_*", "--no-cache"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scene: 'fig99_*' matches no scene" in err[0]


@pytest.mark.parametrize("engine", engines.engine_names())
def test_declared_search_ranges_are_valid_settings_around_the_defaults(engine):
    # calibrate's default space: the step times 1, 2, 5, 10 and the engine's own
    # declared ranges; each value must be one its Settings accept, the calibrated
    # default among them (so the search can answer "keep the defaults").
    import dataclasses

    from trilith_xval import engines
    from trilith_xval.compare.campaign.calibrate import MAX_CANDIDATES, default_space
    space = default_space(engine)
    defaults = engines.configure(engine)
    for name, values in space.items():
        if name == "dt":
            continue
        assert getattr(defaults, name) in values, (engine, name)
        for v in values:
            assert getattr(engines.configure(engine, **{name: v}), name) == v
    assert math.prod(len(v) for v in space.values()) <= MAX_CANDIDATES
    assert set(space) <= {f.name for f in dataclasses.fields(defaults)}


def test_the_pareto_plot_keys_its_points_by_the_settings_that_vary(tmp_path):
    from trilith_xval.compare.campaign.calibrate import Calibration
    from trilith_xval.compare.report.calibration_plot import _label, _varied, pareto_plot

    def ev(dt, iters, err, cpu):
        return Evaluation({"dt": dt, "iterations": iters, "slop_fraction": 1e-4}, err, (),
                          cpu, 2.0 * cpu, 1.0, 1)
    evs = [ev(1e-4, 30, 0.004, 8.0), ev(5e-4, 30, 0.009, 2.0), ev(5e-4, 60, 0.008, 2.1),
           ev(2e-3, 30, math.inf, 0.6)]  # the last: no bracket somewhere
    cal = Calibration("pymunk", "test", "thresholds", 0.01, ValidationSet(omegas=(12.0,)), evs)
    # slop_fraction is the same in every candidate: it would only lengthen each key
    assert _varied(evs) == ["dt", "iterations"]
    assert _label(evs[1], _varied(evs)) == "dt 0.0005, iterations 30"
    assert _varied(evs[:1]) == ["dt", "iterations", "slop_fraction"]
    out = tmp_path / "front.png"
    pareto_plot(cal, out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_pareto_plot_draws_on_the_given_axes(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from trilith_xval.compare.campaign.calibrate import Calibration
    from trilith_xval.compare.report.calibration_plot import pareto_plot
    evs = [Evaluation({"dt": dt}, err, (), cpu, 2.0 * cpu, 1.0, 1)
           for dt, err, cpu in ((1e-4, 0.004, 8.0), (5e-4, 0.009, 2.0))]
    cal = Calibration("pymunk", "test", "thresholds", 0.01, ValidationSet(omegas=(12.0,)), evs)
    fig, (left, right) = plt.subplots(1, 2)
    assert pareto_plot(cal, ax=right) is right
    assert not left.has_data() and right.has_data()
    assert right.get_xscale() == "log" and "worst error" in right.get_ylabel()
    out = tmp_path / "two.png"
    assert pareto_plot(cal, out, ax=left) is left  # the caller's figure, written
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    plt.close(fig)


def test_every_candidate_runs_its_run_spec(monkeypatch):
    """A candidate's releases run one RunSpec each: the engine's defaults, the
    base, then the candidate's own values, on each release's scene with no base
    motion (the free-rocking measurement is a stand-in here)."""
    import types

    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.measure import restitution
    from trilith_xval.compare.run.spec import RunSpec
    seen = []

    def stand_in(run, theta0=None, n_impacts=4, psi0=0.0, restitution_factor=1.0):
        seen.append(run)
        return types.SimpleNamespace(max_rel_error=0.001, complete=True,
                                     diagnostics={"cpu_time": 0.1, "steps": 10},
                                     settings={"dt": run.settings.dt})
    monkeypatch.setattr(restitution, "free_rocking", stand_in)
    vs = ValidationSet(releases=((3.0, 1.0),), n_impacts=2)
    cal = calibrate("pymunk", "restitution", validation=vs, space={"dt": [5e-4, 1e-3]},
                    base={"iterations": 20})
    assert [e.options for e in cal.evaluations] == [{"dt": 5e-4}, {"dt": 1e-3}]
    # Each candidate: the lam-3 release and the scene itself (with its pendulum).
    assert len(seen) == 4 and all(isinstance(r, RunSpec) for r in seen)
    for run, dt in zip(seen, (5e-4, 5e-4, 1e-3, 1e-3)):
        assert isinstance(run.excitation, Still)
        assert run.settings == engines.configure("pymunk", iterations=20, dt=dt)
        assert set(dict(run.origin).values()) == {"the candidate settings"}
    assert seen[0].scene.lam == 3.0 and not seen[0].scene.has_pendulum
    assert seen[1].scene.has_pendulum
