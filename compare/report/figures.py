"""The paper's overturning-spectrum figures (Figs. 5, 8, 9, 10, 11), recomputed.

Plotting and bookkeeping only: every number comes from
:func:`analytic.spectrum.overturning_spectrum` (paper Section 5.2: the first
overturning amplitude of a one-sine, Eq. 22, or one-cosine, Eq. 23, pulse per
frequency; gain ``Delta = 100 (A_yp - A_np) / A_np``).  The scenes are the
shipped scene files (``scenes/data/fig*.toml``); their header comments say which
parameter values the OCR text states and which are our reading.

Layouts follow the captions:

* Fig. 5: (a) both spectra (dashed: without pendulum, solid: with), (b) Delta;
  one-sine, lam = 5, b = 0.6 m, gamma = 0.3, mu = 1.
* Fig. 8: rows lam in {3, 5, 7}, columns gamma in {0.1, 0.2, 0.3}; b = 0.6, mu = 1.
* Fig. 9: rows lam in {3, 5, 7}, columns b in {0.2, 0.4, 0.6, 0.8} m; gamma = 0.3, mu = 1.
* Fig. 10: one-cosine, b = 0.4 m, gamma = 0.3, mu = 1, lam in {3, 5, 7}.
* Fig. 11: lam = 5, b = 0.6 m, gamma = 0.3, mu in {0.5, 1, 2, 4}.

Mode jumps (a change between 'after-impact' and 'no-impact' overturning between
two neighbouring frequencies, Section 5.2, the paper's dashed circles) are
marked by dashed circles between the two points.  Frequencies where the model
itself is invalid on its threshold run (a contact would pull, or the bob would
meet a column: :mod:`analytic.threshold_validity`) are hatched, and every
panel's JSON carries the per-point validity of both curves.  A ``--quick`` run
says so in every caption and in ``figures.json``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from trilith_xval.analytic.spectrum import Spectrum, SpectrumSettings, overturning_spectrum
from trilith_xval.analytic.threshold_validity import invalid_spans, spectrum_validity
from trilith_xval.compare.run import atomic
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.scenes import load_scene

__all__ = ["FigureSettings", "Panel", "FigureSpec", "FIGURES", "compute_spectra", "output_names",
           "plot_figure", "make_figures", "omega_grid", "quick_settings", "figure_size",
           "check_output_options", "plain_text", "QUICK_MARK", "shade_validity",
           "FORMATS", "DEFAULT_DPI"]

from trilith_xval.compare.report.figure_options import DEFAULT_DPI, FORMATS, check_output_options  # noqa: F401
SINGLE_COLUMN, DOUBLE_COLUMN = 3.5, 7.0  # in: one and two journal columns


@dataclass(frozen=True)
class FigureSettings:
    """How densely the figures are computed."""

    # The frequency axis of the paper's spectra [rad/s] (the spectrum command's range).
    omega_start: float = 3.0
    omega_stop: float = 30.0
    # 0.5 rad/s places each mode jump within half a rad/s; the run took 2-3 min on
    # 2 shared cores (0.25 took 4.6 min, half of it in 72 undecided cosine runs).
    omega_step: float = 0.5
    # Scan/bisection settings shared by every spectrum (defaults of analytic.spectrum).
    spectrum: SpectrumSettings = field(default_factory=SpectrumSettings)
    # A smoke run (quick_settings): its captions and JSON say so.
    quick: bool = False

    def __post_init__(self) -> None:
        for name in ("omega_start", "omega_stop", "omega_step"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0.0 < v <= 1e4):
                raise ValueError(f"{name} must be in (0, 1e4] rad/s, got {v!r}")
        if self.omega_stop < self.omega_start:
            raise ValueError(f"omega_stop ({self.omega_stop:g}) must be >= omega_start "
                             f"({self.omega_start:g})")
        if not isinstance(self.spectrum, SpectrumSettings):
            raise ValueError("spectrum must be analytic.spectrum.SpectrumSettings")

    def describe(self) -> dict:
        out = asdict(self)
        out["spectrum"] = self.spectrum.describe()
        return out


def quick_settings() -> FigureSettings:
    """``--quick``: 7 frequencies, coarser tolerances (a smoke run, not the figures)."""
    # Omega = 3, 7.5, 12, ..., 30: both ends of the axis and one point (12) in the
    # paper's gain range.  tol/scan steps 5x coarser: the scan to ~100 m/s^2
    # dominates the cost.
    return FigureSettings(omega_step=4.5,
                          spectrum=SpectrumSettings(tol=0.05, scan_step=0.5, scan_rel_step=0.1),
                          quick=True)


def omega_grid(fs: FigureSettings) -> np.ndarray:
    """Frequencies ``omega_start .. omega_stop`` (included) by ``omega_step`` [rad/s]."""
    n = int(math.floor((fs.omega_stop - fs.omega_start) / fs.omega_step + 1e-9)) + 1
    return np.round(fs.omega_start + fs.omega_step * np.arange(n), 12)


@dataclass(frozen=True)
class Panel:
    """One spectrum of a figure: a shipped scene under one pulse kind."""

    scene: str
    pulse: str
    title: str
    row: int = 0
    col: int = 0


@dataclass(frozen=True)
class FigureSpec:
    name: str
    caption: str
    panels: tuple[Panel, ...]
    nrows: int = 1
    ncols: int = 1


def _figures() -> tuple[FigureSpec, ...]:
    lams = (3, 5, 7)
    # Titles in matplotlib mathtext: Greek symbols in every output format.
    lam_, gam_, mu_ = r"$\lambda$", r"$\gamma$", r"$\mu$"
    fig8 = tuple(Panel(f"fig8_lam{lam}_gamma{g}", "sine", f"{lam_} = {lam}, {gam_} = {g}", r, c)
                 for r, lam in enumerate(lams) for c, g in enumerate((0.1, 0.2, 0.3)))
    fig9 = tuple(Panel(f"fig9_lam{lam}_b{b}", "sine", f"{lam_} = {lam}, b = {b} m", r, c)
                 for r, lam in enumerate(lams) for c, b in enumerate((0.2, 0.4, 0.6, 0.8)))
    fig10 = tuple(Panel(f"fig9_lam{lam}_b0.4", "cosine", f"{lam_} = {lam}", 0, c)
                  for c, lam in enumerate(lams))
    fig11 = tuple(Panel(f"fig11_mu{mu}", "sine", f"{mu_} = {mu}", 0, c)
                  for c, mu in enumerate(("0.5", "1", "2", "4")))
    return (
        FigureSpec("fig5", f"Fig. 5: one-sine, {lam_} = 5, b = 0.6 m, {gam_} = 0.3, {mu_} = 1",
                   (Panel("fig5", "sine", f"{lam_} = 5, b = 0.6 m, {gam_} = 0.3, {mu_} = 1"),),
                   2, 1),
        FigureSpec("fig8", f"Fig. 8: one-sine, b = 0.6 m, {mu_} = 1; rows {lam_}, columns {gam_}",
                   fig8, 3, 3),
        FigureSpec("fig9", f"Fig. 9: one-sine, {gam_} = 0.3, {mu_} = 1; rows {lam_}, columns b",
                   fig9, 3, 4),
        FigureSpec("fig10", f"Fig. 10: one-cosine, b = 0.4 m, {gam_} = 0.3, {mu_} = 1", fig10,
                   1, 3),
        FigureSpec("fig11", f"Fig. 11: one-sine, {lam_} = 5, b = 0.6 m, {gam_} = 0.3; lintel mass "
                   f"{mu_}", fig11, 1, 4),
    )


FIGURES: tuple[FigureSpec, ...] = _figures()
_GREEK = {r"$\lambda$": "λ", r"$\gamma$": "γ", r"$\mu$": "μ"}


def plain_text(text: str) -> str:
    """A title without mathtext (``$\\lambda$`` -> ``λ``): for terminals and JSON."""
    for tex, char in _GREEK.items():
        text = text.replace(tex, char)
    return text


def _key(panel: Panel) -> tuple:
    # Scenes with the same model arguments share one spectrum (fig5 = fig8 lam5
    # gamma0.3 = fig9 lam5 b0.6 = fig11 mu1).
    return (load_scene(panel.scene).model_args(), panel.pulse)


def compute_spectra(fs: FigureSettings, workers: int = 1, progress: bool = False,
                    figures: tuple[FigureSpec, ...] = FIGURES) -> dict[tuple, Spectrum]:
    """One :class:`Spectrum` per distinct (model arguments, pulse) of ``figures``.

    Parameters
    ----------
    fs : FigureSettings
        Frequency grid and the scan/bisection settings (the pulse kind comes from
        each panel: one-sine Eq. 22 or one-cosine Eq. 23).
    workers : int
        Processes per spectrum, in [1, 256].
    progress : bool
        A tqdm bar counting spectra.
    figures : tuple of FigureSpec
        Which figures' panels to compute (default: all of :data:`FIGURES`).

    Returns
    -------
    dict
        ``{(scene.model_args(), pulse): Spectrum}``.
    """
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")
    omegas = omega_grid(fs)
    todo: dict[tuple, Panel] = {}
    for spec in figures:
        for panel in spec.panels:
            todo.setdefault(_key(panel), panel)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(todo), unit="spectrum", desc="figures")
    out = {}
    try:
        for key, panel in todo.items():
            ss = dataclasses.replace(fs.spectrum, pulse=panel.pulse)
            out[key] = overturning_spectrum(load_scene(panel.scene), omegas, ss, workers=workers)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out


# --- plotting -------------------------------------------------------------------------
QUICK_MARK = "QUICK (coarse grid, not the paper's figure)"


def shade_validity(ax, sp: Spectrum, validity: dict | None, label: bool = True) -> None:
    """Hatch the frequencies where either curve's model is invalid on its
    threshold run (``/``: with the pendulum, ``\\``: without; a scene without a
    pendulum has its one curve, labelled "model invalid")."""
    if not validity:
        return
    for curve, hatch, text in (("pendulum", "///", "model invalid (with pendulum)"),
                               ("no_pendulum", "\\\\", "model invalid (without)")):
        if curve not in sp.curves:
            continue
        if len(sp.curves) == 1:
            text = "model invalid"
        spans = invalid_spans(sp.omega, [v["model_valid"] for v in validity[curve]])
        for k, (lo, hi) in enumerate(spans):
            ax.axvspan(lo, hi, facecolor="none", edgecolor="0.55", hatch=hatch, lw=0,
                       zorder=0, label=text if (label and k == 0) else None)


def _draw_spectrum(ax, sp: Spectrum, legend: bool, validity: dict | None = None) -> None:
    shade_validity(ax, sp, validity)
    if "pendulum" in sp.curves:
        ax.plot(sp.omega, sp.a_no_pendulum, "k--", lw=1.0, label="without pendulum")
        ax.plot(sp.omega, sp.a_pendulum, "k-", lw=1.2, label="with pendulum")
    else:  # one curve: no "with pendulum" copy of it
        ax.plot(sp.omega, sp.a_no_pendulum, "k-", lw=1.2, label="no pendulum")
    curves = {"no_pendulum": sp.a_no_pendulum, "pendulum": sp.a_pendulum}
    first = True
    for jump in sp.mode_jumps():
        a = curves[jump["curve"]]
        i = int(np.flatnonzero(sp.omega == jump["omega_before"])[0])
        x, y = 0.5 * (sp.omega[i] + sp.omega[i + 1]), 0.5 * (a[i] + a[i + 1])
        # Dashed circle as in the paper's Fig. 5 (scatter edges take a line style).
        ax.scatter([x], [y], s=70, facecolors="none", edgecolors="tab:red",
                   linestyles="--", linewidths=1.0, zorder=3,
                   label="mode jump" if first else None)
        first = False
    if legend:
        ax.legend(loc="upper left", frameon=False)


def figure_size(spec: FigureSpec) -> tuple[float, float]:
    """Publication size [in]: Fig. 5 one journal column wide (3.5 in), the
    multi-panel figures two columns (7 in), rows ~1.9 in tall."""
    if spec.name == "fig5":
        return SINGLE_COLUMN, 4.2
    return DOUBLE_COLUMN, 1.9 * spec.nrows + 0.7


def plot_figure(spec: FigureSpec, spectra: dict[tuple, Spectrum], path: Path,
                dpi: int = DEFAULT_DPI, validity: dict | None = None,
                quick: bool = False) -> None:
    """Draw one figure of :data:`FIGURES` from computed ``spectra`` into ``path``;
    the format (PNG, PDF or SVG, fonts embedded as TrueType) follows the suffix,
    ``dpi`` sets the raster resolution (and the PNG's pixel size,
    :func:`figure_size` x ``dpi``).  ``validity``: ``{key: spectrum_validity}``
    (hatched where invalid); ``quick`` puts :data:`QUICK_MARK` in the caption."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with plt.rc_context(_RC):
        _draw_figure(plt, spec, spectra, path, dpi, validity or {}, quick)


