"""The engines' run monitor (engines/_common.py) on synthetic samples."""
from __future__ import annotations

from analytic import OverturnCriterion, Pulse, Scene
from engines._common import RunMonitor
from engines.base import EngineSettings


def test_columns_out_of_step_is_a_collapse():
    """The lintel ties the columns together; engines keep them within ~1e-5 rad.
    A mismatch of half alpha while standing is a broken linkage, not data."""
    scene = Scene()
    mon = RunMonitor(scene, Pulse(3.0, 6.0), EngineSettings(criterion=OverturnCriterion(), t_max=1.0))
    assert not mon.record(0.0, 0.0, 0.0, 0.0)
    assert not mon.record(0.001, 1e-5, -1e-5, 0.0)  # engine noise: fine
    assert mon.record(0.002, 0.25 * scene.alpha, -0.25 * scene.alpha, 0.0)
    assert mon.verdict.status == "collapsed"  # the frame broke: never 'overturned'
    assert "out of step" in mon.verdict.reason


def test_mismatch_ignored_without_lintel():
    """mu = 0, no pendulum: no lintel body, the columns rock independently."""
    scene = Scene(mu=0.0, gamma=0.0)
    mon = RunMonitor(scene, Pulse(3.0, 6.0), EngineSettings(criterion=OverturnCriterion(), t_max=1.0))
    assert not mon.record(0.002, 0.25 * scene.alpha, -0.25 * scene.alpha, 0.0)


def test_overturn_threshold_and_mode():
    scene = Scene(gamma=0.0)
    crit = OverturnCriterion()
    mon = RunMonitor(scene, Pulse(20.0, 10.0), EngineSettings(criterion=crit, t_max=None))
    assert not mon.record(0.01, 0.01, 0.01, 1.0)
    assert not mon.record(0.02, -0.01, -0.01, -1.0)  # sign change: an impact
    assert mon.record(0.5, 1.6, 1.6, -3.0)
    assert mon.verdict.overturned and mon.verdict.mode == "after-impact"
