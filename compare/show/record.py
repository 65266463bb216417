"""Headless recordings of a run: GIF (Pillow) or MP4 (ffmpeg), one panel per backend.

Every backend runs the same scene under the same excitation; its
:class:`~analytic.trajectory.Trajectory` is sampled on one common time base
(``k / fps``) and drawn with :mod:`compare.show.draw` in every panel: one scale, one
camera (it follows the moving base), theta and psi written on each panel, so
panels side by side compare at a glance.  (PyBullet's own software renderer had
its own world-fixed camera and scale and lost the lintel as the base drifted; it
is no longer used for recordings.)

A scene of another kind (:mod:`analytic.kinds`) has no theta/psi picture: every
body is drawn from each engine's own poses (:mod:`compare.show.kind_record`).

When every run has ended before ``--duration`` (all overturned), the recording
stops :data:`HOLD_AFTER_END` seconds after the last one, so the verdicts can be
read but no panel sits frozen for long.

The figure is drawn with matplotlib's Agg canvas directly (no pyplot), so
recording works without a display and never touches the GUI backend.
"""
from __future__ import annotations

import math
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.trajectory import Trajectory
from trilith_xval.engines import engine_names

__all__ = ["RecordSettings", "RecordResult", "frame_times", "default_duration", "resolve_engines",
           "recording_run", "run_backend", "sample_states", "Panels", "render_frames",
           "write_gif", "write_mp4", "find_ffmpeg", "shown_duration",
           "check_output", "record", "ALL_ENGINES", "FORMATS", "DEFAULT_AMPLITUDE",
           "DEFAULT_OMEGA", "HOLD_AFTER_END"]

# ``--engine all``: the accurate analytic reference and every physics engine
# (``analytic-fast`` is the same model as ``analytic``; a panel for it adds nothing).
ALL_ENGINES = ("analytic",) + engine_names()  # the model and every registered engine
FORMATS = (".gif", ".mp4")
# The paper integrates to at least ten pulse periods (Sec. 5.1): the default length.
DEFAULT_PERIODS = 10.0
# Default pulse of ``trilith view/record``: case A of the paper's Fig. 6
# (A_s = 19 m/s^2, Omega = 15 rad/s on the Fig. 5 trilith), inside the gain range
# where the pendulum changes the outcome, so it is worth watching.
DEFAULT_AMPLITUDE = 19.0
DEFAULT_OMEGA = 15.0
MAX_FRAMES = 20000  # about 11 min at 30 fps: beyond that a GIF is not a sensible output
# Seconds shown after the last run has ended: enough to read "OVERTURNED (mode)".
HOLD_AFTER_END = 0.5


@dataclass(frozen=True)
class RecordSettings:
    """How a run is turned into frames.

    fps : frames per second of the recording, in (0, 120].  Default 30: smooth for
        rocking (a few Hz).  GIF stores delays in 10 ms units: 30 fps is written
        as 30 ms per frame, so a GIF plays 10 % fast (25 or 20 fps play exactly);
        MP4 keeps the exact rate.
    duration : recorded time span [s], > 0; ``None`` gives ten pulse periods
        (the paper's ``t_max``, Sec. 5.1).
    panel_width, panel_height : pixels of one backend's panel, even numbers in
        [64, 4096]; default 480 x 360 keeps a 10 s GIF around a few MB.
    runs : per backend its run (:class:`compare.run.spec.RunSpec` on the recorded
        scene and excitation, e.g. with a ``--settings`` file's values); a backend
        without one runs at its defaults (:func:`recording_run`).
    """

    fps: float = 30.0
    duration: float | None = None
    panel_width: int = 480
    panel_height: int = 360
    runs: tuple = ()  # RunSpec, at most one per backend

    def run_of(self, backend: str):
        """The run given for ``backend`` (None: its defaults)."""
        return next((r for r in self.runs if r.backend == backend), None)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.fps) and 0.0 < self.fps <= 120.0):
            raise ValueError(f"fps must be in (0, 120], got {self.fps!r}")
        if self.duration is not None and not (math.isfinite(self.duration)
                                              and 0.0 < self.duration <= 3600.0):
            raise ValueError(f"duration must be in (0, 3600] s, got {self.duration!r}")
        for name in ("panel_width", "panel_height"):
            value = getattr(self, name)
            if not (isinstance(value, int) and 64 <= value <= 4096 and value % 2 == 0):
                # Even sizes: MP4 (yuv420p) needs even frame dimensions.
                raise ValueError(f"{name} must be an even integer in [64, 4096], got {value!r}")