# Type sizes for a figure printed at its own size (7 pt text, 6 pt ticks); fonts
# embedded as TrueType (Type 42) in PDF and PostScript: Type 3 fonts are refused
# by journals and render poorly in some viewers.
_RC = {"font.size": 7, "axes.titlesize": 7, "axes.labelsize": 7, "xtick.labelsize": 6,
       "ytick.labelsize": 6, "legend.fontsize": 6, "lines.markersize": 3,
       "pdf.fonttype": 42, "ps.fonttype": 42, "hatch.linewidth": 0.5}


def _draw_figure(plt, spec: FigureSpec, spectra: dict, path: Path, dpi: int,
                 validity: dict, quick: bool) -> None:
    if spec.name == "fig5":
        sp = spectra[_key(spec.panels[0])]
        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=figure_size(spec),
                                       gridspec_kw={"height_ratios": [2, 1]})
        _draw_spectrum(ax1, sp, legend=True, validity=validity.get(_key(spec.panels[0])))
        shade_validity(ax2, sp, validity.get(_key(spec.panels[0])), label=False)
        ax1.set_ylabel(r"$A_s$ [m/s$^2$]")
        ax1.set_title("(a) overturning spectrum")
        ax2.plot(sp.omega, sp.gain_percent, "k-", lw=1.2)
        ax2.axhline(0.0, color="0.6", lw=0.8)
        ax2.set_ylabel(r"$\Delta$ [%]")
        ax2.set_xlabel(r"$\Omega$ [rad/s]")
        ax2.set_title(r"(b) gain $\Delta = 100\,(A_{yp}-A_{np})/A_{np}$")
    else:
        fig, axes = plt.subplots(spec.nrows, spec.ncols, sharex=True, squeeze=False,
                                 figsize=figure_size(spec))
        for k, panel in enumerate(spec.panels):
            ax = axes[panel.row][panel.col]
            _draw_spectrum(ax, spectra[_key(panel)], legend=(k == 0),
                           validity=validity.get(_key(panel)))
            ax.set_title(panel.title)
            if panel.row == spec.nrows - 1:
                ax.set_xlabel(r"$\Omega$ [rad/s]")
            if panel.col == 0:
                ax.set_ylabel(r"$A_s$ [m/s$^2$]")
    fig.suptitle(spec.caption + (f"\n{QUICK_MARK}" if quick else ""), fontsize=8,
                 color="tab:red" if quick else "k")
    fig.tight_layout()
    atomic.savefig(fig, path, dpi=dpi, format=Path(path).suffix.lstrip(".").lower() or "png")
    plt.close(fig)


