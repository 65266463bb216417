"""The report's evidence plots, as inline PNGs (base64 strings).

Each plot puts the engines on the analytic reference *and* shows the error
explicitly in its own panel, so agreement is read off a scale rather than
guessed from overlapping curves:

* :func:`spectra_figures`: engine threshold points on the reference spectrum, one
  figure per case; below, relative error vs Omega with the tolerance band, the
  mode jumps marked and the frequencies where the model is invalid hatched.
* :func:`convergence_figure`: relative error vs time step for the points that
  failed (when the campaign measured a convergence study); doubled solver
  iterations are separate markers, never a point of the step line.
* :func:`history_figures`: theta/alpha at one of the paper's points, one figure
  per case; below, ``|theta_engine - theta_model| / alpha`` vs time.
* :func:`restitution_figures`: relative error of every impact against Eq. 20/19.

Sizes: one case per figure, 5 in wide at :data:`DPI` (1000 px); the page sets
two side by side in its 1100 px column (text about 13 px on screen) and one
above the other on a phone (about 9 px at 390 px).

Each figure is drawn in two steps: the data it plots is gathered first (plain
numbers, lists and arrays, the backends' labels and styles included), then a
``_draw_*`` function draws only that.  The PNG is kept in the run store under a
key of that data (:mod:`compare.report.figure_cache`), so a report rebuilt from
stored runs redraws nothing.
"""
from __future__ import annotations

import io
import math

import numpy as np

from trilith_xval.analytic.threshold_validity import invalid_spans
from trilith_xval.compare.report import figure_cache
from trilith_xval.compare.report.trust import label
from trilith_xval.compare.report.units import g_hz_axes

__all__ = ["spectra_figures", "convergence_figure", "convergence_axes", "history_figures",
           "restitution_figures", "shade_invalid", "color", "marker", "DPI", "WIDTH"]


def color(name: str) -> str | None:
    """A backend's plot colour (its class's ``color``; None: matplotlib's cycle)."""
    return _style(name, "color", None)


def marker(name: str) -> str:
    """A backend's plot marker (its class's ``marker``; 'o' if not registered)."""
    return _style(name, "marker", "o")


def _style(name: str, attr: str, default):
    from trilith_xval.engines import get_backend
    try:
        return getattr(get_backend(name), attr)
    except ValueError:
        return default


DPI = 200  # 5 in -> 1000 px: sharp at the page's 540 px per figure on a 2x screen
WIDTH = 5.0  # in
# 9 pt text at 200 dpi is 25 px in the PNG: ~13 px shown at 540 px, ~9 px on a phone.
_RC = {"font.size": 9, "axes.titlesize": 9.5, "axes.labelsize": 9, "xtick.labelsize": 8.5,
       "ytick.labelsize": 8.5, "legend.fontsize": 8.5, "legend.frameon": False}
_CASES = {"pendulum": "with pendulum", "no_pendulum": "without pendulum"}


def _pyplot():
    """matplotlib's pyplot on the Agg backend, imported by the first figure drawn
    (0.3-0.5 CPU s): a report whose figures all come from the store never needs it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
    _pyplot().close(fig)
    return buf.getvalue()


# Everything besides the data and this module's code that changes a figure.
_OPTIONS = {"dpi": DPI, "width": WIDTH, "rc": _RC, "format": "png", "bbox": "tight"}


def _figure(name: str, data: dict, draw) -> str:
    """``draw(data)`` (a Figure) as a base64 PNG, through the figure cache; drawn
    and saved under the report's type sizes (ticks are laid out when saved)."""
    def render() -> bytes:
        with _pyplot().rc_context(_RC):
            return _png(draw(data))
    return figure_cache.png_base64(name, data, _OPTIONS, render)


def _style_of(name: str) -> dict:
    """What a backend's points look like: its label, colour and marker."""
    return {"name": name, "label": label(name), "color": color(name), "marker": marker(name)}


def _arr(values) -> np.ndarray:
    return np.asarray([np.nan if v is None else v for v in values], dtype=float)


def _jump_omegas(spec: dict) -> list[float]:
    ws = [jp["omega"] for jp in spec.get("jumps", [])]
    tip = (spec.get("jump") or {}).get("omega_tip")
    return ws + ([tip] if tip is not None else [])