@dataclass
class RecordResult:
    """What :func:`record` wrote."""

    path: Path
    n_frames: int
    fps: float
    duration: float
    trajectories: dict[str, Trajectory]


def default_duration(excitation) -> float:
    """Ten pulse periods (the paper's ``t_max``), from ``excitation.end_time``."""
    return DEFAULT_PERIODS * float(excitation.end_time)


def frame_times(duration: float, fps: float) -> np.ndarray:
    """The common time base ``k / fps``, ``k = 0 .. round(fps * duration) - 1`` [s]."""
    n = int(round(duration * fps))
    if n < 1:
        raise ValueError(f"duration x fps must give at least one frame, got {duration!r} s "
                         f"x {fps!r} fps")
    if n > MAX_FRAMES:
        raise ValueError(f"duration x fps gives {n} frames; at most {MAX_FRAMES} allowed "
                         "(shorten --duration or lower --fps)")
    return np.arange(n) / float(fps)


def check_output(path: str | Path) -> Path:
    """Validate the output path before any simulation: suffix, encoder, folder."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"--out must end in {' or '.join(FORMATS)}, got {str(path)!r}")
    if suffix == ".mp4" and find_ffmpeg() is None:
        raise ValueError("--out .mp4 needs ffmpeg (on PATH or from the imageio-ffmpeg "
                         "package), which was not found; "
                         f"write a GIF instead: --out {path.with_suffix('.gif')}")
    if not path.parent.is_dir():
        raise ValueError(f"--out: folder {str(path.parent)!r} does not exist")
    return path


def resolve_engines(engine: str) -> tuple[str, ...]:
    """``'all'`` -> :data:`ALL_ENGINES`; ``'a,b'`` -> ``('a', 'b')`` (registered
    backends, each once, panels in that order); else ValueError."""
    from trilith_xval.engines import backend_names

    if engine.strip() == "all":
        return ALL_ENGINES
    names = tuple(n.strip() for n in engine.split(","))
    for name in names:
        if name not in backend_names():
            raise ValueError(f"--engine must name backends from {', '.join(backend_names())} "
                             f"(comma-separated) or all; got {name!r}")
    if len(set(names)) != len(names):
        raise ValueError(f"--engine names a backend twice: {engine!r}")
    return names


def load_backend(name: str):
    """The backend module (:func:`engines.get_backend`; ValueError if unknown)."""
    from trilith_xval.engines import get_backend
    return get_backend(name)


def recording_run(name: str, scene: Scene, excitation, duration: float, run=None):
    """Backend ``name``'s run of ``scene`` under ``excitation`` over the whole
    recorded span: ``run`` (a :class:`compare.run.spec.RunSpec` of that backend,
    default its defaults, which are calibrated for time histories) with one more
    layer, ``t_max = duration`` and ``early_stop=False``.

    ``early_stop=False``: a run would otherwise stop as soon as survival is
    certain (energy below the barrier, or at rest), which freezes the picture
    while the pendulum still swings; every backend runs to ``t_max`` (or until it
    overturns).
    """
    from trilith_xval.compare.run.spec import RunSpec
    run = RunSpec.resolve(name, scene, excitation) if run is None else run.at(scene, excitation)
    return run.with_options("the recorded span", t_max=duration, early_stop=False)


def run_backend(run) -> Trajectory:
    """Simulate ``run`` (a :func:`recording_run`) in its backend."""
    return load_backend(run.backend).simulate(run.scene, run.excitation, run.settings)


def shown_duration(trajectories: dict[str, Trajectory], duration: float,
                   hold: float = HOLD_AFTER_END) -> float:
    """The span to show: ``duration``, or ``hold`` seconds after the last run's
    end when every run ended earlier (overturned; the early "survived" stops
    are off in recordings), so no panel is frozen for longer than ``hold``."""
    ends = [float(tr.t[-1]) for tr in trajectories.values() if len(tr.t)]
    if not ends:
        return duration
    return min(duration, max(ends) + hold)


def sample_states(traj: Trajectory, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, psi)`` at ``times`` by linear interpolation; after the run's last
    sample (it stopped: overturned, at rest or ``t_max``) the last state is held."""
    if len(traj.t) == 0:
        raise ValueError(f"backend {traj.backend!r} returned an empty trajectory")
    theta = np.interp(times, traj.t, traj.theta)
    psi = np.interp(times, traj.t, traj.psi)
    return theta, psi


