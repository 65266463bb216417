"""The engines' run monitor (engines/_common.py) on synthetic samples."""
from __future__ import annotations

from trilith_xval.analytic import OverturnCriterion, Pulse, Scene
from trilith_xval.engines.monitor import RunMonitor
from trilith_xval.engines.base import EngineSettings


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


def test_overturn_certain_rules_after_the_pulse():
    """Without a pendulum, past alpha after the pulse and moving outwards is a
    certain fall; moving back inwards with energy above the barrier is not (it can
    cross alpha again).  With a pendulum only the energy rule applies."""
    from trilith_xval.analytic import equations as eq

    bare = Scene(gamma=0.0)
    a = bare.alpha
    pulse = Pulse(20.0, 10.0)  # ends at 0.628 s
    probe = RunMonitor(bare, pulse, EngineSettings(verdict_only=True))
    assert not probe.record(0.5, 1.2 * a, 1.2 * a, 2.0)  # during the pulse: never certain
    fast_in = -3.0  # rad/s back towards alpha: energy far above the barrier
    args = bare.model_args()
    assert eq.energy(1.2 * a, fast_in, 0.0, 0.0, 1, *args) > eq.overturn_energy_barrier(
        *args[:4], args[6])
    assert not probe.record(0.7, 1.2 * a, 1.2 * a, fast_in)
    assert probe.record(0.8, 1.3 * a, 1.3 * a, 0.5)  # outwards: certain
    assert probe.verdict.status == "overturned" and "certain" in probe.verdict.reason

    pend = Scene()
    with_pendulum = RunMonitor(pend, pulse, EngineSettings(verdict_only=True))
    assert not with_pendulum.record(0.7, 1.2 * pend.alpha, 1.2 * pend.alpha, 3.0)


def test_a_fixed_window_ignores_a_certain_fall():
    """With ``t_max`` fixed, a run is 'overturned' only if the threshold is reached
    inside the window (the model's fixed-window convention, analytic/simulate.py):
    a fall that became certain is not called before the threshold, and a window
    that ends mid-fall is 'survived' by that convention, as the model would say."""
    bare = Scene(gamma=0.0)
    a = bare.alpha
    pulse = Pulse(20.0, 10.0)  # ends at 0.628 s
    window = RunMonitor(bare, pulse, EngineSettings(verdict_only=True, t_max=0.9,
                                                    early_stop=False))
    assert not window.record(0.8, 1.3 * a, 1.3 * a, 0.5)  # certain, but not decided
    assert window.certain_at == 0.8
    assert window.record(0.9, 2.0 * a, 2.0 * a, 1.0)  # the window ends mid-fall
    assert window.verdict.status == "survived" and "end of run" in window.verdict.reason
