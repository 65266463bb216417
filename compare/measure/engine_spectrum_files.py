"""Engine spectra as files: CSV rows and the plot (analytic curves, every engine's
points, relative error vs Omega with the cause of each point outside tolerance)."""
from __future__ import annotations

import math

from compare.measure.engine_spectrum import DEFAULT_TOL, EngineSpectrum

__all__ = ["write_csv", "plot", "CSV_FIELDS"]


# Labels of the error panel: the cause of each point outside the tolerance.
_SHORT = {"model": "model", "jump": "jump", "window": "window", "discretisation": "dt",
          "iterations": "iter", "contact": "contact", "sensitivity": "sens", "unknown": "?",
          "no-bracket": "none"}

CSV_FIELDS = ("engine", "curve", "omega", "a_reference", "a_engine", "a_survives", "rel_error",
              "rel_resolution", "mode_reference", "mode_engine", "n_runs", "collapsed_below",
              "valid", "cause", "cause_detail", "cpu_s")


def write_csv(spectra: list[EngineSpectrum], path) -> None:
    """One row per engine, curve and frequency (:data:`CSV_FIELDS`)."""
    import csv
    import io
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_FIELDS + ("isolated",))
    for es in spectra:
        for curve, points in es.curves.items():
            for p in points:
                d = p.to_dict()
                w.writerow([es.engine, curve] + [d[k] for k in CSV_FIELDS[2:]]
                           + ["; ".join(f"{i['amplitude']:.6g}" for i in d["isolated"])])
    from pathlib import Path
    Path(path).write_text(buf.getvalue())


def plot(reference, spectra: list[EngineSpectrum], path, tol: float = DEFAULT_TOL) -> None:
    """The analytic curves with every engine's points, and the relative error vs
    Omega below (tolerance band, mode jumps shaded)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, low) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.4),
                                   gridspec_kw={"height_ratios": [2, 1]})
    top.plot(reference.omega, reference.a_pendulum, "k-", lw=1.2, label="model, pendulum")
    top.plot(reference.omega, reference.a_no_pendulum, "k--", lw=1.2, label="model, no pendulum")
    for jump in reference.mode_jumps():
        for ax in (top, low):
            ax.axvspan(jump["omega_before"], jump["omega_after"], color="0.9", zorder=0)
    markers = {"pendulum": "o", "no_pendulum": "s"}
    for k, es in enumerate(spectra):
        color = f"C{k}"
        for curve, points in es.curves.items():
            w = [p.omega for p in points]
            fill = "full" if curve == "pendulum" else "none"
            top.plot(w, [p.a_engine for p in points], markers[curve], color=color, ms=4,
                     fillstyle=fill, label=f"{es.engine}, {curve.replace('_', ' ')}")
            low.plot(w, [100 * p.rel_error for p in points], markers[curve] + "-", color=color,
                     ms=4, lw=0.7, fillstyle=fill)
            for p in points:
                if p.cause != "agrees" and math.isfinite(p.rel_error):
                    low.annotate(_SHORT.get(p.cause, p.cause), (p.omega, 100 * p.rel_error),
                                 fontsize=6, xytext=(2, 2), textcoords="offset points")
    low.axhspan(-100 * tol, 100 * tol, color="C2", alpha=0.12, lw=0)
    low.axhline(0.0, color="0.5", lw=0.6)
    top.set_ylabel(r"first overturning $A_s$ [m/s$^2$]")
    low.set_ylabel("engine error [%]")
    low.set_xlabel(r"$\Omega$ [rad/s]")
    top.legend(fontsize=7, ncol=2)
    sc = reference.scene
    top.set_title(f"{reference.settings.pulse} pulse, $\\lambda$={sc.lam:g}, b={sc.b:g} m, "
                  f"$\\gamma$={sc.gamma:g}, $\\mu$={sc.mu:g}; band: $\\pm${100 * tol:g} %",
                  fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
