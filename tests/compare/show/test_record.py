"""Drawing, recording and viewing: geometry of the drawn trilith (Eq. 5), GIF
frames read back with Pillow, the no-display path of ``view``, and the README's
``Watching a run`` commands."""
from __future__ import annotations

import math
import re
import shlex
from pathlib import Path

from tests.support.paths import ROOT

import numpy as np
import pytest
from PIL import Image, ImageSequence

import trilith_xval.compare.show.record as rec
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.trajectory import OverturnCriterion, Trajectory, Verdict
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_scene
from trilith_xval.compare.show.draw import bob_radius, trilith_shape, view_limits
from trilith_xval.compare.show.view import display_problem

README = ROOT / "README.md"
FIG5 = load_scene("fig5")
# Geometry is a few trig evaluations: equal to float rounding.
TOL = 1e-12


# --- geometry -------------------------------------------------------------------
def test_rest_shape_matches_the_scene():
    s = FIG5
    shape = trilith_shape(s, 0.0)
    left, right = shape.columns
    assert left[:, 0].min() == pytest.approx(-0.5 * s.d - s.b, abs=TOL)
    assert right[:, 0].min() == pytest.approx(0.5 * s.d, abs=TOL)
    assert left[:, 1].max() == pytest.approx(s.h, abs=TOL)
    assert shape.lintel[:, 1].min() == pytest.approx(s.h, abs=TOL)
    assert np.ptp(shape.lintel[:, 0]) == pytest.approx(2 * s.b + s.d, abs=TOL)
    assert shape.bob == pytest.approx(np.array([s.hinge_x, s.h - s.pendulum_length]), abs=TOL)


@pytest.mark.parametrize("theta", [0.2, -0.2, 1.2, -1.2])
def test_columns_rock_about_the_correct_corners(theta):
    s = FIG5
    rest = trilith_shape(s, 0.0).columns
    moved = trilith_shape(s, theta).columns
    pivot = 0 if theta > 0 else 1  # bottom-left corner for theta > 0, bottom-right for < 0
    for before, after in zip(rest, moved):
        assert after[pivot] == pytest.approx(before[pivot], abs=TOL)
        # The other bottom corner lifts by b |sin theta|: the column is rigid.
        assert after[1 - pivot][1] == pytest.approx(s.b * abs(math.sin(theta)), abs=TOL)
        edges = np.linalg.norm(np.diff(np.vstack([after, after[:1]]), axis=0), axis=1)
        assert edges == pytest.approx([s.b, s.h, s.b, s.h], abs=TOL)
    # theta > 0 is counter-clockwise: the tops move left.
    assert np.sign(moved[0][2, 0] - rest[0][2, 0]) == -np.sign(theta)


@pytest.mark.parametrize("theta", [0.15, -0.15, 0.9, -0.9])
def test_lintel_translates_as_in_eq5(theta):
    """Eq. 5: r_G3 = x_g + b3 + b cos(theta) - h sin(theta), h3 + b sin(theta) + h cos(theta)
    about the left corners; the mirror (b -> -b) about the right ones (Eq. A.1)."""
    s = FIG5
    sb = s.b if theta > 0 else -s.b
    expected = np.array([sb * math.cos(theta) - s.h * math.sin(theta) - sb,
                         sb * math.sin(theta) + s.h * math.cos(theta) - s.h])
    x_g = 0.37
    moved = trilith_shape(s, theta, 0.0, x_g).lintel
    rest = trilith_shape(s, 0.0).lintel
    assert (moved - rest) == pytest.approx(np.tile(expected + [x_g, 0.0], (4, 1)), abs=TOL)
    # It rides on the column tops: its underside is at the highest column corner.
    top = max(c[:, 1].max() for c in trilith_shape(s, theta).columns)
    assert moved[:, 1].min() == pytest.approx(top, abs=TOL)


