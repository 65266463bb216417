"""Engine spectra and the cause classifier: the CLI on a small grid, robust brackets,
causes evaluated all, independent of the frequency grid."""
from __future__ import annotations

import json

import numpy as np
import pytest

from trilith_xval import engines
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.spectrum import SpectrumSettings, overturning_spectrum
from trilith_xval.compare.measure import causes
from trilith_xval.compare.measure import engine_spectrum as es
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.compare.campaign.settings_file import threshold_options
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_scene


def _without_costs(obj):
    """The document without what a rerun measures anew (CPU and wall seconds)."""
    if isinstance(obj, dict):
        return {k: _without_costs(v) for k, v in obj.items()
                if "cpu" not in k and k not in ("cost", "wall_time", "provenance")}
    if isinstance(obj, list):
        return [_without_costs(v) for v in obj]
    return obj


@pytest.fixture(scope="module")
def fig5_ref():
    scene = load_scene("fig5")
    return scene, overturning_spectrum(scene, np.array([12.0, 14.0]), SpectrumSettings())


@pytest.mark.slow
def test_brackets_are_honest_when_rerun_independently(fig5_ref):
    """The engine overturns at a_engine and survives at a_survives, rerun from scratch
    with the calibrated settings (not through the bisection's own probes)."""
    scene, ref = fig5_ref
    out = es.engine_spectrum(RunSpec.resolve("pymunk", scene), ref, workers=1)
    assert set(out.curves) == {"pendulum", "no_pendulum"}
    for curve, points in out.curves.items():
        sc = scene if curve == "pendulum" else scene.without_pendulum()
        for p in points:
            assert p.a_survives < p.a_engine <= p.a_survives + es.DEFAULT_REL_TOL * p.a_reference * 1.01
            settings = es.pulse_settings("pymunk", sc, 2.2 * p.a_reference, p.omega)
            # Robust ends, rerun from scratch: the neighbours 2e-4 outside agree too.
            for a, status in ((p.a_engine, "overturned"), (p.a_engine * 1.0002, "overturned"),
                              (p.a_survives, "survived"), (p.a_survives * 0.9998, "survived")):
                run = engines.simulate("pymunk", sc, Pulse(a, p.omega), settings)
                assert run.verdict.status == status, (curve, p.omega, a, run.verdict)
            assert p.cause in es.CAUSES and p.valid is not None


