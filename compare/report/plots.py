"""The report's evidence plots, as inline PNGs (base64 strings).

Each plot puts the engines on the analytic reference *and* shows the error
explicitly in its own panel, so agreement is read off a scale rather than
guessed from overlapping curves:

* :func:`spectra_figure`: engine threshold points on the reference spectra; below,
  relative error vs Omega with the tolerance band and the mode jumps marked.
* :func:`convergence_figure`: relative error vs time step for the points that
  failed (when the campaign measured a step-convergence study).
* :func:`history_figure`: theta/alpha at one of the paper's points; below,
  ``|theta_engine - theta_model| / alpha`` vs time, first impact marked.
* :func:`restitution_figure`: relative error of every impact against Eq. 20/19.
"""
from __future__ import annotations

import base64
import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

from compare.report.trust import label  # noqa: E402

__all__ = ["spectra_figure", "convergence_figure", "history_figure", "restitution_figure",
           "color", "marker", "DPI"]



def color(name: str) -> str | None:
    """A backend's plot colour (its class's ``color``; None: matplotlib's cycle)."""
    return _style(name, "color", None)


def marker(name: str) -> str:
    """A backend's plot marker (its class's ``marker``; 'o' if not registered)."""
    return _style(name, "marker", "o")


def _style(name: str, attr: str, default):
    from engines import get_backend
    try:
        return getattr(get_backend(name), attr)
    except ValueError:
        return default

# 100 dpi on figures 7 in wide: 700 px, sharp on a laptop, scaled down on a phone.
DPI = 100
_CASES = {"pendulum": "with pendulum", "no_pendulum": "without pendulum"}


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _arr(values) -> np.ndarray:
    return np.asarray([np.nan if v is None else v for v in values], dtype=float)


def _jump_omegas(spec: dict) -> list[float]:
    ws = [jp["omega"] for jp in spec.get("jumps", [])]
    tip = (spec.get("jump") or {}).get("omega_tip")
    return ws + ([tip] if tip is not None else [])


def spectra_figure(doc: dict) -> str | None:
    """Engine thresholds on the reference spectra (top) and their relative error
    [%] against Omega with the +-tolerance band (bottom), one column per case."""
    cases = [c for c in ("pendulum", "no_pendulum") if c in doc.get("spectra", {})]
    if not cases:
        return None
    tol = 100.0 * doc["config"]["tolerances"]["threshold"]
    fig, axes = plt.subplots(2, len(cases), figsize=(3.6 * len(cases), 4.6), squeeze=False,
                             sharex="col", gridspec_kw={"height_ratios": [2, 1.2]})
    for col, case in enumerate(cases):
        spec = doc["spectra"][case]
        top, bot = axes[0, col], axes[1, col]
        w, a = _arr(spec["omega"]), _arr(spec["a"])
        for jp in spec.get("jumps", []):  # no line across a jump: the curve is discontinuous
            i = int(np.searchsorted(w, jp["omega_hi"]))
            w, a = np.insert(w, i, np.nan), np.insert(a, i, np.nan)
        top.plot(w, a, "k-", lw=1.0, label="model")
        bot.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0,
                    label=f"±{tol:g} % tolerance")
        bot.axhline(0.0, color="0.5", lw=0.6)
        for name, pts in spec.get("engines", {}).items():
            style = dict(color=color(name), marker=marker(name), ls="none",
                         mfc="none", ms=5)
            top.plot([p["omega"] for p in pts], _arr([p["a_engine"] for p in pts]),
                     label=label(name), **style)
            bot.plot([p["omega"] for p in pts],
                     100.0 * _arr([p["rel_error"] for p in pts]), **style)
        for k, wj in enumerate(_jump_omegas(spec)):
            for ax in (top, bot):
                ax.axvline(wj, color="tab:red", lw=0.7, ls=":",
                           label="mode jump" if (k == 0 and ax is top) else None)
        top.set_title(_CASES.get(case, case), fontsize=9)
        top.set_ylabel("first overturning A [m/s²]", fontsize=8)
        bot.set_ylabel("engine / model − 1 [%]", fontsize=8)
        bot.set_xlabel("Ω [rad/s]", fontsize=8)
        lim = max([2.0 * tol] + [abs(v) * 1.2 for v in
                                 100.0 * _arr([p["rel_error"] for pts in
                                               spec.get("engines", {}).values() for p in pts])
                                 if math.isfinite(v)])
        bot.set_ylim(-lim, lim)
        for ax in (top, bot):
            ax.tick_params(labelsize=7)
        top.legend(fontsize=7, frameon=False)
    axes[1, 0].legend(fontsize=7, frameon=False, loc="lower left")
    fig.tight_layout()
    return _png(fig)


def _convergence(point: dict) -> tuple[np.ndarray, np.ndarray] | None:
    rows = point.get("convergence") or []
    dts, errs = [], []
    for r in rows:
        if isinstance(r, dict):
            dt, err = r.get("dt"), r.get("rel_error")
        else:
            dt, err = r[0], r[2] if len(r) > 2 else None
        if dt is not None and err is not None:
            dts.append(float(dt))
            errs.append(float(err))
    return (np.array(dts), np.array(errs)) if dts else None


