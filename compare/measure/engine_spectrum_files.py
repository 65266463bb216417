"""Engine spectra as files: CSV rows and the plot (analytic curves, every engine's
points, relative error vs Omega with the cause of each point outside tolerance),
and from stored ``spectrum --engine --json`` documents the summary table and the
plot again (``python -m trilith_xval.compare.measure.engine_spectrum_files``)."""
from __future__ import annotations

import math

from trilith_xval.compare.measure.engine_spectrum import DEFAULT_TOL, EngineSpectrum

__all__ = ["write_csv", "plot", "plot_document", "summary_table", "CSV_FIELDS",
           "SHORT_CAUSE"]


# Labels of the error panel: the cause of each point outside the tolerance.
SHORT_CAUSE = {"model": "model", "jump": "jump", "window": "window", "discretisation": "dt",
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

    from trilith_xval.compare.report.units import g_hz_axes

    fig, (top, low) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.4),
                                   gridspec_kw={"height_ratios": [2, 1]})
    if reference.scene.gamma > 0.0:  # without a pendulum its curve repeats the other
        top.plot(reference.omega, reference.a_pendulum, "k-", lw=1.2, label="model, pendulum")
    top.plot(reference.omega, reference.a_no_pendulum,
             "k--" if reference.scene.gamma > 0.0 else "k-", lw=1.2, label="model, no pendulum")
    for k, jump in enumerate(reference.mode_jumps()):
        for ax in (top, low):
            ax.axvspan(jump["omega_before"], jump["omega_after"], color="0.9", zorder=0,
                       label="model's mode jump" if (k == 0 and ax is top) else None)
    markers = {"pendulum": "o", "no_pendulum": "s"}
    for k, es in enumerate(spectra):
        color = f"C{k}"
        unlabelled = es
        for curve, points in es.curves.items():
            w = [p.omega for p in points]
            fill = "full" if curve == "pendulum" else "none"
            top.plot(w, [p.a_engine for p in points], markers[curve], color=color, ms=4,
                     fillstyle=fill, label=f"{es.engine}, {curve.replace('_', ' ')}")
            lost = [p for p in points if not _finite(p.a_engine)]
            if lost:  # no robust bracket: marked on the model's curve
                top.plot([p.omega for p in lost], [p.a_reference for p in lost], "x",
                         color=color, ms=5, label=None if unlabelled is not es else
                         f"{es.engine}: no robust bracket")
                unlabelled = None
            low.plot(w, [100 * p.rel_error for p in points], markers[curve] + "-", color=color,
                     ms=4, lw=0.7, fillstyle=fill)
            for p in points:
                if p.cause != "agrees" and math.isfinite(p.rel_error):
                    low.annotate(SHORT_CAUSE.get(p.cause, p.cause), (p.omega, 100 * p.rel_error),
                                 fontsize=6, xytext=(2, 2), textcoords="offset points")
    low.axhspan(-100 * tol, 100 * tol, color="C2", alpha=0.12, lw=0)
    low.axhline(0.0, color="0.5", lw=0.6)
    top.set_ylabel(r"first overturning $A_s$ [m/s$^2$]")
    g_hz_axes(top)  # g and Hz beside the SI axes, as on the model's spectrum plots
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


def _finite(x) -> bool:
    return x is not None and math.isfinite(x)


def plot_document(doc: dict, path) -> None:
    """:func:`plot` from a stored ``trilith spectrum --engine --json`` document."""
    from types import SimpleNamespace as NS

    ref = doc["analytic"]
    def values(key):
        return [math.nan if v is None else v for v in ref[key]]

    reference = NS(omega=ref["omega"],
                   # Absent from the document of a scene without a pendulum.
                   a_pendulum=values("a_pendulum") if "a_pendulum" in ref else None,
                   a_no_pendulum=values("a_no_pendulum"),
                   mode_jumps=lambda: ref["mode_jumps"], settings=NS(pulse=ref["pulse"]),
                   scene=NS(**{k: doc["inputs"]["scene"][k] for k in ("lam", "b", "gamma", "mu")}))
    spectra = []
    for name, es in doc["engines"].items():
        curves = {c: [NS(**{k: (math.nan if p[k] is None else p[k]) for k in
                            ("omega", "a_engine", "a_reference", "rel_error")}, cause=p["cause"])
                      for p in pts] for c, pts in es["curves"].items()}
        spectra.append(NS(engine=name, curves=curves))
    plot(reference, spectra, path, tol=next(iter(doc["engines"].values()))["tol"])