def shade_invalid(axes, omega, valid, label_it: bool = True) -> bool:
    """Hatch the frequencies where the model is invalid on its threshold run
    (``valid`` False; None: not checked) on every axis of ``axes``; True when
    something was shaded."""
    spans = invalid_spans(omega, valid)
    for k, (lo, hi) in enumerate(spans):
        for j, ax in enumerate(axes):
            ax.axvspan(lo, hi, facecolor="0.88", edgecolor="0.6", hatch="///", lw=0, zorder=0,
                       label="model invalid" if (label_it and k == 0 and j == 0) else None)
    return bool(spans)


def _spectrum_data(doc: dict, case: str) -> dict:
    spec = doc["spectra"][case]
    validity = spec.get("model_validity")
    return {"title": _CASES.get(case, case),
            "tol": 100.0 * doc["config"]["tolerances"]["threshold"],
            "omega": _arr(spec["omega"]), "a": _arr(spec["a"]),
            "valid": [v.get("model_valid") for v in validity] if validity else None,
            "breaks": [jp["omega_hi"] for jp in spec.get("jumps", [])],
            "jumps": _jump_omegas(spec),
            "engines": [{**_style_of(name), "omega": _arr([p["omega"] for p in pts]),
                         "a": _arr([p["a_engine"] for p in pts]),
                         "error": 100.0 * _arr([p["rel_error"] for p in pts])}
                        for name, pts in spec.get("engines", {}).items()]}


def _draw_spectrum(d: dict):
    tol = d["tol"]
    fig, (top, bot) = _pyplot().subplots(2, 1, figsize=(WIDTH, 5.0), sharex=True,
                                   gridspec_kw={"height_ratios": [2, 1.2]})
    w, a = d["omega"], d["a"]
    if d["valid"]:
        shade_invalid((top, bot), w, d["valid"])
    for hi in d["breaks"]:  # no line across a jump: the curve is discontinuous
        i = int(np.searchsorted(w, hi))
        w, a = np.insert(w, i, np.nan), np.insert(a, i, np.nan)
    top.plot(w, a, "k-", lw=1.0, label="model")
    bot.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0, label=f"±{tol:g} % tolerance")
    bot.axhline(0.0, color="0.5", lw=0.6)
    for eng in d["engines"]:
        style = dict(color=eng["color"], marker=eng["marker"], ls="none", mfc="none", ms=6)
        top.plot(eng["omega"], eng["a"], label=eng["label"], **style)
        bot.plot(eng["omega"], eng["error"], **style)
    for k, wj in enumerate(d["jumps"]):
        for ax in (top, bot):
            ax.axvline(wj, color="tab:red", lw=0.8, ls=":",
                       label="mode jump" if (k == 0 and ax is top) else None)
    top.set_title(d["title"], loc="left")
    top.set_ylabel("first overturning A [m/s²]")
    bot.set_ylabel("engine / model − 1 [%]")
    bot.set_xlabel("Ω [rad/s]")
    g_hz_axes(top)
    lim = max([2.0 * tol] + [abs(v) * 1.2 for eng in d["engines"] for v in eng["error"]
                             if math.isfinite(v)])
    bot.set_ylim(-lim, lim)
    # One legend, on the spectrum's empty upper left: the error panel's points
    # can lie anywhere in it.
    handles, labels = top.get_legend_handles_labels()
    extra = bot.get_legend_handles_labels()
    top.legend(handles + extra[0], labels + extra[1], loc="upper left")
    fig.tight_layout()
    return fig


def spectra_figures(doc: dict) -> list[tuple[str, str]]:
    """``[(case, png)]``: engine thresholds on the reference spectrum (top) and
    their relative error [%] against Omega with the +-tolerance band (bottom),
    one figure per case (with, then without pendulum)."""
    return [(case, _figure("spectrum", _spectrum_data(doc, case), _draw_spectrum))
            for case in ("pendulum", "no_pendulum") if case in doc.get("spectra", {})]


