"""theta(t) and psi(t) of one or more runs of one scene on one axes each, every
run's events marked in its colour (``trilith simulate --plot``: an engine's run
over the model's).

The events are those of the rule every backend is read by
(:mod:`analytic.sampled_events`): uplift, impacts and the last rise past alpha,
and the run's overturn (its verdict's time, ``Trajectory.overturn_time``), so a
model's and an engine's marks are comparable.  Both functions follow
matplotlib's convention: they draw on ``ax`` when given, else on a new figure's
axes, and return the axes.
"""
from __future__ import annotations

import numpy as np

__all__ = ["plot_theta", "plot_psi", "plot_runs", "EVENT_MARKERS"]

# One marker per kind of event, the same for every run (the colour is the run's).
EVENT_MARKERS = {"uplift": ("^", "uplift"), "impact": ("o", "impact"),
                 "exceeds_alpha": ("D", "past alpha for good"), "overturn": ("X", "overturn")}


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt
    return plt.subplots(figsize=(7.0, 2.8))[1]


def _runs(trajectories) -> list:
    """``trajectories`` as a list: one Trajectory or a sequence of them."""
    runs = [trajectories] if hasattr(trajectories, "theta") else list(trajectories)
    if not runs or not all(hasattr(r, "theta") and hasattr(r, "t") for r in runs):
        raise TypeError("trajectories must be an analytic.Trajectory or a non-empty "
                        "sequence of them")
    return runs


def _label(traj) -> str:
    return "model (analytic)" if traj.backend.startswith("analytic") else traj.backend


def _at(traj, t: float, values) -> float:
    return float(np.interp(t, traj.t, values))


def plot_theta(trajectories, alpha: float, ax=None, labels=None, events: bool = True):
    """theta(t)/alpha of each run, its events marked, a legend naming each run and
    each kind of mark.

    Parameters
    ----------
    trajectories : Trajectory or sequence of Trajectory
        Runs of one scene; the first is drawn solid and below, the others dashed.
    alpha : float
        The scene's slenderness angle [rad] (``Scene.alpha``), > 0: the unit of
        the y axis (|theta| = alpha is the static overturning angle).
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure's axes.
    labels : sequence of str, optional
        One per run; default the backend ("model (analytic)" for the model).
    events : bool
        Mark uplift, impacts, the last rise past alpha and the overturn.

    Returns
    -------
    matplotlib.axes.Axes
    """
    runs = _runs(trajectories)
    if isinstance(alpha, bool) or not isinstance(alpha, (int, float)) or not alpha > 0:
        raise ValueError(f"alpha must be a positive angle [rad], got {alpha!r}")
    labels = [_label(r) for r in runs] if labels is None else list(labels)
    if len(labels) != len(runs):
        raise ValueError(f"labels must have one entry per run ({len(runs)}), got "
                         f"{len(labels)}")
    ax = _axes(ax)
    used = set()
    for k, (traj, label) in enumerate(zip(runs, labels)):
        color = f"C{k}"
        ax.plot(traj.t, np.asarray(traj.theta) / alpha, color=color, lw=1.4 if k == 0 else 1.0,
                ls="-" if k == 0 else "--", label=label, zorder=2 + k)
        if events:  # the first run's marks large and open, so later ones show inside
            used |= _mark_events(ax, traj, alpha, color, zorder=4 + k, first=k == 0)
    for y in (-1.0, 1.0):
        ax.axhline(y, color="0.6", lw=0.6, ls=":")
    for kind in EVENT_MARKERS:  # one legend entry per kind of mark, in black
        if kind in used:
            marker, text = EVENT_MARKERS[kind]
            ax.plot([], [], marker, color="k", mfc="none", ls="none", label=text)
    ax.set_ylabel(r"$\theta/\alpha$")
    ax.set_xlabel("t [s]")
    ax.legend(fontsize=7, ncol=2, loc="best")
    return ax


def _mark_events(ax, traj, alpha: float, color: str, zorder: int, first: bool) -> set:
    """The run's events on its own curve; returns the kinds drawn."""
    theta = np.asarray(traj.theta) / alpha
    read = traj.sampled_events()
    marks = [("impact", e.t) for e in read.impacts]
    if read.uplift is not None:
        marks.append(("uplift", read.uplift.t))
    if read.exceeds_alpha is not None:
        marks.append(("exceeds_alpha", read.exceeds_alpha.t))
    if traj.overturn_time is not None:
        marks.append(("overturn", traj.overturn_time))
    for kind, t in marks:
        ax.plot([t], [_at(traj, t, theta)], EVENT_MARKERS[kind][0], color=color,
                mfc="none" if first else color, ms=8 if first else 4, mew=1.2, zorder=zorder)
    return {kind for kind, _ in marks}


def plot_psi(trajectories, ax=None, labels=None, legend: bool = True):
    """psi(t) [rad] of each run (runs of a scene with its pendulum).

    Parameters
    ----------
    trajectories : Trajectory or sequence of Trajectory
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure's axes.
    labels : sequence of str, optional
        One per run; default the backend.
    legend : bool
        Name the runs (with more than one).

    Returns
    -------
    matplotlib.axes.Axes
    """
    runs = _runs(trajectories)
    labels = [_label(r) for r in runs] if labels is None else list(labels)
    if len(labels) != len(runs):
        raise ValueError(f"labels must have one entry per run ({len(runs)}), got "
                         f"{len(labels)}")
    ax = _axes(ax)
    for k, (traj, label) in enumerate(zip(runs, labels)):
        ax.plot(traj.t, traj.psi, color=f"C{k}", lw=1.4 if k == 0 else 1.0,
                ls="-" if k == 0 else "--", label=label)
    ax.set_ylabel(r"$\psi$ [rad]")
    ax.set_xlabel("t [s]")
    if legend and len(runs) > 1:
        ax.legend(fontsize=7)
    return ax


def plot_runs(runs: list, scene, path) -> None:
    """The figure of ``trilith simulate --plot``: theta(t)/alpha of ``runs`` (the
    model's first, when the run is an engine's) with each run's events and each
    verdict in the title, and psi(t) below when the scene has a pendulum; written
    atomically to ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 2 if scene.has_pendulum else 1
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(7, 2.8 * rows + 0.4),
                             squeeze=False)
    plot_theta(runs, scene.alpha, ax=axes[0, 0])
    titles = []
    for traj in runs:
        v = traj.verdict
        titles.append(f"{traj.backend}: {v.status}" + (
            f" ({v.mode}, overturn_time = {traj.overturn_time:.3f} s)" if v.overturned else ""))
    axes[0, 0].set_title("\n".join(titles), fontsize=9)
    if scene.has_pendulum:
        plot_psi(runs, ax=axes[1, 0], legend=False)  # named once, above
    for ax in axes[:-1, 0]:
        ax.set_xlabel("")
    fig.tight_layout()
    from trilith_xval.compare.run.atomic import savefig
    savefig(fig, path, dpi=120)
    plt.close(fig)