def test_mirror_symmetry_and_pendulum():
    s = FIG5
    a = trilith_shape(s, 0.3, 0.4)
    m = trilith_shape(s, -0.3, -0.4)
    flip = np.array([-1.0, 1.0])
    # Mirroring x swaps the columns and reverses each outline's corner order.
    assert np.sort((m.columns[1] * flip)[:, 0]) == pytest.approx(np.sort(a.columns[0][:, 0]), abs=TOL)
    assert np.sort(m.lintel[:, 0] * -1) == pytest.approx(np.sort(a.lintel[:, 0]), abs=TOL)
    assert m.bob * flip == pytest.approx(a.bob, abs=TOL)
    assert np.linalg.norm(a.bob - a.hinge) == pytest.approx(s.pendulum_length, abs=TOL)
    assert a.bob[0] > a.hinge[0]  # psi > 0 is counter-clockwise from hanging: bob to the right
    assert trilith_shape(s.without_pendulum(), 0.3).bob is None


@pytest.mark.parametrize("theta, psi", [(1.5, 0.87), (-1.5, -0.9), (1.4, 0.0), (1.45, -0.3)])
def test_fallen_trilith_bob_lies_on_the_ground(theta, psi):
    """Past overturning the model's bob point is below the ground (the model has no
    bob-ground contact); it is drawn on the ground, still l from the hinge."""
    s = FIG5
    free = trilith_shape(s, theta, psi)
    hinge = free.hinge
    raw = hinge + s.pendulum_length * np.array([math.sin(psi), -math.cos(psi)])
    assert raw[1] < 0.0  # the case in point: the model's point is under the ground
    r = bob_radius(s)
    assert free.bob_grounded and free.bob[1] == pytest.approx(r, abs=TOL)
    assert np.linalg.norm(free.bob - hinge) == pytest.approx(s.pendulum_length, abs=TOL)
    assert np.sign(free.bob[0] - hinge[0]) == np.sign(math.sin(psi) or 1.0)


def test_upright_bob_is_not_moved():
    shape = trilith_shape(FIG5, 0.3, 0.8)
    assert not shape.bob_grounded


def test_lintel_only_when_there_is_one():
    # single_block: mu = 0 and no pendulum, the engines build no lintel body.
    assert trilith_shape(load_scene("single_block"), 0.1).lintel is None
    # mu = 0 with a pendulum: the (massless) lintel still carries the hinge.
    assert trilith_shape(load_scene("single_block", gamma=0.3), 0.1).lintel is not None


def test_bad_state_is_rejected():
    with pytest.raises(ValueError, match="theta"):
        trilith_shape(FIG5, math.nan)
    with pytest.raises(ValueError, match="equal length"):
        view_limits(FIG5, [0.0, 0.1], [0.0], [0.0])


# --- recording --------------------------------------------------------------------
def synthetic(backend: str, amplitude: float, t_end: float = 1.0) -> Trajectory:
    """A made-up decaying rocking history (stands in for a backend in fast tests)."""
    t = np.linspace(0.0, t_end, 201)
    theta = amplitude * np.sin(2 * np.pi * 2 * t) * np.exp(-t)
    psi = 0.3 * np.sin(2 * np.pi * t)
    return Trajectory(backend, t, theta, np.gradient(theta, t), psi, np.gradient(psi, t), (),
                      Verdict("survived"), OverturnCriterion(), t_end)


def read_gif(path) -> list[np.ndarray]:
    with Image.open(path) as im:
        return [np.asarray(frame.convert("RGB"), dtype=np.int16)
                for frame in ImageSequence.Iterator(im)]


def test_frame_times_count():
    assert rec.frame_times(2.0, 30.0).size == 60
    assert rec.frame_times(0.5, 7.0).size == 4  # round(3.5) -> 4 (banker's rounding)
    assert rec.frame_times(1.0, 10.0)[-1] == pytest.approx(0.9, abs=TOL)
    with pytest.raises(ValueError, match="at least one frame"):
        rec.frame_times(0.01, 10.0)


def test_gif_has_fps_times_duration_frames_that_change(tmp_path):
    out = tmp_path / "run.gif"
    fps, duration = 12.0, 1.5
    trajs = {"analytic": synthetic("analytic", 0.12), "pymunk": synthetic("pymunk", -0.2)}
    result = rec.record(FIG5, Pulse(4.0, 9.0), "all", out,
                        rec.RecordSettings(fps=fps, duration=duration, panel_width=160,
                                           panel_height=120), trajectories=trajs)
    frames = read_gif(out)
    assert result.n_frames == len(frames) == round(fps * duration)
    assert frames[0].shape == (120, 2 * 160, 3)  # two panels side by side
    for frame in frames:
        # Non-blank: dark outlines on a light background give a wide spread of values.
        assert frame.min() < 80 and frame.max() > 200
        assert frame.std() > 10
    diffs = [np.abs(a - b).mean() for a, b in zip(frames[:-1], frames[1:])]
    assert min(diffs) > 0.0  # every frame differs from the previous (at least the clock)
    # The trilith moves: far-apart frames differ by much more than a clock digit.
    assert np.abs(frames[3] - frames[9]).mean() > 5 * min(diffs)
    with Image.open(out) as im:  # GIF delays are stored in 10 ms units
        assert im.info["duration"] == pytest.approx(1000.0 / fps, abs=10)