def _convergence(point: dict) -> tuple[np.ndarray, np.ndarray, list[tuple]] | None:
    """A point's convergence rows split by their ``kind``: the step study
    (``dt``, ``rel_error`` arrays of the 'dt' rows) and the solver-iteration
    rows ``[(dt, rel_error, iterations)]`` (same step, doubled iterations), which
    are not a point of the step line."""
    rows = point.get("convergence") or []
    dts, errs, more = [], [], []
    for r in rows:
        if isinstance(r, dict):
            kind, dt, err = r.get("kind", "dt"), r.get("dt"), r.get("rel_error")
        else:
            kind, dt, err = "dt", r[0], r[2] if len(r) > 2 else None
        if dt is None or err is None:
            continue
        if kind == "iterations":
            more.append((float(dt), float(err), r.get("iterations")))
        else:
            dts.append(float(dt))
            errs.append(float(err))
    return (np.array(dts), np.array(errs), more) if (dts or more) else None


def convergence_axes(ax, series: list[tuple], tol: float) -> None:
    """Draw ``series`` ``[(engine, case, point, (dt, err, iteration_rows))]`` on
    ``ax``: the step study as one line per point, the doubled-iteration runs as
    separate open markers at their step, labelled with the iteration count."""
    ax.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0, label=f"±{tol:g} % tolerance")
    ax.axhline(0.0, color="0.5", lw=0.6)
    for name, case, p, (dt, err, more) in series:
        where = f"{label(name)}, Ω = {p['omega']:g} ({_CASES.get(case, case)})"
        if dt.size:
            order = np.argsort(dt)
            ax.semilogx(dt[order], 100.0 * err[order], marker=marker(name),
                        color=color(name), lw=0.9, ms=4, label=f"{where}: dt, dt/2, dt/4")
        for dt_i, err_i, iterations in more:
            count = "" if iterations is None else f" ({iterations})"
            ax.semilogx([dt_i], [100.0 * err_i], marker="*", ls="none", ms=8,
                        markerfacecolor="none", color=color(name),
                        label=f"{where}: doubled solver iterations{count}")
    ax.set_xlabel("engine time step dt [s]")
    ax.set_ylabel("engine / model − 1 [%]")
    # Below the axes: the labels are long and the points may sit anywhere.
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.2))


def convergence_figure(doc: dict) -> str | None:
    """Relative threshold error against the engine time step for every point
    that carries a convergence study (a flat line away from zero: the
    disagreement is not discretisation), the doubled-iteration runs as separate
    markers (:func:`convergence_axes`); None when no point carries one."""
    series = []
    for case, spec in doc.get("spectra", {}).items():
        for name, pts in spec.get("engines", {}).items():
            for p in pts:
                conv = _convergence(p)
                if conv is not None:
                    dt, err, more = conv
                    series.append({"name": name, "case": case, "omega": p["omega"],
                                   "dt": dt, "err": err, "more": [list(m) for m in more]})
    if not series:
        return None
    data = {"tol": 100.0 * doc["config"]["tolerances"]["threshold"], "series": series}
    return _figure("convergence", data, _draw_convergence)


def _draw_convergence(d: dict):
    fig, ax = _pyplot().subplots(figsize=(WIDTH, 3.4))
    convergence_axes(ax, [(s["name"], s["case"], {"omega": s["omega"]},
                           (np.asarray(s["dt"], dtype=float), np.asarray(s["err"], dtype=float),
                            [tuple(m) for m in s["more"]]))
                          for s in d["series"]], d["tol"])
    fig.tight_layout()
    return fig


