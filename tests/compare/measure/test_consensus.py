"""Where the model is invalid the engines are checked against each other: each
engine's own first failure, converged in the step, their median and named
outliers; never called agreement with the model."""
from __future__ import annotations

import math

import pytest

from trilith_xval.compare.measure import consensus as cs
from trilith_xval.compare.measure import thresholds as thr
from trilith_xval.compare.measure.engine_spectrum import point_spec
from trilith_xval.compare.measure.thresholds import Probe
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.scenes import load_scene


def _own(a, failure="overturned", dt=1e-4):
    return {"converged": a is not None, "a_fails": a, "failure": failure, "dt": dt,
            "cause": None if a is not None else "step", "detail": ""}


def test_the_median_and_the_outlier_named_with_its_cause():
    owns = {"a": _own(10.0), "b": _own(10.1), "c": _own(10.9), "d": _own(None)}
    c = cs.consensus(owns, {"c": "sliding"})
    assert c["status"] == "consensus" and c["median"] == pytest.approx(10.1)
    assert [o["engine"] for o in c["outliers"]] == ["c"]
    assert c["outliers"][0]["cause"] == "sliding"
    assert c["outliers"][0]["deviation"] == pytest.approx(0.8 / 10.1)
    assert [n["engine"] for n in c["no_answer"]] == ["d"]  # not in the median


def test_two_engines_apart_name_no_outlier_and_one_is_no_consensus():
    two = cs.consensus({"a": _own(10.0), "b": _own(10.5)})
    assert two["status"] == "disagree" and two["outliers"] == []
    assert cs.consensus({"a": _own(10.0), "b": _own(10.1)})["status"] == "consensus"
    assert cs.consensus({"a": _own(10.0), "b": _own(None)})["status"] == "one engine"
    assert cs.consensus({"a": _own(None)})["status"] == "none"


def _fake_engine(monkeypatch, failing):
    """An engine whose run fails ('collapsed' above 30 m/s^2, else 'overturned') at
    ``failing(dt)`` m/s^2: the search itself runs as on a real engine."""
    def fake(backend, scene, omega, amplitude, settings=None, kind="sine"):
        a = failing(settings.dt)
        status = ("collapsed" if a > 30.0 else "overturned") if amplitude >= a else "survived"
        return Probe(amplitude, status, None, cpu_s=0.0, sim_s=1.0)
    monkeypatch.setattr(thr, "overturns", fake)


@pytest.fixture
def spec():
    scene = load_scene("fig5")
    return point_spec(RunSpec.resolve("pymunk", scene, overrides={"dt": 1e-4}), scene, 12.0,
                      20.0, "sine", cs.FAILURE_SEARCH)


def test_converged_when_two_steps_agree_within_one_percent(monkeypatch, spec):
    # Error proportional to the step: 2e-4 s is 2 % high, 1e-4 s 1 %: 0.99 % apart.
    _fake_engine(monkeypatch, lambda dt: 20.0 * (1.0 + 100.0 * dt))
    own = cs.own_threshold(spec, 12.0, 20.0)
    assert own["converged"] and own["dt"] == pytest.approx(1e-4)
    assert own["a_fails"] == pytest.approx(20.2, rel=5e-3)  # the finer step's bracket
    assert [r["dt"] for r in own["steps"]] == pytest.approx([2e-4, 1e-4])


def test_a_coarse_step_is_refined_and_a_step_that_never_settles_has_no_answer(
        monkeypatch, spec):
    _fake_engine(monkeypatch, lambda dt: 20.0 * (1.0 + 300.0 * dt))  # 3 %, 6 % ...
    own = cs.own_threshold(spec, 12.0, 20.0)
    assert own["converged"] and own["dt"] == pytest.approx(2.5e-5)  # 0.75 % from 5e-5 s
    _fake_engine(monkeypatch, lambda dt: 20.0 * (1.0 + 0.05 * math.log2(1e-3 / dt)))
    own = cs.own_threshold(spec, 12.0, 20.0)
    assert not own["converged"] and own["cause"] == "step" and own["a_fails"] is None


def test_a_collapse_is_a_failure_recorded_as_such(monkeypatch, spec):
    _fake_engine(monkeypatch, lambda dt: 33.0)  # far above the guess: the search widens
    own = cs.own_threshold(spec, 12.0, 20.0)
    assert own["converged"] and own["failure"] == "collapsed"
    assert own["a_fails"] == pytest.approx(33.0, rel=5e-3)


@pytest.mark.slow
def test_where_the_lintel_hops_pymunk_and_mujoco_agree_with_each_other():
    """Fig. 8 (lam 3, gamma 0.1) at Omega 20 with the pendulum: the model's lintel
    would have to be pulled down (invalid), its number 53.3 m/s^2.  Each engine's
    own failure, converged in its step, is ~56.2 m/s^2, 5 % above the model's
    invalid number: Pymunk and MuJoCo agree with each other within the 2 %
    outlier tolerance (measured 2026-11-28: 56.06 and 56.35 m/s^2, 2 CPU s)."""
    from trilith_xval.compare.campaign.study import _scene
    scene = _scene("fig8_lam3_gamma0.1", "pendulum")
    owns = {e: cs.own_threshold(point_spec(RunSpec.resolve(e, scene, calibrated=True), scene,
                                           20.0, 53.31, "sine", cs.FAILURE_SEARCH),
                                20.0, 53.31) for e in ("pymunk", "mujoco")}
    assert all(o["converged"] for o in owns.values()), owns
    c = cs.consensus(owns)
    assert c["status"] == "consensus"
    assert max(abs(v["deviation"]) for v in c["engines"].values()) <= cs.OUTLIER_TOL
    assert c["median"] > 1.02 * 53.31  # not the model's number: the model is invalid here
