"""Watching a run live: a matplotlib animation window (or PyBullet's own GUI).

Without a display there is nothing to show; :func:`display_problem` says why
and :func:`view` raises ``ValueError`` pointing at ``trilith record`` *before*
any simulation (the CLI turns it into ``error: ...`` and exit code 2: a usage
condition, like a bad option).
"""
from __future__ import annotations

import os
import sys

import numpy as np

from trilith_xval.analytic.excitation_contract import PULSE_KINDS
from trilith_xval.analytic.parameters import Scene

__all__ = ["display_problem", "view", "NON_INTERACTIVE_BACKENDS"]

# matplotlib backends that write files and never open a window.
NON_INTERACTIVE_BACKENDS = ("agg", "cairo", "pdf", "pgf", "ps", "svg", "template",
                            "module://matplotlib_inline.backend_inline")


def display_problem(environ: dict | None = None, backend: str | None = None) -> str | None:
    """Why no window can be shown, or ``None`` if one can.

    Checks, in order: on Linux/BSD an X11 or Wayland display (``$DISPLAY`` or
    ``$WAYLAND_DISPLAY``); then the matplotlib backend (``$MPLBACKEND`` or the
    configured one), which must be interactive.  ``environ`` and ``backend``
    default to the process environment and matplotlib's setting.
    """
    env = os.environ if environ is None else environ
    if sys.platform.startswith(("linux", "freebsd", "openbsd")) and not (
            env.get("DISPLAY") or env.get("WAYLAND_DISPLAY")):
        return "no display ($DISPLAY and $WAYLAND_DISPLAY are unset)"
    if backend is None:
        backend = env.get("MPLBACKEND") or _configured_backend()
    if backend and backend.lower() in NON_INTERACTIVE_BACKENDS:
        return f"matplotlib backend {backend!r} cannot open a window"
    return None


def _configured_backend() -> str | None:
    """The backend set in matplotlibrc, without resolving (importing) a GUI toolkit."""
    import matplotlib

    # Read the raw entry: ``rcParams["backend"]`` would resolve (import) a GUI
    # backend; until one is chosen the raw entry is a sentinel object, not a string.
    value = dict.get(matplotlib.rcParams, "backend")
    return value if isinstance(value, str) else None


def record_hint(scene_name: str, engine: str, excitation) -> str:
    """The ``trilith record`` command that shows the same run in a file (a record
    is named by its file name: its path is the user's own)."""
    form = excitation.compiled_form()  # a sine or cosine pulse: the options give it
    if form is not None and form.kind in PULSE_KINDS:
        shape = "" if form.kind == "sine" else f"--pulse {form.kind} "
        what = f"{shape}--amplitude {form.amplitude:g} --omega {form.omega:g}"
    else:
        what = f"--record {excitation.label}"
    return f"trilith record --scene {scene_name} --engine {engine} {what} --out run.gif"


def _own_gui(run, duration: float) -> bool:
    """Run ``run`` (a :func:`compare.show.record.recording_run`) in its engine's own
    GUI window if the engine declares the ``'gui'`` capability; return whether it did."""
    from trilith_xval.engines import supports
    from trilith_xval.compare.show.record import load_backend

    if not supports(run.backend, "gui"):
        return False
    load_backend(run.backend).view(run.scene, run.excitation, run.settings, duration=duration)
    return True


def view(scene: Scene, excitation, engine: str = "analytic", fps: float = 30.0,
         duration: float | None = None, scene_arg: str | None = None,
         runs: tuple = ()) -> dict:
    """Show a run in a window: PyBullet's GUI if available, else a matplotlib
    animation drawn from the backend's Trajectory (several panels for ``'all'``); a
    scene of another kind from each engine's poses (:mod:`compare.show.kind_record`).

    Returns the trajectories shown (backend -> Trajectory); empty when PyBullet's
    own GUI was used.  Raises ``ValueError`` when there is no display, with the
    equivalent ``trilith record`` command (``scene_arg``: the ``--scene`` value
    to quote in it, by default ``scene.name``); ``runs`` as
    :class:`compare.show.record.RecordSettings`'s.
    """
    from trilith_xval.compare.show.record import (RecordSettings, Panels, default_duration,
                                                  frame_times, load_backend, recording_run,
                                                  resolve_engines, run_backend, shown_duration)

    settings = RecordSettings(fps=fps, duration=duration,  # validates fps/duration
                              runs=runs)
    names = resolve_engines(engine)
    problem = display_problem()
    if problem is None:
        # A display exists, but pyplot may still fall back to Agg when no GUI
        # toolkit is installed; find out before simulating.
        import matplotlib
        import matplotlib.pyplot  # noqa: F401  (selects the backend)

        backend = matplotlib.get_backend()
        if backend.lower() in NON_INTERACTIVE_BACKENDS:
            problem = f"matplotlib found no GUI toolkit (backend {backend!r})"
    if problem is not None:
        raise ValueError(f"cannot open a window: {problem}. Record the run to a file "
                         f"instead: {record_hint(scene_arg or scene.name, engine, excitation)}")
    for name in names:
        load_backend(name)
    span = settings.duration if settings.duration is not None else default_duration(excitation)
    spans = {name: recording_run(name, scene, excitation, span, settings.run_of(name))
             for name in names}
    kind = getattr(scene, "kind", "trilith") != "trilith"
    # An engine's own GUI draws the trilith only: a kind is drawn from its poses.
    if not kind and len(names) == 1 and _own_gui(spans[names[0]], span):
        return {}
    frame_times(span, settings.fps)  # validates the frame count before any run
    if kind:
        from trilith_xval.compare.show.kind_record import KindPanels, run_with_poses
        posed = {name: run_with_poses(run) for name, run in spans.items()}
        trajectories = {name: r.trajectory for name, r in posed.items()}
    else:
        trajectories = {name: run_backend(run) for name, run in spans.items()}
    times = frame_times(shown_duration(trajectories, span), settings.fps)

    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    # At most 12 in (1200 px at 100 dpi) wide: three panels fit a 1280 px screen.
    width = min(4.8, 12.0 / len(names))
    figure = plt.figure(figsize=(width * len(names), 0.75 * width))
    panels = (KindPanels(times, posed, excitation, figure) if kind
              else Panels(scene, excitation, times, trajectories, figure))
    # Keep a reference: an unreferenced FuncAnimation is garbage-collected and stops.
    # blit: only the moving artists are redrawn (Panels.update returns them), which
    # keeps the window near real time with several panels.
    animation = FuncAnimation(figure, panels.update, frames=np.arange(len(panels)),
                              interval=1000.0 / settings.fps, blit=True, repeat=True)
    figure.animation = animation
    plt.show()
    return trajectories