def overturning(backend: str, t_end: float, t_over: float) -> Trajectory:
    """A synthetic run that overturns (|theta| = 1.5 rad) at ``t_over`` and stops."""
    t = np.linspace(0.0, t_end, 101)
    theta = 1.5 * (t / t_over) ** 2
    keep = t <= t_over
    t, theta = t[keep], theta[keep]
    psi = 0.2 * np.sin(4 * t)
    return Trajectory(backend, t, theta, np.gradient(theta, t), psi, np.gradient(psi, t), (),
                      Verdict("overturned", mode="no-impact", time=float(t[-1])),
                      OverturnCriterion(), t_end)


def test_recording_stops_soon_after_every_run_has_ended(tmp_path):
    """No frozen panels: 0.5 s after the last run ended, not the whole --duration."""
    trajs = {"analytic": overturning("analytic", 3.0, 1.0),
             "pymunk": overturning("pymunk", 3.0, 1.2)}
    fps = 10.0
    result = rec.record(FIG5, Pulse(25.0, 11.0), "all", tmp_path / "o.gif",
                        rec.RecordSettings(fps=fps, duration=3.0, panel_width=96,
                                           panel_height=72), trajectories=trajs)
    end = max(float(tr.t[-1]) for tr in trajs.values())
    assert result.duration == pytest.approx(end + rec.HOLD_AFTER_END)
    assert result.n_frames == round(fps * (end + rec.HOLD_AFTER_END))
    # A run that goes on keeps the full span.
    trajs["pybullet"] = synthetic("pybullet", 0.1, t_end=3.0)
    assert rec.shown_duration(trajs, 3.0) == 3.0


def test_panels_share_scale_camera_and_time_base():
    """Every panel: same limits; the camera follows the base (a state drawn at two
    ground displacements lands on the same pixels); the world lines move by -x_g."""
    from matplotlib.figure import Figure

    pulse = Pulse(25.0, 11.0)
    times = rec.frame_times(2.0, 10.0)
    trajs = {"analytic": synthetic("analytic", 0.2, 2.0), "pymunk": synthetic("pymunk", -0.1, 2.0),
             "pybullet": synthetic("pybullet", 0.05, 2.0)}
    panels = rec.Panels(FIG5, pulse, times, trajs, Figure(figsize=(9, 3)))
    limits = {(a.ax.get_xlim(), a.ax.get_ylim()) for a in panels.artists.values()}
    assert len(limits) == 1
    art = panels.artists["analytic"]
    art.update(0.0, 0.1, 0.2, 0.0)
    cols0, world0 = art.columns[0].get_xy().copy(), art.world.get_xdata().copy()
    art.update(0.0, 0.1, 0.2, 0.37)
    assert art.columns[0].get_xy() == pytest.approx(cols0, abs=TOL)
    shifted = np.asarray(art.world.get_xdata(), dtype=float)
    step = 2.0 * FIG5.b
    # World lines: same set modulo the line spacing, moved by -0.37 m.
    frac = lambda x: np.mod(x[np.isfinite(x)], step)  # noqa: E731
    assert sorted(frac(shifted))[0] == pytest.approx(np.mod(-0.37, step), abs=1e-9)
    assert sorted(frac(np.asarray(world0, float)))[0] == pytest.approx(0.0, abs=1e-9)


def test_held_state_after_the_run_ends(tmp_path):
    traj = synthetic("analytic", 0.1, t_end=0.5)
    theta, psi = rec.sample_states(traj, np.array([0.25, 0.5, 0.9]))
    assert theta[2] == theta[1] == traj.theta[-1]
    assert psi[2] == traj.psi[-1]