def _note(traj: Trajectory, t: float) -> str:
    verdict = traj.verdict
    if verdict.overturned and verdict.time is not None and t >= verdict.time:
        mode = f" ({verdict.mode})" if verdict.mode else ""
        return f"OVERTURNED{mode}"
    if len(traj.t) and t > traj.t[-1]:
        return f"run ended: {verdict.status}"
    return ""


class Panels:
    """One figure, one panel per backend, all on the same time base, the same
    scale and the same camera (following the base)."""

    def __init__(self, scene: Scene, excitation, times: np.ndarray,
                 trajectories: dict[str, Trajectory], figure) -> None:
        from trilith_xval.compare.show.draw import TrilithArtist, view_limits

        self.times = np.asarray(times, dtype=float)
        self.trajectories = trajectories
        self.x_g = np.array([excitation.displacement(float(t)) for t in self.times])
        self.states = {name: sample_states(traj, self.times)
                       for name, traj in trajectories.items()}
        # One set of limits for every panel (base frame: x_g = 0), so the panels
        # compare at a glance.
        all_theta = np.concatenate([s[0] for s in self.states.values()])
        all_psi = np.concatenate([s[1] for s in self.states.values()])
        limits = view_limits(scene, all_theta, all_psi, np.zeros_like(all_theta))
        names = list(trajectories)
        axes = figure.subplots(1, len(names), squeeze=False)[0]
        figure.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.92, wspace=0.03)
        self.artists = {}
        for ax, name in zip(axes, names):
            artist = TrilithArtist(ax, scene, title=name)
            artist.set_limits(*limits)
            self.artists[name] = artist

    def __len__(self) -> int:
        return self.times.size

    def update(self, k: int) -> list:
        """Show frame ``k`` in every panel; returns the changed artists."""
        t = float(self.times[k])
        changed = []
        for name, artist in self.artists.items():
            theta, psi = self.states[name]
            changed += artist.update(t, float(theta[k]), float(psi[k]), float(self.x_g[k]),
                                     note=_note(self.trajectories[name], t))
        return changed


