"""Shared fixtures: the paper's Fig. 5 scene (with and without pendulum), a cached
accurate-simulator run (several tests look at the same trajectories), and ``no_work``
(every entry point that does real work fails the test: checks at the door)."""
from __future__ import annotations

import atexit
import functools
import os
import shutil
import tempfile

import pytest

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.parameters import Scene
from trilith_xval.scenes import load_scene

# Every CLI run of the suite (in process or a subprocess) uses a throwaway run
# store, never the user's cache.
os.environ["TRILITH_CACHE"] = tempfile.mkdtemp(prefix="trilith-test-cache-")
atexit.register(shutil.rmtree, os.environ["TRILITH_CACHE"], True)


@pytest.fixture(scope="session")
def fig5() -> Scene:
    """lam = 5, b = 0.6 m, gamma = 0.3, mu = 1, l = 2h/3 (the paper's Fig. 5)."""
    return load_scene("fig5")


@pytest.fixture(scope="session")
def fig5_bare(fig5) -> Scene:
    """The Fig. 5 trilith without its pendulum (gamma = 0)."""
    return fig5.without_pendulum()


@functools.lru_cache(maxsize=64)
def _cached_run(scene: Scene, amplitude: float, omega: float, kind: str,
                t_max: float | None, criterion: str):
    from trilith_xval.analytic.simulate import Settings, simulate
    from trilith_xval.analytic.trajectory import OverturnCriterion
    settings = Settings(t_max=t_max, criterion=OverturnCriterion(criterion))
    return simulate(scene, Pulse(amplitude, omega, kind), settings)


@pytest.fixture(scope="session")
def run_analytic():
    """``run_analytic(scene, A, Omega, kind='sine', t_max=None, criterion='topple')``:
    an accurate-path Trajectory, cached per session (treat it as read-only)."""
    def run(scene: Scene, amplitude: float, omega: float, kind: str = "sine",
            t_max: float | None = None, criterion: str = "topple"):
        return _cached_run(scene, float(amplitude), float(omega), kind, t_max, criterion)
    return run


class WorkStarted(AssertionError):
    pass


@pytest.fixture
def no_work(monkeypatch):
    """Make every entry point that does real work fail the test."""
    import trilith_xval.analytic.fast
    import trilith_xval.analytic.simulate
    import trilith_xval.analytic.spectrum
    import trilith_xval.compare.campaign.validation
    import trilith_xval.compare.cli.bench
    import trilith_xval.compare.cli.record
    import trilith_xval.compare.cli.view
    import trilith_xval.compare.measure.restitution
    import trilith_xval.compare.report.figures
    import trilith_xval.engines.base
    from trilith_xval import analytic, compare, engines

    def boom(*args, **kwargs):
        raise WorkStarted("work started before the input was checked")

    for module, name in ((analytic.simulate, "simulate"), (analytic.fast, "simulate"),
                         (engines.base.Engine, "run"),  # every registered engine
                         (analytic.spectrum, "overturning_spectrum"),
                         (compare.campaign.validation, "run_campaign"), (compare.report.figures, "make_figures"),
                         (compare.cli.record, "record"), (compare.cli.view, "view"),
                         (compare.cli.bench, "_load_bench"),
                         (compare.measure.restitution, "measure_restitution")):
        monkeypatch.setattr(module, name, boom)
