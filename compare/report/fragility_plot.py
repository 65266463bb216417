"""The fragility figure (``trilith fragility``): P(overturn | IM) per backend."""
from __future__ import annotations

import math

from trilith_xval.analytic.excitation import G_STANDARD
from trilith_xval.analytic.ida import IM_UNITS, IDASettings

__all__ = ["plot_fragility", "IM_TEXT"]

# The intensity measures' names on axes and in tables.
IM_TEXT = {"pga": "PGA", "pgv": "PGV", "scale": "scale factor"}


def plot_fragility(path, doc: dict, st: IDASettings) -> None:
    """The fragility figure of a ``trilith fragility`` result ``doc``: per backend the
    empirical overturning fraction (steps), the lognormal fit (line) and its 90 %
    band, with ``--stripes`` the stripes' overturned fractions (circles) and their
    fit (dashes), against the intensity measure of ``st`` (PGA with g on the top
    axis), written atomically to ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from scipy import stats

    from trilith_xval.compare.run.atomic import savefig
    from trilith_xval.compare.measure.fragility import empirical_curve
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    from trilith_xval.compare.report.plots import color
    colours = {b: "k" if b == "analytic" else color(b) for b in doc["backends"]}
    for b, body in doc["backends"].items():
        fit, c = body["fit"], colours.get(b, None)
        if fit is None:  # no record with a robust bracket: nothing to draw
            continue
        ims = np.array([math.inf if v is None else v for v in fit["im"]])
        x, f = empirical_curve(ims)
        if x.size:
            ax.step(np.concatenate([[x[0] / 2], x]), np.concatenate([[0.0], f]), where="post",
                    color=c, alpha=0.6, lw=1.0)
        grid = np.array(fit["band"]["im"])
        if fit["median"] is not None:
            curve = stats.norm.cdf(np.log(grid / fit["median"]) / fit["beta"])
            ax.plot(grid, curve, color=c, lw=1.8,
                    label=f"{b}: median {fit['median']:.3g}, beta {fit['beta']:.2f}")
            lo = np.array([np.nan if v is None else v for v in fit["band"]["lower"]])
            hi = np.array([np.nan if v is None else v for v in fit["band"]["upper"]])
            ax.fill_between(grid, lo, hi, color=c, alpha=0.12, lw=0)
        msa = body.get("msa")
        if msa:  # the stripes' overturned fractions (dots) and their fit (dashes)
            xs = np.array(msa["stripes"])
            ax.plot(xs, np.array(msa["overturned"]) / np.array(msa["n"]), "o", color=c,
                    ms=4, mfc="none")
            if msa["median"] is not None:
                ax.plot(grid, stats.norm.cdf(np.log(grid / msa["median"]) / msa["beta"]),
                        "--", color=c, lw=1.2, label=f"{b} MSA: median {msa['median']:.3g}, "
                                                    f"beta {msa['beta']:.2f}")
    ax.set_xscale("log")
    unit = IM_UNITS[st.im]
    ax.set_xlabel(f"{IM_TEXT[st.im]}" + (f" [{unit}]" if unit else ""))
    # Plain numbers on the log axes (matplotlib's default writes 2 x 10^0 and
    # overlaps the minor labels); in g on the top axis at the values engineers use.
    from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter
    ax.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 3.0, 5.0, 7.0)))
    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    if st.im == "pga":
        sec = ax.secondary_xaxis("top", functions=(lambda a: a / G_STANDARD,
                                                   lambda g: g * G_STANDARD))
        sec.xaxis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 3.0, 5.0, 7.0)))
        sec.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        sec.xaxis.set_minor_formatter(NullFormatter())
        sec.set_xlabel("PGA [g]")
    # A scene of another kind: the engines' failures (overturn or collapse), no model.
    kinds = doc.get("engine_against_engine", False)
    ax.set_ylabel("P(failure | IM)" if kinds else "P(overturn | IM)")
    ax.set_ylim(0.0, 1.0)
    if ax.get_legend_handles_labels()[1]:  # no fit (fewer than 2 overturns): no line
        ax.legend(fontsize=8, loc="upper left")
    pendulum = "" if doc["scene"].get("gamma", 0.0) > 0.0 else " without pendulum"
    msa = any(body.get("msa") for body in doc["backends"].values())
    ax.set_title(f"{doc['scene'].get('name', '')}{pendulum}: {len(doc['records'])} records\n"
                 "steps: empirical; lines: IDA lognormal fit, 90 % band"
                 + ("; circles, dashes: MSA stripes and fit" if msa else "")
                 + (f"\n{doc['kind']}: no model; engine against engine" if kinds else ""),
                 fontsize=8)
    fig.tight_layout()
    savefig(fig, path, dpi=120)
    plt.close(fig)