def _row(doc: dict, engine: str) -> str:
    """One engine's line of :func:`summary_table` from a ``spectrum --engine --json``
    document."""
    es = doc["engines"][engine]
    pts = [dict(p, curve=c) for c, ps in es["curves"].items() for p in ps]
    ok = [p for p in pts if p["cause"] == "agrees"]
    # The agreement region: up to the first frequency where a point disagrees.
    first_bad = min((p["omega"] for p in pts if p["cause"] != "agrees"), default=math.inf)
    region = [p for p in ok if p["omega"] < first_bad]
    inside = max((p["a_reference"] for p in region), default=math.nan)
    beyond = [p for p in pts if p["omega"] >= first_bad]
    errs = [100 * p["rel_error"] for p in beyond if p["rel_error"] is not None]
    causes: dict[str, int] = {}
    for p in beyond:
        if p["cause"] != "agrees":
            causes[p["cause"]] = causes.get(p["cause"], 0) + 1
    none = sorted({p["omega"] for p in beyond if p["a_engine"] is None})
    iso = sum(len(p["isolated"]) for p in pts)
    cost = es["cost"]
    lo = min((p["omega"] for p in region), default=math.nan)
    hi = max((p["omega"] for p in region), default=math.nan)
    search = math.fsum(p["search_cpu_s"] for p in pts)
    beyond_text = ("none" if not beyond else
                   f"Omega {first_bad:g}-{max(p['omega'] for p in beyond):g}: "
                   + (f"{min(errs):+.1f} to {max(errs):+.1f} %" if errs else "")
                   + (f", no robust bracket at Omega {', '.join(f'{w:g}' for w in none)}"
                      if none else "")
                   + " (" + ", ".join(f"{k} {n}" for k, n in sorted(causes.items())) + ")")
    return (f"| {engine} | {len(ok)} of {len(pts)} | Omega {lo:g}-{hi:g} "
            f"(A <= {inside:.1f} m/s^2), {len(region)} points | {beyond_text} | {iso} "
            f"| {cost['runs']} | {search:.0f} / {cost['cpu_s']:.0f} "
            f"| {cost['cpu_per_sim_s']:.3f} |")


def summary_table(paths) -> str:
    """A Markdown table of the ``spectrum --engine --json`` documents at ``paths``:
    points within the tolerance, the agreement region (every point up to the first
    frequency with a disagreeing point), what lies beyond, isolated overturns, runs
    and CPU seconds when computed (the searches / with the convergence reruns)."""
    from trilith_xval.scenes.safe_read import read_json
    lines = ["| engine | agree within 2 % | region | beyond (error, primary causes) "
             "| isolated overturns | runs | CPU s (search / all) | CPU per simulated s |",
             "|---|---|---|---|---|---|---|---|"]
    for path in paths:
        doc = read_json(path, f"spectrum file {str(path)!r}", schema_versions=(1,))
        lines += [_row(doc, engine) for engine in doc["engines"]]
    return "\n".join(lines)


def main(argv=None) -> int:
    """``FILE.json ...``: print the summary table; ``--plot OUT.png FILE.json``:
    redraw a stored spectrum's figure."""
    import sys
    from pathlib import Path

    from trilith_xval.scenes.safe_read import read_json
    args = list(sys.argv[1:] if argv is None else argv)
    if args[:1] == ["--plot"]:
        out, source = args[1], args[2]
        from trilith_xval.compare.run.atomic import atomic_path
        doc = read_json(source, f"spectrum file {source!r}", schema_versions=(1,))
        with atomic_path(out, Path(out).suffix) as tmp:
            plot_document(doc, tmp)
        return 0
    print(summary_table(args))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