# --- the whole run --------------------------------------------------------------------
def output_names(fmt: str) -> list[str]:
    """The files :func:`make_figures` writes into its folder (in ``fmt``)."""
    return ["figures.json", *(f"{spec.name}.{fmt}" for spec in FIGURES)]


def make_figures(out_dir, fs: FigureSettings | None = None, workers: int = 1,
                 progress: bool = False, dpi: int = DEFAULT_DPI, fmt: str = "png") -> dict:
    """Compute every spectrum, write ``<fig>.<fmt>`` per figure and ``figures.json``.

    Parameters
    ----------
    out_dir : str or Path
        Output directory, created if missing (``ValueError`` if it is a file).
    fs : FigureSettings, optional
        Default: Omega = 3..30 rad/s by 0.5, default spectrum settings.
    workers : int
        Processes per spectrum, in [1, 256].
    progress : bool
        Show a tqdm bar.
    dpi : int
        Raster resolution in [50, 1200] (PNG pixels = :func:`figure_size` x dpi).
    fmt : {'png', 'pdf', 'svg'}
        Output format.

    Returns
    -------
    dict
        The JSON document (NaN as None): ``quick``, per figure its caption and
        panels, each panel with its scene name, pulse, the spectrum's
        ``to_dict()`` and ``model_validity`` (both curves, one
        :func:`analytic.threshold_validity.point_validity` per frequency).
    """
    fs = FigureSettings() if fs is None else fs
    check_output_options(dpi, fmt)
    if not isinstance(fs, FigureSettings):
        raise ValueError("settings must be compare.report.figures.FigureSettings")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out_dir (--out) must be a directory, {str(out)!r} is a file")
    t0 = time.perf_counter()
    spectra = compute_spectra(fs, workers=workers, progress=progress)
    validity = {key: spectrum_validity(sp, workers=workers) for key, sp in spectra.items()}
    names = output_names(fmt)
    atomic.check_into(out, names, "out_dir (--out)")  # a user's file is never overwritten
    atomic.record_into(out, names)
    doc = {"quick": fs.quick, "settings": fs.describe(), "omega": omega_grid(fs).tolist(),
           "figures": {}, "dpi": dpi, "format": fmt}
    for spec in FIGURES:
        path = out / f"{spec.name}.{fmt}"
        plot_figure(spec, spectra, path, dpi, validity, fs.quick)
        doc["figures"][spec.name] = {
            "caption": plain_text(spec.caption) + (f" [{QUICK_MARK}]" if fs.quick else ""),
            "file": path.name,
            "panels": [{"scene": p.scene, "pulse": p.pulse, "title": plain_text(p.title),
                        "row": p.row, "col": p.col, "spectrum": spectra[_key(p)].to_dict(),
                        "model_validity": validity[_key(p)]}
                       for p in spec.panels]}
    doc["n_spectra"] = len(spectra)
    doc["n_runs"] = int(sum(s.n_runs for s in spectra.values()))
    doc["n_undecided"] = int(sum(s.n_undecided for s in spectra.values()))
    doc["wall_time"] = time.perf_counter() - t0
    doc = plain(doc)
    atomic.write_text(out / "figures.json", json.dumps(doc, indent=1, allow_nan=False))
    return doc