def render_frames(panels: Panels, figure) -> list[np.ndarray]:
    """Draw every frame on the Agg canvas of ``figure``; (H, W, 3) uint8 arrays.

    Blitting: the static parts (axes frames, titles) are drawn once and restored
    for every frame, then only the moving artists are drawn on top, in z-order
    (a full redraw costs about three times as much).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(figure)
    for artist in panels.update(0):
        artist.set_animated(True)  # left out of the full draw below
    canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)
    frames = []
    for k in range(len(panels)):
        canvas.restore_region(background)
        for artist in sorted(panels.update(k), key=lambda a: a.get_zorder()):
            artist.axes.draw_artist(artist)
        frames.append(np.asarray(canvas.buffer_rgba())[:, :, :3].copy())
    return frames


def gif_palette(frames: list[np.ndarray], colors: int = 128):
    """One adaptive palette for the whole GIF, from the first, middle and last
    frames: quantising each frame on its own costs ~90 ms per frame and makes
    colours flicker between frames."""
    from PIL import Image

    picks = [frames[0], frames[len(frames) // 2], frames[-1]]
    montage = Image.fromarray(np.concatenate(picks, axis=0))
    return montage.quantize(colors=colors, method=Image.Quantize.MEDIANCUT,
                            dither=Image.Dither.NONE)


def write_gif(frames: list[np.ndarray], path: Path, fps: float) -> None:
    """Animated GIF via Pillow, looping; delay ``1000/fps`` ms (GIF stores 10 ms units)."""
    from PIL import Image

    palette = gif_palette(frames)
    images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE)
              for f in frames]
    from trilith_xval.compare.run.atomic import atomic_path
    with atomic_path(path, Path(path).suffix) as tmp:  # whole file or none
        images[0].save(tmp, save_all=True, append_images=images[1:], loop=0,
                       duration=int(round(1000.0 / fps)), optimize=False)


def find_ffmpeg() -> str | None:
    """The ffmpeg executable: the one on PATH, else the binary shipped inside the
    ``imageio-ffmpeg`` wheel (a project dependency, so MP4 works on a fresh
    machine without a system ffmpeg); None if neither exists."""
    exe = shutil.which("ffmpeg")
    if exe is not None:
        return exe
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError:  # the package is there but its binary is not
        return None


def write_mp4(frames: list[np.ndarray], path: Path, fps: float) -> None:
    """H.264 MP4 by piping raw RGB frames to ffmpeg (:func:`find_ffmpeg`)."""
    ffmpeg = find_ffmpeg()
    if ffmpeg is None:
        raise ValueError("writing .mp4 needs ffmpeg on PATH; use a .gif output instead")
    height, width = frames[0].shape[:2]
    cmd = [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
           "-s", f"{width}x{height}", "-r", f"{fps:g}", "-i", "-",
           # Pad to even sizes (yuv420p) and use the most widely playable pixel format.
           "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", str(path)]
    from trilith_xval.compare.run.atomic import atomic_path
    with atomic_path(path, Path(path).suffix) as tmp:  # whole file or none
        cmd[-1] = str(tmp)
        proc = subprocess.run(cmd, input=b"".join(np.ascontiguousarray(f).tobytes()
                                                  for f in frames),
                              capture_output=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"ffmpeg failed: {proc.stderr.decode(errors='replace').strip()}")


def record(scene: Scene, excitation, engine: str, out: str | Path,
           settings: RecordSettings | None = None,
           trajectories: dict[str, Trajectory] | None = None) -> RecordResult:
    """Simulate ``scene`` under ``excitation`` and write an animation to ``out``.

    Parameters
    ----------
    engine : str
        A registered backend name or ``'all'`` (analytic, pybullet, pymunk side
        by side on the same time base, scale and camera).
    out : path
        ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    trajectories : dict, optional
        Backend -> precomputed Trajectory (skips simulation; used by tests and
        by callers that already ran the backends).
    """
    from matplotlib.figure import Figure

    settings = settings or RecordSettings()
    path = check_output(out)
    names = tuple(trajectories) if trajectories else resolve_engines(engine)
    duration = settings.duration if settings.duration is not None else default_duration(excitation)
    frame_times(duration, settings.fps)  # validates the frame count before any run
    kind = getattr(scene, "kind", "trilith") != "trilith"
    if trajectories is None:
        for name in names:  # fail on a missing backend before any long run
            load_backend(name)
        runs = {name: recording_run(name, scene, excitation, duration, settings.run_of(name))
                for name in names}
        if kind:  # every body drawn from the engine's own poses
            from trilith_xval.compare.show.kind_record import run_with_poses
            posed = {name: run_with_poses(run) for name, run in runs.items()}
            trajectories = {name: r.trajectory for name, r in posed.items()}
        else:
            trajectories = {name: run_backend(run) for name, run in runs.items()}
    duration = shown_duration(trajectories, duration)
    times = frame_times(duration, settings.fps)
    dpi = 100
    figure = Figure(figsize=(len(names) * settings.panel_width / dpi,
                             settings.panel_height / dpi), dpi=dpi)
    if kind:
        from trilith_xval.compare.show.kind_record import KindPanels
        panels = KindPanels(times, posed, excitation, figure)
    else:
        panels = Panels(scene, excitation, times, trajectories, figure)
    frames = render_frames(panels, figure)
    if path.suffix.lower() == ".gif":
        write_gif(frames, path, settings.fps)
    else:
        write_mp4(frames, path, settings.fps)
    return RecordResult(path=path, n_frames=len(frames), fps=settings.fps, duration=duration,
                        trajectories=trajectories)