def test_bad_outputs_fail_before_simulating(tmp_path, monkeypatch):
    def boom(*args, **kwargs):
        raise AssertionError("simulated despite a bad output")

    monkeypatch.setattr(rec, "run_backend", boom)
    monkeypatch.setattr(rec, "find_ffmpeg", lambda: None)
    with pytest.raises(ValueError, match=r"ffmpeg.*\.gif"):
        rec.record(FIG5, Pulse(4.0, 9.0), "analytic", tmp_path / "x.mp4")
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        rec.record(FIG5, Pulse(4.0, 9.0), "analytic", tmp_path / "x.avi")
    with pytest.raises(ValueError, match="does not exist"):
        rec.record(FIG5, Pulse(4.0, 9.0), "analytic", tmp_path / "no" / "x.gif")
    with pytest.raises(ValueError, match="fps"):
        rec.RecordSettings(fps=0.0)
    with pytest.raises(ValueError, match="--engine"):
        rec.record(FIG5, Pulse(4.0, 9.0), "bullet", tmp_path / "x.gif")


def test_missing_backend_is_a_clear_error(tmp_path, monkeypatch):
    from trilith_xval import engines

    monkeypatch.setitem(engines.BACKENDS, "ghost", "engines.ghost_engine")
    with pytest.raises(ValueError, match="'ghost' is not available"):
        rec.record(FIG5, Pulse(4.0, 9.0), "ghost", tmp_path / "x.gif")


def test_all_backends_side_by_side(tmp_path):
    """Real backends, short run: three panels on one time base, all drawn in 2D from
    their trajectories (one scale, one camera)."""
    out = tmp_path / "all.gif"
    settings = rec.RecordSettings(fps=10.0, duration=0.4, panel_width=128, panel_height=96)
    result = rec.record(FIG5, Pulse(19.0, 15.0), "all", out, settings)
    frames = read_gif(out)
    assert len(frames) == 4 and frames[0].shape == (96, len(rec.ALL_ENGINES) * 128, 3)
    assert set(result.trajectories) == set(rec.ALL_ENGINES)
    for traj in result.trajectories.values():
        # Recordings switch off the early stops: every run covers the recorded span
        # (to within one engine sample, 1 ms) unless it overturned.
        assert traj.overturned or traj.t[-1] >= 0.4 - 1e-3



def test_a_list_of_backends_in_its_order(tmp_path):
    """--engine takes a comma list: one panel per backend, in the order given."""
    out = tmp_path / "two.gif"
    settings = rec.RecordSettings(fps=10.0, duration=0.2, panel_width=128, panel_height=96)
    result = rec.record(FIG5, Pulse(19.0, 15.0), "pymunk,analytic", out, settings)
    assert list(result.trajectories) == ["pymunk", "analytic"]
    assert read_gif(out)[0].shape == (96, 2 * 128, 3)
    for bad, needle in (("pymunk,nope", "'nope'"), ("pymunk,pymunk", "twice"), (",", "''")):
        with pytest.raises(ValueError, match=needle):
            rec.resolve_engines(bad)


# --- view ---------------------------------------------------------------------------
def test_display_problem_detection():
    assert "DISPLAY" in display_problem({}, None)
    assert "Agg" in display_problem({"DISPLAY": ":0", "MPLBACKEND": "Agg"})
    assert display_problem({"DISPLAY": ":0"}, backend="TkAgg") is None


@pytest.mark.parametrize("env", [{}, {"DISPLAY": ":0", "MPLBACKEND": "Agg"}])
def test_view_without_display_points_at_record(monkeypatch, capsys, env):
    for name in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND"):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setattr(rec, "run_backend", lambda *a, **k: pytest.fail("simulated"))
    rc = main(["view", "--scene", "fig5", "--engine", "pymunk"])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.startswith("error: cannot open a window")
    assert "trilith record --scene fig5 --engine pymunk" in err


# --- README ---------------------------------------------------------------------------
def readme_commands() -> list[str]:
    text = README.read_text()
    section = text[text.index("## Watching a run"):]
    block = re.search(r"```\n(.*?)```", section, re.S).group(1)
    lines = [line.strip().removeprefix(".venv/bin/") for line in block.splitlines()]
    return [line for line in lines if line.startswith("trilith ")]