def _error_vs_time(ref, traj, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    from trilith_xval.compare.measure.trajectories import GRID_DT, common_grid_values

    t_end = min(float(ref.t[-1]), float(traj.t[-1]))
    t0 = max(float(ref.t[0]), float(traj.t[0]))
    if t_end <= t0:
        return np.array([]), np.array([])
    grid = np.arange(t0, t_end, GRID_DT)
    err = np.abs(common_grid_values(traj, "theta", grid)
                 - common_grid_values(ref, "theta", grid)) / alpha
    return grid, err


def _history_data(histories: dict, point: str, pend: bool, alpha: float, reference: str,
                  title: str) -> dict:
    ref = histories.get((point, pend, reference))
    lines = []
    for (pt, p, name), traj in sorted(histories.items(), key=lambda kv: str(kv[0])):
        if pt != point or p != pend:
            continue
        line = {**_style_of(name), "reference": name == reference, "t": np.asarray(traj.t),
                "theta": np.asarray(traj.theta) / alpha, "grid": None, "error": None}
        if ref is not None and name != reference:
            grid, err = _error_vs_time(ref, traj, alpha)
            if grid.size:
                line.update(grid=grid, error=np.maximum(err, 1e-7))
        lines.append(line)
    first_impact = float(ref.impacts[0].t) if ref is not None and ref.impacts else None
    return {"title": f"{title}, {'with' if pend else 'without'} pendulum", "lines": lines,
            "first_impact": first_impact}


def _draw_history(d: dict):
    fig, (top, bot) = _pyplot().subplots(2, 1, figsize=(WIDTH, 4.6), sharex=True,
                                   gridspec_kw={"height_ratios": [1.5, 1]})
    for line in d["lines"]:
        is_ref = line["reference"]
        top.plot(line["t"], line["theta"], color=line["color"], lw=1.5 if is_ref else 1.0,
                 ls="-" if is_ref else "--", label=line["label"], zorder=1 if is_ref else 2)
        if line["grid"] is not None:
            bot.semilogy(line["grid"], line["error"], color=line["color"], lw=0.9,
                         label=line["label"])
    if d["first_impact"] is not None:
        for ax in (top, bot):
            ax.axvline(d["first_impact"], color="0.4", lw=0.7, ls=":")
        top.annotate("1st impact", (d["first_impact"], 1.6), color="0.3",
                     xytext=(2, 0), textcoords="offset points")
    for y in (-1.0, 1.0):
        top.axhline(y, color="0.75", lw=0.5)
    top.set_ylim(-2.0, 2.0)
    top.set_title(d["title"])
    top.set_ylabel("θ / α")
    bot.set_ylabel("|θ − θ_model| / α")
    bot.set_xlabel("t [s]")
    bot.set_ylim(1e-7, 10.0)
    top.legend(loc="lower left", ncol=2)
    fig.tight_layout()
    return fig


def history_figures(histories: dict, point: str, alphas: dict, reference: str,
                    title: str) -> list[str]:
    """theta/alpha of every backend at ``point`` (top) and the engines' error
    ``|theta - theta_model|/alpha`` on a log scale (bottom); one figure per case
    (with, then without pendulum).

    ``histories``: ``(point, pendulum, backend) -> Trajectory``; ``alphas``:
    ``pendulum -> alpha`` [rad].  The model's first impact is a dotted line:
    before it the error measures the integration, after it the impact model.
    """
    cases = sorted({p for (pt, p, _) in histories if pt == point}, reverse=True)
    return [_figure("history", _history_data(histories, point, pend, alphas[pend], reference,
                                              title), _draw_history)
            for pend in cases]


def _restitution_data(doc: dict, pend: bool, title: str, key: str) -> dict:
    rows = [r for r in doc.get("restitution", []) if r["pendulum"] == pend]
    return {"title": title, "tol": 100.0 * doc["config"]["tolerances"][key],
            "rows": [{**_style_of(r["backend"]),
                      "error": [100.0 * i["rel_error"] for i in r["impacts"]
                                if i.get("rel_error") is not None]} for r in rows]}


def _draw_restitution(d: dict):
    fig, ax = _pyplot().subplots(figsize=(WIDTH, 3.8))
    tol = d["tol"]
    ax.axhspan(-tol, tol, color="tab:green", alpha=0.15, lw=0, label=f"±{tol:g} %")
    ax.axhline(0.0, color="0.5", lw=0.6)
    seen = set()
    for r in d["rows"]:
        errs = r["error"]
        ax.plot(np.arange(1, len(errs) + 1), errs, marker=r["marker"], ms=5, lw=0.8,
                color=r["color"], label=r["label"] if r["name"] not in seen else None)
        seen.add(r["name"])
    ax.set_title(d["title"])
    from matplotlib.ticker import MaxNLocator
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("impact number")
    ax.set_ylabel("measured / predicted − 1 [%]")
    # Below the axes: with five engines' lines spread over the band, no corner
    # of the axes is free of data.
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3)
    fig.tight_layout()
    return fig


def restitution_figures(doc: dict) -> list[str]:
    """Relative error of each measured impact against Eq. 20 (no pendulum) and
    Eq. 19 at the measured psi (with it), with the tolerance band; one figure per
    equation that the campaign measured."""
    rows = doc.get("restitution", [])
    groups = [(False, "Eq. 20 (no pendulum)", "restitution"),
              (True, "Eq. 19 (with pendulum)", "restitution_pendulum")]
    return [_figure("restitution", _restitution_data(doc, *g), _draw_restitution)
            for g in groups if any(r["pendulum"] == g[0] for r in rows)]
