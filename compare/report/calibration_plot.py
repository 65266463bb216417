"""The Pareto front of a calibration: CPU cost against worst error, one point per
candidate, the front joined, the tolerance drawn and the recommendation marked;
candidates that gave no answer somewhere on the top edge."""
from __future__ import annotations

import math

__all__ = ["pareto_plot"]


def _varied(evaluations) -> list[str]:
    """The option names whose values differ between ``evaluations`` (all of them
    when there is only one candidate)."""
    names = list(dict.fromkeys(k for e in evaluations for k in e.options))
    varied = [k for k in names if len({e.options.get(k) for e in evaluations}) > 1]
    return varied or names


def _label(e, varied) -> str:
    """``'dt 0.0005, solver_iterations 100'``: the candidate's varied settings."""
    return ", ".join(f"{k} {e.options[k]:g}" for k in varied if k in e.options)


def pareto_plot(cal, path=None, ax=None):
    """The Pareto front of a calibration on one axes.

    Parameters
    ----------
    cal : compare.campaign.calibrate.Calibration
    path : str or Path, optional
        Where to write the figure (PNG, PDF or SVG by suffix), atomically; the
        figure is then closed.
    ax : matplotlib.axes.Axes, optional
        Where to draw (matplotlib's convention); default a new figure's axes.

    Returns
    -------
    matplotlib.axes.Axes or None
        The axes drawn on; None once written to ``path`` on a figure of its own.
    """
    import matplotlib
    if ax is None and path is not None:
        matplotlib.use("Agg")  # a file only: no display needed
    import matplotlib.pyplot as plt

    from trilith_xval.compare.run import atomic

    pts = [e for e in cal.evaluations if math.isfinite(e.worst_error) and e.engine_cpu_s > 0]
    front = [e for e in cal.front if e in pts]
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(7.0, 5.4), dpi=150, layout="constrained")
    fig = ax.figure
    ax.scatter([e.engine_cpu_s for e in pts], [max(e.worst_error, 1e-6) for e in pts], s=28,
               color="0.55", label="candidate (settings: table, CSV)", zorder=2)
    if front:
        ax.plot([e.engine_cpu_s for e in front], [max(e.worst_error, 1e-6) for e in front], "-o",
                color="C0", ms=5, lw=1.5, label="Pareto front", zorder=3)
    # The front's points and the ones without an answer are numbered and keyed below
    # the axes, naming only the settings that differ between candidates: labels
    # beside points that nearly coincide in cost overprint one another.  Every
    # candidate's settings are in the table and CSV.
    varied = _varied(cal.evaluations)
    keyed = []
    for e in front:
        keyed.append(e)
        ax.annotate(str(len(keyed)), (e.engine_cpu_s, max(e.worst_error, 1e-6)),
                    textcoords="offset points", xytext=(0, 7), ha="center",
                    fontsize=8, fontweight="bold", color="C0")
    ax.axhline(cal.tolerance, color="C3", ls="--", lw=1.2,
               label=f"tolerance {cal.tolerance:g}")
    rec = cal.recommended
    if rec is not None:
        ax.scatter([rec.engine_cpu_s], [max(rec.worst_error, 1e-6)], s=140, facecolors="none",
                   edgecolors="C2", linewidths=2, label="recommended (cheapest within)",
                   zorder=4)
    # A candidate with no answer at some point (no robust bracket: infinite worst
    # error) is still a measured cost: drawn on the top edge, not left out.
    lost = [e for e in cal.evaluations if not math.isfinite(e.worst_error)
            and e.engine_cpu_s > 0]
    if lost:
        ax.scatter([e.engine_cpu_s for e in lost], [0.97] * len(lost), marker="^", s=40,
                   color="C3", transform=ax.get_xaxis_transform(), clip_on=False,
                   label="no answer at some point (no bracket)", zorder=3)
        for e in lost:
            keyed.append(e)
            ax.annotate(str(len(keyed)), (e.engine_cpu_s, 0.97),
                        xycoords=ax.get_xaxis_transform(), textcoords="offset points",
                        xytext=(7, 0), ha="left", va="center", fontsize=8,
                        fontweight="bold", color="C3")
    ax.margins(x=0.2, y=0.15)  # room for the labels at the ends
    ax.set_xscale("log")
    ax.set_yscale("log")
    costs = [e.engine_cpu_s for e in pts + lost]
    if costs:  # every candidate in view, the top-edge ones too
        ax.set_xlim(min(costs) / 1.6, max(costs) * 1.6)
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter
    ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))  # 1-2-5 seconds, plain
    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    unit = {"restitution": "relative error vs Eq. 19/20",
            "thresholds": "relative threshold error",
            "histories": "theta RMS / alpha before the first impact"}[cal.metric]
    ax.set_xlabel("engine CPU time on the validation set [s]")
    ax.set_ylabel(f"worst error ({unit})")
    load = ", ".join(f"{x:.2f}" for x in cal.load_average)
    ax.set_title(f"{cal.engine}: {cal.metric}, {cal.validation.scene_label} (load {load})",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    if keyed:
        from matplotlib.lines import Line2D
        # Below the axes: outside the figure's layout on a figure of our own; under
        # the given axes (in its coordinates) on a caller's.
        where = ({"loc": "outside lower center"} if own else
                 {"loc": "upper center", "bbox_to_anchor": (0.5, -0.12),
                  "bbox_transform": ax.transAxes})
        fig.legend([Line2D([], [], ls="none")] * len(keyed),
                   [f"{k}: {_label(e, varied)}" for k, e in enumerate(keyed, 1)],
                   ncols=1 if len(keyed) < 4 else 2, fontsize=8, frameon=False,
                   handlelength=0, handletextpad=0, **where)
    if path is None:
        return ax
    atomic.savefig(fig, path)
    if own:
        plt.close(fig)
        return None
    return ax