def convergence_figure(doc: dict) -> str | None:
    """Relative threshold error against the engine time step for every point
    that carries a step-convergence study (a flat line away from zero: the
    disagreement is not discretisation); None when no point does."""
    series = []
    for case, spec in doc.get("spectra", {}).items():
        for name, pts in spec.get("engines", {}).items():
            for p in pts:
                conv = _convergence(p)
                if conv is not None:
                    series.append((name, case, p, conv))
    if not series:
        return None
    tol = 100.0 * doc["config"]["tolerances"]["threshold"]
    fig, ax = plt.subplots(figsize=(5.0, 3.2))
    ax.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0, label=f"±{tol:g} % tolerance")
    ax.axhline(0.0, color="0.5", lw=0.6)
    for name, case, p, (dt, err) in series:
        order = np.argsort(dt)
        ax.semilogx(dt[order], 100.0 * err[order], marker=marker(name),
                    color=color(name), lw=0.9, ms=4,
                    label=f"{label(name)}, Ω = {p['omega']:g} ({_CASES.get(case, case)})")
    ax.set_xlabel("engine time step dt [s]", fontsize=8)
    ax.set_ylabel("engine / model − 1 [%]", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6, frameon=False)
    fig.tight_layout()
    return _png(fig)


def _error_vs_time(ref, traj, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    from compare.measure.trajectories import GRID_DT, common_grid_values

    t_end = min(float(ref.t[-1]), float(traj.t[-1]))
    t0 = max(float(ref.t[0]), float(traj.t[0]))
    if t_end <= t0:
        return np.array([]), np.array([])
    grid = np.arange(t0, t_end, GRID_DT)
    err = np.abs(common_grid_values(traj, "theta", grid)
                 - common_grid_values(ref, "theta", grid)) / alpha
    return grid, err


def history_figure(histories: dict, point: str, alphas: dict, reference: str,
                   title: str) -> str | None:
    """theta/alpha of every backend at ``point`` (top) and the engines' error
    ``|theta - theta_model|/alpha`` on a log scale (bottom); one column per case.

    ``histories``: ``(point, pendulum, backend) -> Trajectory``; ``alphas``:
    ``pendulum -> alpha`` [rad].  The model's first impact is a dotted line:
    before it the error measures the integration, after it the impact model.
    """
    cases = sorted({p for (pt, p, _) in histories if pt == point}, reverse=True)
    if not cases:
        return None
    fig, axes = plt.subplots(2, len(cases), figsize=(3.6 * len(cases), 4.4), squeeze=False,
                             sharex="col", gridspec_kw={"height_ratios": [1.5, 1]})
    for col, pend in enumerate(cases):
        top, bot = axes[0, col], axes[1, col]
        alpha = alphas[pend]
        ref = histories.get((point, pend, reference))
        for (pt, p, name), traj in sorted(histories.items(), key=lambda kv: str(kv[0])):
            if pt != point or p != pend:
                continue
            is_ref = name == reference
            top.plot(traj.t, traj.theta / alpha, color=color(name), lw=1.4 if is_ref else 0.9,
                     ls="-" if is_ref else "--", label=label(name), zorder=1 if is_ref else 2)
            if ref is not None and not is_ref:
                grid, err = _error_vs_time(ref, traj, alpha)
                if grid.size:
                    bot.semilogy(grid, np.maximum(err, 1e-7), color=color(name), lw=0.8,
                                 label=label(name))
        if ref is not None and ref.impacts:
            for ax in (top, bot):
                ax.axvline(ref.impacts[0].t, color="0.4", lw=0.7, ls=":")
            top.annotate("1st impact", (ref.impacts[0].t, 1.6), fontsize=6, color="0.3",
                         xytext=(2, 0), textcoords="offset points")
        for y in (-1.0, 1.0):
            top.axhline(y, color="0.75", lw=0.5)
        top.set_ylim(-2.0, 2.0)
        top.set_title(f"{title}, {'with' if pend else 'without'} pendulum", fontsize=8)
        top.set_ylabel("θ / α", fontsize=8)
        bot.set_ylabel("|θ − θ_model| / α", fontsize=8)
        bot.set_xlabel("t [s]", fontsize=8)
        bot.set_ylim(1e-7, 10.0)
        for ax in (top, bot):
            ax.tick_params(labelsize=7)
        top.legend(fontsize=6, frameon=False, loc="lower left")
    fig.tight_layout()
    return _png(fig)


def restitution_figure(doc: dict) -> str | None:
    """Relative error of each measured impact against Eq. 20 (left) and Eq. 19
    at the measured psi (right), with the tolerance band."""
    rows = doc.get("restitution", [])
    groups = [(False, "Eq. 20 (no pendulum)", "restitution"),
              (True, "Eq. 19 (with pendulum)", "restitution_pendulum")]
    groups = [g for g in groups if any(r["pendulum"] == g[0] for r in rows)]
    if not groups:
        return None
    fig, axes = plt.subplots(1, len(groups), figsize=(3.6 * len(groups), 2.8), squeeze=False,
                             sharey=True)
    for ax, (pend, title, key) in zip(axes[0], groups):
        tol = 100.0 * doc["config"]["tolerances"][key]
        ax.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0, label=f"±{tol:g} %")
        ax.axhline(0.0, color="0.5", lw=0.6)
        seen = set()
        for r in (r for r in rows if r["pendulum"] == pend):
            name = r["backend"]
            errs = [100.0 * i["rel_error"] for i in r["impacts"] if i.get("rel_error") is not None]
            ax.plot(np.arange(1, len(errs) + 1), errs, marker=marker(name), ms=4,
                    lw=0.7, color=color(name),
                    label=label(name) if name not in seen else None)
            seen.add(name)
        ax.set_title(title, fontsize=8)
        ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
        ax.set_xlabel("impact number", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, frameon=False)
    axes[0, 0].set_ylabel("measured / predicted − 1 [%]", fontsize=8)
    fig.tight_layout()
    return _png(fig)
