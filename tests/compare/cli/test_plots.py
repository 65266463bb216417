"""The plots a cross-validation user expects: an engine's theta(t) over the model's
with both runs' events, g/Hz twin axes on engine spectrum plots, and plotting
functions that take matplotlib's ``ax=``."""
from __future__ import annotations

from types import SimpleNamespace as NS

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from trilith_xval import engines  # noqa: E402
from trilith_xval.analytic import Pulse  # noqa: E402
from trilith_xval.compare.cli.main import main  # noqa: E402
from trilith_xval.compare.show.history import EVENT_MARKERS, plot_psi, plot_theta  # noqa: E402
from trilith_xval.scenes import load_scene  # noqa: E402


@pytest.fixture
def saved(monkeypatch):
    """The figures the CLI saves, kept open for inspection."""
    import trilith_xval.compare.run.atomic as atomic
    figures = []
    monkeypatch.setattr(atomic, "savefig", lambda fig, *a, **k: figures.append(fig))
    yield figures
    for fig in figures:
        plt.close(fig)


def _line(ax, label):
    return next(line for line in ax.get_lines() if line.get_label() == label)


def test_engine_plot_overlays_the_model_with_both_runs_events(saved, tmp_path):
    args = ["simulate", "-A", "10", "-w", "9", "--no-pendulum", "--plot", str(tmp_path / "p.png")]
    assert main([*args, "--engine", "pymunk"]) == 0
    (fig,) = saved
    ax = fig.axes[0]
    scene = load_scene("fig5").without_pendulum()
    model = engines.simulate("analytic", scene, Pulse(amplitude=10.0, omega=9.0))
    drawn = _line(ax, "model (analytic)")
    np.testing.assert_array_equal(drawn.get_xdata(), model.t)  # the model's own run
    np.testing.assert_allclose(drawn.get_ydata(), model.theta / scene.alpha, rtol=1e-15)
    engine = _line(ax, "pymunk")
    assert len(engine.get_xdata()) != len(model.t)  # the engine's samples, not a copy
    labels = ax.get_legend_handles_labels()[1]
    assert {"model (analytic)", "pymunk", "impact", "overturn"} <= set(labels)
    # Each run's overturn is marked at its own overturn_time, in its colour.
    marks = [line for line in ax.get_lines() if line.get_marker() == EVENT_MARKERS[
        "overturn"][0] and len(line.get_xdata()) == 1]
    times = sorted(float(m.get_xdata()[0]) for m in marks)
    assert len(times) == 2 and model.overturn_time in times
    assert "overturn_time" in ax.get_title()


def test_model_plot_has_one_run(saved, tmp_path):
    assert main(["simulate", "-A", "10", "-w", "9", "--plot", str(tmp_path / "p.png")]) == 0
    (fig,) = saved
    runs = [line for line in fig.axes[0].get_lines() if len(line.get_xdata()) > 1
            and not line.get_label().startswith("_")]
    assert [line.get_label() for line in runs] == ["model (analytic)"]
    assert len(fig.axes) == 2  # theta, and psi for the pendulum


def test_plot_functions_draw_on_the_given_axes():
    scene = load_scene("fig5")
    traj = engines.simulate("analytic", scene, Pulse(amplitude=19.0, omega=15.0))
    fig, (a, b) = plt.subplots(2, 1)
    assert plot_theta(traj, scene.alpha, ax=a) is a
    assert plot_psi([traj], ax=b) is b
    assert len(fig.axes) == 2 and a.get_lines() and b.get_lines()
    assert "impact" in a.get_legend_handles_labels()[1]
    own = plot_theta([traj, traj], scene.alpha, labels=["one", "two"], events=False)
    assert own.figure is not fig and {"one", "two"} <= set(own.get_legend_handles_labels()[1])
    plt.close("all")


@pytest.mark.parametrize("call, error", [
    (lambda tr: plot_theta(tr, 0.0), ValueError),
    (lambda tr: plot_theta(tr, True), ValueError),
    (lambda tr: plot_theta([], 0.2), TypeError),
    (lambda tr: plot_theta("theta", 0.2), TypeError),
    (lambda tr: plot_theta([tr], 0.2, labels=["a", "b"]), ValueError),
    (lambda tr: plot_psi([tr, tr], labels=["a"]), ValueError),
])
def test_plot_functions_refuse_bad_input(call, error):
    traj = engines.simulate("analytic", load_scene("fig5"), Pulse(amplitude=5.0, omega=10.0))
    with pytest.raises(error):
        call(traj)
    plt.close("all")


def test_engine_spectrum_plot_has_g_and_hz_axes(monkeypatch, tmp_path):
    from matplotlib.figure import Figure

    from trilith_xval.compare.measure import engine_spectrum_files as files
    figures = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: figures.append(fig))
    point = NS(omega=10.0, a_engine=5.6, a_reference=5.5, rel_error=0.018, cause="agrees")
    reference = NS(omega=[10.0], a_pendulum=[6.0], a_no_pendulum=[5.5],
                   mode_jumps=lambda: [], settings=NS(pulse="sine"),
                   scene=NS(lam=5.0, b=0.6, gamma=0.3, mu=1.0))
    files.plot(reference, [NS(engine="toy", curves={"no_pendulum": [point]})],
               tmp_path / "e.png")
    top = figures[0].axes[0]
    twins = {(c.get_xlabel(), c.get_ylabel()) for c in top.child_axes}
    assert ("", "[g]") in twins and any("Hz" in x for x, _ in twins)
    g_axis = next(c for c in top.child_axes if c.get_ylabel() == "[g]")
    figures[0].canvas.draw()  # the twin's limits follow its parent's when drawn
    # The twin is the same data in g: the left limits [m/s^2] over 9.80665.
    assert np.divide(top.get_ylim(), 9.80665) == pytest.approx(g_axis.get_ylim(), rel=1e-12)
    plt.close("all")