@pytest.mark.slow
def test_cli_engine_spectrum_json_csv_plot(tmp_path, capsys):
    csv, png = tmp_path / "s.csv", tmp_path / "s.png"
    # Two engines (the two cheapest; the document's shape does not depend on which).
    code = main(["spectrum", "--engine", "pymunk,mujoco", "--omega", "13:14:1", "--json",
                 "--csv", str(csv), "--plot", str(png), "--workers", "2", "--no-cache"])
    assert code == 0
    text = capsys.readouterr().out
    doc = json.loads(text)
    assert doc["schema_version"] and doc["inputs"]["engine"] == ["pymunk", "mujoco"]
    assert set(doc["engine_version"]) == {"analytic", "pymunk", "mujoco"}
    assert list(doc)[-1] == "timings"  # wall times apart from the results
    assert set(doc["engines"]) == {"pymunk", "mujoco"}
    # A rerun gives the same document up to the costs (the run store is off).
    assert main(["spectrum", "--engine", "pymunk,mujoco", "--omega", "13:14:1", "--json",
                 "--no-cache", "--workers", "2"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert _without_costs(again["engines"]) == _without_costs(doc["engines"])
    for name, spec in doc["engines"].items():
        # The threshold searches' calibrated step (else the engine's own), carried in the JSON.
        fig5 = load_scene("fig5")
        assert spec["settings"]["dt"] == threshold_options(name, fig5).get(
            "dt", engines.configure(name).dt)
        for key in ("pendulum", "no_pendulum"):
            for p in spec["curves"][key]:
                for field in ("omega", "a_reference", "a_engine", "a_survives", "rel_error",
                              "rel_resolution", "isolated", "cause", "causes", "valid",
                              "cpu_s", "mode_reference", "mode_engine", "n_runs"):
                    assert field in p
        assert spec["cost"]["cpu_s"] > 0 and spec["cost"]["points_from_store"] == 0
    rows = csv.read_text().splitlines()
    assert rows[0].startswith("engine,curve,omega") and len(rows) == 1 + 2 * 2 * 2
    assert png.stat().st_size > 10_000


def test_cli_engine_spectrum_bad_input(capsys):
    assert main(["spectrum", "--engine", "bullet", "--omega", "13"]) == 2
    assert "unknown engine 'bullet'" in capsys.readouterr().err
    assert main(["spectrum", "--engine", "pymunk", "--dt", "0.5", "--omega", "13"]) == 2
    assert "--dt" in capsys.readouterr().err
    assert main(["spectrum", "--dt", "1e-4", "--omega", "13"]) == 2
    assert "need --engine" in capsys.readouterr().err


def _point(a_eng, a_surv, a_ref=20.0, omega=12.0, probes=()):
    from trilith_xval.compare.measure.thresholds import ThresholdPoint
    from trilith_xval.compare.measure.trajectories import Provenance
    return ThresholdPoint(omega, "sine", a_ref, a_eng, a_surv, None, None, 5, 0, 5e-3,
                          Provenance("pymunk", "", 1e-4, {}, 0.0), tuple(probes))


@pytest.fixture
def valid_model(monkeypatch):
    """The model valid everywhere, no jump, no island (the engine side under test)."""
    monkeypatch.setattr(causes, "model_validity", lambda scene, omega, kind, amps, friction: [
        {"amplitude": a, "where": w, "valid": True, "reason": ""} for w, a in amps.items()])
    monkeypatch.setattr(causes, "model_jump", lambda *a, **k: None)
    monkeypatch.setattr(causes, "model_island", lambda *a, **k: None)
    monkeypatch.setattr(causes, "contact_detail", lambda *a, **k: "pivot_sliding_max = 1e-3")


def test_cause_contact_when_the_error_shrinks_with_nothing(monkeypatch, valid_model):
    """-5 % at dt, dt/2, dt/4 and with doubled iterations: contact, every rerun listed."""
    monkeypatch.setattr(causes, "engine_threshold", lambda *a, **k: _point(19.0, 18.9))
    c = causes.classify("pymunk", load_scene("fig5"), 12.0, _point(19.0, 18.9),
                        engines.configure("pymunk"))
    assert c.cause == "contact" and "pivot_sliding_max" in c.detail and c.valid is True
    assert [(r["kind"], r["dt"]) for r in c.convergence] == [
        ("dt", 1e-4), ("dt", 5e-5), ("dt", 2.5e-5), ("iterations", 1e-4)]
    assert c.convergence[3]["iterations"] == 2 * engines.configure("pymunk").solver_iterations


def test_iterations_and_step_are_told_apart(monkeypatch, valid_model):
    """Doubled iterations at the same step meet the tolerance, finer steps do not: the
    cause is 'iterations', not a step the reruns never took."""
    calls = []

    def fake(engine, scene, omega, a_ref, settings, **k):
        calls.append(settings)
        doubled = settings.solver_iterations > engines.configure("pymunk").solver_iterations
        return _point(20.02, 19.95) if doubled else _point(19.0, 18.9)
    monkeypatch.setattr(causes, "engine_threshold", fake)
    c = causes.classify("pymunk", load_scene("fig5"), 12.0, _point(19.0, 18.9),
                        engines.configure("pymunk"))
    assert c.cause == "iterations" and [x["name"] for x in c.causes] == ["iterations"]


def test_collapse_where_the_model_holds_is_the_engine(valid_model):
    """The frame collapses below the model's threshold where the model is valid (PyBullet,
    Omega 21 with pendulum: collapse from 49.37 m/s^2, model invalid only at its own 50.89):
    the cause is the collapse, however invalid the model is higher up."""
    from trilith_xval.compare.measure.thresholds import Probe
    probes = (Probe(49.37, "collapsed", None), Probe(50.0, "collapsed", None))
    p = _point(float("nan"), float("nan"), a_ref=50.89, omega=21.0, probes=probes)
    c = causes.classify("pybullet", load_scene("fig5"), 21.0, p, engines.configure("pybullet"))
    assert c.cause == "collapse" and {x["name"] for x in c.causes} == {"collapse", "no-bracket"}


def test_model_blamed_only_at_the_decisive_amplitude():
    """Real model checks, Fig. 5 with pendulum, Omega 21: the lintel lifts (-0.01 of its
    weight) at the model's 50.89 m/s^2 but presses (+0.046) at 49.37."""
    scene = load_scene("fig5")
    rows = causes.model_validity(scene, 21.0, "sine", {"low": 49.37, "model": 50.89}, None)
    assert rows[0]["valid"] and not rows[1]["valid"] and "lintel" in rows[1]["reason"]


def test_cause_model_where_the_lintel_would_be_thrown_off():
    """Omega 24 with the pendulum: the model's own threshold is 64.66 m/s^2, where its
    lintel normal force is negative (about -0.3 of the weight, docs/model.md), and the
    engine overturns above it: the cause is the model's assumption, not the engine."""
    scene = load_scene("fig5")
    c = causes.classify("pymunk", scene, 24.0, _point(66.4, 66.0, 64.66, 24.0),
                        engines.configure("pymunk"), convergence=False)
    assert c.cause == "model" and "lintel" in c.detail and "64.66" in c.detail
    assert c.valid is False


def test_cause_window_where_the_model_survives_again():
    """Omega 9 with the pendulum: the model overturns from 5.64 m/s^2, survives again
    at 5.82-5.92 and overturns from 5.94 (fast path, 0.02 steps); Pymunk and MuJoCo
    both first overturn at 5.95 (measured 2026-11-23): the next onset, a window."""
    scene = load_scene("fig5")
    c = causes.classify("pymunk", scene, 9.0, _point(5.952, 5.93, 5.6417, 9.0),
                        engines.configure("pymunk"), convergence=False)
    assert c.cause == "window", c.detail
    assert "safe island" in c.detail and c.convergence == ()


def test_jump_is_located_on_the_model_not_the_grid():
    """Fig. 5 with pendulum: the mode changes (after-impact -> no-impact) between
    Omega 10.25 and 10.5; seen from 10.4 it is found and located, from 12 it is not."""
    scene = load_scene("fig5")
    found = causes.model_jump(scene, 10.4, "sine", 12.0, 0.02)
    assert found is not None and "after-impact to no-impact" in found
    omega_jump = float(found.split("Omega = ")[1].split(" ")[0])
    assert 10.25 < omega_jump < 10.51  # 10.5 itself: no-impact, 16.2 m/s^2
    assert causes.model_jump(scene, 12.0, "sine", 20.0, 0.02) is None


def test_same_point_same_cause_with_any_grid(monkeypatch):
    """Three grids around Omega 12 (no pendulum): the point's causes come
    from the point and the model, never from its neighbours on the grid.  The engine is
    a fake that overturns 3 % low at every frequency (no engine run)."""
    from trilith_xval.compare.measure import thresholds as thr
    from trilith_xval.compare.measure.thresholds import Probe
    bare = load_scene("fig5").without_pendulum()

    def fake(backend, scene, omega, amplitude, settings=None, kind="sine"):
        from trilith_xval.analytic.first_overturn import first_overturn_amplitude
        a_ref = _REF.setdefault(omega, first_overturn_amplitude(scene, omega,
                                                                SpectrumSettings())[0])
        over = amplitude >= 0.97 * a_ref
        return Probe(amplitude, "overturned" if over else "survived", None)
    monkeypatch.setattr(thr, "overturns", fake)
    monkeypatch.setattr(causes, "contact_detail", lambda *a, **k: "fake engine")
    seen = []
    for grid in ([12.0, 23.0, 25.0], [11.0, 12.0, 13.0], [10.0, 12.0, 19.0]):
        ref = overturning_spectrum(bare, np.array(grid), SpectrumSettings())
        out = es.engine_spectrum(RunSpec.resolve("pymunk", bare), ref, workers=1,
                                 convergence=True)
        (p,) = [q for q in out.curves["no_pendulum"] if q.omega == 12.0]
        seen.append((p.cause, tuple(c["name"] for c in p.causes), round(p.rel_error, 6)))
    assert seen[0] == seen[1] == seen[2] and seen[0][0] == "contact", seen


_REF: dict = {}
