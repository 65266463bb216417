"""Figures of the restitution map (:mod:`compare.measure.restitution_map`).

One figure per engine, two panels against lam (block family only): r_eff / r_H
(the mean over the measured impacts of measured / Eq. 20) and the threshold
error at Omega = 3 p, one line per settings variant, with the acceptance bands
(0.5 % and 2 %) shaded.
"""
from __future__ import annotations

import math
from pathlib import Path

__all__ = ["engine_figure", "write_figures", "figure_name"]


def figure_name(engine: str) -> str:
    return f"restitution_map_{engine}.png"


def engine_figure(doc: dict, engine: str):
    """The matplotlib figure of ``engine``'s cells in ``doc`` (the map document)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = [c for c in doc["cells"] if c["engine"] == engine and c["scene"].startswith("block")]
    fig, (ax_r, ax_t) = plt.subplots(1, 2, figsize=(10.0, 4.0), constrained_layout=True)
    r_tol, t_tol = doc["r_tol"], doc["thr_tol"]
    ax_r.axhspan(1 - r_tol, 1 + r_tol, color="0.9", zorder=0)
    ax_t.axhspan(-100 * t_tol, 100 * t_tol, color="0.9", zorder=0)
    for variant in dict.fromkeys(c["variant"] for c in cells):
        mine = sorted((c for c in cells if c["variant"] == variant), key=lambda c: c["lam"])
        lam = [c["lam"] for c in mine]
        ax_r.plot(lam, [c["r_ratio"] if c["r_ratio"] is not None else math.nan for c in mine],
                  marker="o", ms=3, label=variant)
        # The stored JSON holds NaN as null.
        ax_t.plot(lam, [100 * c["thr_error"] if c["thr_error"] is not None else math.nan
                        for c in mine], marker="o", ms=3, label=variant)
    ax_r.set(xlabel="lam = h/b [-]", ylabel="r_eff / r_H [-]",
             title=f"{engine}: restitution (mean of {doc['n_impacts']} impacts)")
    ax_t.set(xlabel="lam = h/b [-]", ylabel="threshold error [%]",
             title=f"{engine}: one-sine threshold at Omega = {doc['omega_ratio']:g} p")
    ax_r.legend(fontsize=7)
    return fig


def write_figures(doc: dict, directory) -> list[Path]:
    """One PNG per engine of ``doc`` into ``directory`` (created); their paths."""
    import matplotlib.pyplot as plt
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for engine in doc["engines"]:
        fig = engine_figure(doc, engine)
        path = out / figure_name(engine)
        fig.savefig(path, dpi=90)
        plt.close(fig)
        paths.append(path)
    return paths
