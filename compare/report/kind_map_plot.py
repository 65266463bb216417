"""The engines' map of a scene of another kind (``trilith map --scene drums --engine
E1,E2``): one panel per engine, its cells coloured by status, every engine's
first failure on the grid drawn on every panel, the cells where the engines
disagree hatched; engine against engine, never agreement with the model."""
from __future__ import annotations

__all__ = ["plot_kind_map", "STATUS_COLOURS", "STATUSES", "FAILURES", "BASIS"]

# The statuses of a run of another kind, in the order a map's legend lists them.
STATUSES = ("survived", "overturned", "collapsed", "unstable", "undecided")
FAILURES = ("overturned", "collapsed")
BASIS = "engine against engine, never agreement with the model"
# Statuses of a kind's run (STATUSES): failures dark, as the
# trilith map's overturns, a collapse in the trilith map's colour for it.
STATUS_COLOURS = {"survived": "white", "overturned": "0.45", "collapsed": "tab:purple",
                  "unstable": "tab:red", "undecided": "tab:orange"}


def _edges(values):
    """Cell edges of a grid that may be uneven (a subsampled engine grid): the
    midpoints, the ends as far out as their neighbours, as pcolormesh's
    ``shading='nearest'`` draws them."""
    import numpy as np
    v = np.asarray(values, float)
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate(([2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]))


def plot_kind_map(kmap, path, scene, labels, points=None) -> None:
    """Write the figure of ``kmap`` (:class:`compare.cli.map_kinds.KindMap`) to
    ``path``; ``labels``: its axes' names (:class:`~compare.cli.map_kinds.MapAxes`);
    ``points``: the ``--consensus`` points (each engine's converged first
    failure, drawn as a triangle in its colour at each frequency)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from trilith_xval.compare.report.plots import color

    names = list(kmap.status)
    ncols = min(2, len(names))
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 4.6 * nrows + 0.4),
                             squeeze=False)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    cmap = ListedColormap([STATUS_COLOURS[s] for s in STATUSES])
    xe, ye = _edges(kmap.omega), _edges(kmap.amplitude)
    lines = [(n, color(n) or f"C{k}") for k, n in enumerate(names)]
    for ax, name in zip(axes.ravel(), names):
        grid = kmap.status[name]
        ax.pcolormesh(kmap.omega, kmap.amplitude, grid, cmap=cmap, vmin=-0.5,
                      vmax=len(STATUSES) - 0.5, shading="nearest", edgecolors="0.8", lw=0.3)
        for i, j in zip(*np.nonzero(~kmap.agree)):
            ax.add_patch(plt.Rectangle((xe[j], ye[i]), xe[j + 1] - xe[j], ye[i + 1] - ye[i],
                                       fill=False, hatch="xxx", edgecolor="tab:red",
                                       lw=0.0, zorder=2))
        for k, (other, c) in enumerate(lines):  # dashes differ: equal curves stay visible
            ax.step(kmap.omega, kmap.first[other], where="mid", color=c, lw=2.4 - 0.5 * k,
                    ls=("-", "--", ":", "-.")[k % 4],
                    label=f"{other}: first failure on the grid", zorder=3)
        for p in points or ():
            for k, (other, c) in enumerate(lines):
                row = p["engines"].get(other)
                if row:
                    ax.plot([p["omega"]], [row["a_fails"]], "^v<>"[k % 4], color=c, mec="k", ms=6,
                            zorder=4, label=f"{other}: own threshold (converged)")
        present = sorted(set(np.unique(grid).tolist()))
        handles = [Patch(facecolor=STATUS_COLOURS[STATUSES[k]], edgecolor="k",
                         label=STATUSES[k]) for k in present]
        if kmap.disagreements:
            handles.append(Patch(facecolor="none", edgecolor="tab:red", hatch="xxx",
                                 label=f"engines disagree ({kmap.disagreements} cells)"))
        seen = {}
        for h, lab in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(lab, h)
        ax.legend(handles=handles + [Line2D([], [], color=h.get_color(), marker=h.get_marker(),
                                            ls=h.get_linestyle(), label=lab)
                                     for lab, h in seen.items()],
                  fontsize=7, loc="upper left")
        ax.set_xlabel(labels.x_label)
        ax.set_ylabel(labels.y_label)
        ax.set_title(f"{name}: {labels.subject}, scene {scene.name} ({scene.kind})", fontsize=9)
    fig.suptitle(f"No model of the {scene.kind} kind: {BASIS}", fontsize=9)
    fig.tight_layout()
    from trilith_xval.compare.run.atomic import savefig
    savefig(fig, path, dpi=150)
    plt.close(fig)
