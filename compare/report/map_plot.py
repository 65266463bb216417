"""The overturn map's figure: one panel per backend (``trilith map``, pulses and
records), the model's first-overturning curve on each, the frequencies where the
model is invalid hatched, an engine's robust threshold brackets on its panel."""
from __future__ import annotations

__all__ = ["plot_maps"]


def _hatch_invalid(ax, first, validity) -> None:
    """Hatch, above the first-overturning curve, the frequencies where the model
    is invalid on that curve's run (checked there only: the cells above it are
    not checked one by one)."""
    import numpy as np

    from trilith_xval.analytic.threshold_validity import invalid_spans

    w, a = np.asarray(first.omega, float), np.asarray(first.first, float)
    top = float(np.max(first.amplitude))
    for k, (lo, hi) in enumerate(invalid_spans(w, [v["model_valid"] for v in validity])):
        xs = np.concatenate(([lo], w[(w > lo) & (w < hi)], [hi]))
        ys = np.interp(xs, w[np.isfinite(a)], a[np.isfinite(a)])
        ax.fill_between(xs, ys, top, facecolor="none", edgecolor="tab:red", hatch="///",
                        lw=0, zorder=2,
                        label="model invalid at the first overturning" if k == 0 else None)


def _draw_thresholds(ax, points, colour) -> None:
    """An engine's robust brackets: survives at the open mark, overturns at the
    filled one, joined; the cause beside a point outside the tolerance."""
    from trilith_xval.compare.measure.engine_spectrum_files import SHORT_CAUSE
    label = "engine's robust threshold (survives / overturns)"
    for p in points:
        if not p.point.bracketed:
            ax.plot([p.omega], [p.a_reference], "x", color=colour, ms=7, mew=1.5, label=label)
        else:
            ax.plot([p.omega, p.omega], [p.a_survives, p.a_engine], "-", color=colour, lw=1.5)
            ax.plot([p.omega], [p.a_survives], "v", color=colour, mfc="white", ms=5)
            ax.plot([p.omega], [p.a_engine], "^", color=colour, ms=5, label=label)
        label = None
        if p.cause != "agrees":
            ax.annotate(SHORT_CAUSE.get(p.cause, p.cause), (p.omega, p.a_reference), fontsize=7,
                        color=colour, xytext=(3, -9), textcoords="offset points")


def plot_maps(maps, path, validity=None, thresholds=None, xlabel=r"$\Omega$ [rad/s]",
              ylabel=r"$A_s$ [m/s$^2$]", subject="pulse") -> None:
    """One panel per map: cells coloured by label, the analytic first-overturning
    curve (black line) on every panel and, above it, the frequencies where the
    model is invalid on that curve's run hatched (``validity``: one
    :func:`analytic.threshold_validity.point_validity` per frequency); on an
    engine's panel its robust threshold brackets (``thresholds``: backend ->
    :class:`~compare.measure.engine_spectrum.EnginePoint` list)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    colours = {"survived": "white", "overturned (no-impact)": "0.35",
               "overturned (after-impact)": "0.7", "unstable": "tab:red",
               "undecided": "tab:orange", "collapsed": "tab:purple"}
    first = maps[0]
    ncols = min(2, len(maps))  # two panels a row: readable on a page or a phone
    nrows = -(-len(maps) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 4.6 * nrows), squeeze=False)
    for ax in axes.ravel()[len(maps):]:
        ax.set_visible(False)
    for ax, m in zip(axes.ravel(), maps):
        cols = [colours.get(lab, "tab:blue") for lab in m.labels]
        ax.pcolormesh(m.omega, m.amplitude, m.cells, cmap=ListedColormap(cols),
                      vmin=-0.5, vmax=len(cols) - 0.5, shading="nearest")
        ax.plot(first.omega, first.first, "k-", lw=1.2, label="first overturning (analytic)")
        if validity:
            _hatch_invalid(ax, first, validity)
        if thresholds and thresholds.get(m.backend):
            from trilith_xval.compare.report.plots import color
            _draw_thresholds(ax, thresholds[m.backend], color(m.backend) or "tab:blue")
        present = [i for i, n in enumerate(np.bincount(m.cells.ravel(),
                                                       minlength=len(m.labels))) if n]
        handles = [Patch(facecolor=cols[i], edgecolor="k", label=m.labels[i]) for i in present]
        ax.legend(handles=handles + ax.get_legend_handles_labels()[0], fontsize=7,
                  loc="upper left")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        sc = m.scene
        ax.set_title(f"{m.backend}: {f'{m.pulse} {subject}'.strip()}, lam={sc.lam:g}, "
                     f"b={sc.b:g} m, "
                     f"gamma={sc.gamma:g}", fontsize=9)
    used = axes.ravel()[:len(maps)]
    for get, set_ in (("get_xlim", "set_xlim"), ("get_ylim", "set_ylim")):
        lims = [getattr(ax, get)() for ax in used]  # one extent: panels compare by eye
        for ax in used:
            getattr(ax, set_)(min(lo for lo, _ in lims), max(hi for _, hi in lims))
    fig.tight_layout()
    from trilith_xval.compare.run.atomic import savefig
    savefig(fig, path, dpi=150)
    plt.close(fig)