def test_readme_section_has_commands():
    commands = readme_commands()
    assert any(c.startswith("trilith record") for c in commands)
    assert any(c.startswith("trilith view") for c in commands)


@pytest.mark.parametrize("command", readme_commands())
def test_readme_commands_run(command, tmp_path, monkeypatch, capsys):
    """Each README command, shortened (argparse keeps the last --duration/--fps/--out)."""
    for name in ("DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(name, raising=False)
    argv = shlex.split(command)[1:]
    short = ["--duration", "0.2", "--fps", "10", "--width", "96", "--height", "72"]
    if argv[0] == "view":
        rc = main(argv + short[:4])
        assert rc == 2 and "trilith record" in capsys.readouterr().err  # no display in tests
        return
    out = tmp_path / Path(argv[argv.index("--out") + 1]).name
    rc = main(argv + short + ["--out", str(out)])
    captured = capsys.readouterr()
    assert rc == 0, captured.err
    assert out.is_file() and f"wrote {out}: 2 frames" in captured.out
    if out.suffix == ".gif":
        assert len(read_gif(out)) == 2
    else:
        import imageio_ffmpeg

        n_frames, _ = imageio_ffmpeg.count_frames_and_secs(str(out))
        assert n_frames == 2


def test_view_with_a_display_animates_the_trajectories(monkeypatch):
    """The window path, with the display faked and ``plt.show`` replaced by a few
    animation steps (the same Panels as recordings)."""
    import matplotlib.pyplot as plt

    import trilith_xval.compare.show.view as view_mod

    shown = {}

    def fake_show():
        fig = plt.gcf()
        fig.canvas.draw()  # what a window does first; starts the animation
        for k in (0, 5, 9):
            fig.animation._func(k)  # FuncAnimation's frame callback: Panels.update
        shown["texts"] = [t.get_text() for ax in fig.axes for t in ax.texts]
        plt.close(fig)

    monkeypatch.setattr(view_mod, "display_problem", lambda: None)
    monkeypatch.setattr(view_mod, "NON_INTERACTIVE_BACKENDS", ())
    monkeypatch.setattr(rec, "run_backend", lambda run: synthetic(run.backend, 0.1))
    monkeypatch.setattr(plt, "show", fake_show)
    trajs = view_mod.view(FIG5, Pulse(4.0, 9.0), "all", fps=10.0, duration=1.0)
    assert set(trajs) == set(rec.ALL_ENGINES)
    assert len(shown["texts"]) == len(rec.ALL_ENGINES) and all("t     =   0.900 s" in t for t in shown["texts"])


def test_view_pybullet_uses_its_own_gui(monkeypatch):
    import trilith_xval.compare.show.view as view_mod

    calls = []

    class FakeModule:
        from dataclasses import dataclass as _dc

        @_dc(frozen=True)
        class Settings:
            t_max: float | None = None

        @staticmethod
        def view(scene, excitation, settings, duration):
            calls.append((settings.t_max, duration))

    monkeypatch.setattr(view_mod, "display_problem", lambda: None)
    monkeypatch.setattr(view_mod, "NON_INTERACTIVE_BACKENDS", ())
    monkeypatch.setattr(rec, "load_backend", lambda name: FakeModule)
    assert view_mod.view(FIG5, Pulse(4.0, 9.0), "pybullet", duration=2.0) == {}
    assert calls == [(2.0, 2.0)]


def test_mp4_frames_differ(tmp_path):
    """An MP4 of a short run has fps x duration frames that change over time
    (ffmpeg from imageio-ffmpeg when the machine has none on PATH)."""
    import imageio_ffmpeg

    out = tmp_path / "run.mp4"
    rec.record(FIG5, Pulse(19.0, 15.0), "analytic", out,
               rec.RecordSettings(fps=10.0, duration=0.6, panel_width=96, panel_height=72))
    reader = imageio_ffmpeg.read_frames(str(out))
    meta = next(reader)
    w, h = meta["size"]
    frames = [np.frombuffer(f, dtype=np.uint8).reshape(h, w, 3) for f in reader]
    assert len(frames) == 6
    assert all(f.std() > 1.0 for f in frames)  # not blank
    assert np.abs(frames[-1].astype(int) - frames[0].astype(int)).mean() > 0.1  # it moved
