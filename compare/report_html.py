"""Writing the validation report: ``index.html`` (self-contained), ``summary.json``,
``summary.md``.

Plots are matplotlib PNGs embedded as base64 data URIs, so the HTML opens
offline with no server and no side files.
"""
from __future__ import annotations

import base64
import html
import io
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import atomic  # noqa: E402
from .campaign import POINTS  # noqa: E402
from .commands._common import clean_nan  # noqa: E402
from .metrics import _plain  # noqa: E402

__all__ = ["write_report", "render_html", "render_markdown", "summary_dict"]

_COLORS = {"analytic": "k", "analytic-fast": "tab:green", "pybullet": "tab:blue", "pymunk": "tab:orange"}


def summary_dict(result) -> dict:
    """``summary.json``: strict JSON (non-finite numbers become null)."""
    return clean_nan(_plain(result.to_dict()))


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _img(data: str, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _fmt(value, digits: int = 4) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "NO"
    if isinstance(value, float):
        return "n/a" if not math.isfinite(value) else f"{value:.{digits}g}"
    return str(value)


def _table(header: list[str], rows: list[list], md: bool = False) -> str:
    if md:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(_fmt(c) for c in r) + " |" for r in rows]
        return "\n".join(lines)
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(_fmt(c))}</td>" for c in r) + "</tr>"
                   for r in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


# ---------------------------------------------------------------------- plots
def _history_figure(result, point: str) -> str:
    cases = sorted({p for (pt, p, _) in result.histories if pt == point}, reverse=True)
    fig, axes = plt.subplots(2, len(cases), figsize=(5.5 * len(cases), 5.5), squeeze=False,
                             sharex="col")
    amp, omega = POINTS[point]
    for col, pend in enumerate(cases):
        scene = result.scene if pend else result.scene.without_pendulum()
        # Sorted by the key's text (str of the whole item would print every array).
        for (pt, p, name), traj in sorted(result.histories.items(),
                                          key=lambda kv: str(kv[0])):
            if pt != point or p != pend:
                continue
            style = dict(color=_COLORS.get(name), lw=1.0, label=name,
                         ls="-" if name == result.config.reference else "--")
            axes[0, col].plot(traj.t, traj.theta / scene.alpha, **style)
            if pend:
                axes[1, col].plot(traj.t, traj.psi, **style)
        axes[0, col].set_title(f"{point}: A = {amp:g} m/s², Ω = {omega:g} rad/s, "
                               f"{'with' if pend else 'without'} pendulum", fontsize=9)
        axes[0, col].set_ylabel("θ / α")
        axes[1, col].set_ylabel("ψ [rad]")
        if not pend:
            axes[1, col].axis("off")
            axes[1, col].text(0.5, 0.5, "no pendulum", ha="center", transform=axes[1, col].transAxes)
        axes[1, col].set_xlabel("t [s]")
        axes[0, col].axhline(1.0, color="0.7", lw=0.5)
        axes[0, col].axhline(-1.0, color="0.7", lw=0.5)
        axes[0, col].set_ylim(-2.0, 2.0)
        axes[0, col].legend(fontsize=7)
    return _png(fig)


def _restitution_figure(result) -> str:
    fig, ax = plt.subplots(figsize=(7, 3.5))
    names = list(result.config.engines)
    rows = result.restitution
    labels = []
    for k, name in enumerate(names):
        mine = [r for r in rows if r["backend"] == name]
        x = np.arange(len(mine)) + 0.8 * k / max(len(names), 1) - 0.3
        y = [100 * r["max_rel_error"] if r["impacts"] else np.nan for r in mine]
        ax.bar(x, y, width=0.7 / max(len(names), 1), color=_COLORS.get(name), label=name)
        labels = [f"λ{r['lam']:g} μ{r['mu']:g}{' +p' if r['pendulum'] else ''}" for r in mine]
    tol = 100 * result.config.tolerances.restitution
    ax.axhline(tol, color="r", lw=0.8, ls=":", label=f"Eq. 20 tolerance {tol:g} %")
    ax.set_xticks(np.arange(len(labels)), labels, rotation=45, fontsize=7)
    ax.set_ylabel("max |measured/predicted - 1| [%]")
    ax.legend(fontsize=7)
    return _png(fig)


def _spectra_figure(result) -> str:
    cases = [c for c in ("pendulum", "no_pendulum") if c in result.spectra]
    fig, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4), squeeze=False)
    for ax, case in zip(axes[0], cases):
        spec = result.spectra[case]
        w = np.asarray(spec["omega"], float)
        a = np.asarray([np.nan if v is None else v for v in spec["a"]], float)
        for jp in spec.get("jumps", []):  # no line across a jump: the curve is discontinuous
            i = int(np.searchsorted(w, jp["omega_hi"]))
            w, a = np.insert(w, i, np.nan), np.insert(a, i, np.nan)
        ax.plot(w, a, "k-", lw=1, label=f"{spec['backend']} (reference)")
        for name, pts in spec.get("engines", {}).items():
            ax.plot([p["omega"] for p in pts], [p["a_engine"] for p in pts], "o",
                    color=_COLORS.get(name), mfc="none", label=name)
        for jp in spec.get("jumps", []):
            ax.axvline(jp.get("omega_tip", jp["omega"]), color="0.6", lw=0.6, ls=":")
        for name, j in spec.get("jump_shifts", {}).items():
            if j.get("omega_engine") is not None and math.isfinite(j["omega_engine"]):
                ax.axvline(j["omega_engine"], color=_COLORS.get(name), lw=0.8, ls="--",
                           label=f"{name} jump")
        ax.set_title(case.replace("_", " "), fontsize=9)
        ax.set_xlabel("Ω [rad/s]")
        ax.set_ylabel("first overturning A [m/s²]")
        ax.legend(fontsize=7)
    return _png(fig)


# ---------------------------------------------------------------------- text
def _verdict_rows(result) -> list[list]:
    return [[v["metric"], v["backend"], v["value"], v["tolerance"], v["passed"], v["reason"],
             v.get("detail", "")] for v in result.verdicts]


def _threshold_rows(result) -> list[list]:
    rows = []
    for case, spec in result.spectra.items():
        for name, pts in spec.get("engines", {}).items():
            for p in pts:
                rows.append([case, name, p["omega"], p["a_reference"], p["a_engine"],
                             p["rel_error"], p["mode_reference"], p["mode_engine"], p["n_runs"],
                             p["provenance"]["wall_time"]])
    return rows


def _jump_rows(result) -> list[list]:
    rows = []
    for case, spec in result.spectra.items():
        for name, j in spec.get("jump_shifts", {}).items():
            rows.append([case, name, j["amplitude"], j["omega_reference"], j["omega_engine"],
                         j["shift"], j["n_runs"]])
    return rows


def _history_rows(result) -> list[list]:
    return [[c["point"], "yes" if c["pendulum"] else "no", c["backend"], c["status_reference"],
             c["status_test"], c["mode_test"], c["theta_rms_first"], c["theta_max_all"],
             c["uplift_time_error"], c["test"]["wall_time"]] for c in result.comparisons]


def _timing_rows(result) -> list[list]:
    t = result.timings
    rows = [[k, v] for k, v in t.items() if not isinstance(v, dict)]
    rows += [[f"cpu {k}", v] for k, v in t.get("cpu_by_job", {}).items()]
    return rows


_H = {
    "verdicts": ["metric", "backend", "value", "tolerance", "passed", "reason", "detail"],
    "thresholds": ["case", "engine", "Ω [rad/s]", "A analytic", "A engine", "rel. error",
                   "mode (model)", "mode (engine)", "runs", "wall [s]"],
    "jumps": ["case", "engine", "probe A [m/s²]", "Ω jump analytic", "Ω jump engine",
              "shift [rad/s]", "runs"],
    "histories": ["point", "pendulum", "engine", "verdict (model)", "verdict (engine)",
                  "mode (engine)", "θ RMS/α before 1st impact", "θ max err/α (all)",
                  "uplift time err [s]", "wall [s]"],
    "restitution": ["engine", "λ", "μ", "γ", "equation", "impacts", "max rel. error"],
    "timings": ["what", "seconds"],
    "errors": ["job", "engine", "pendulum", "label", "error"],
}


def _error_rows(result) -> list[list]:
    return [[e["job"], e["backend"], e["pendulum"], " ".join(e["label"]), e["error"]]
            for e in result.errors]


def _restitution_rows(result) -> list[list]:
    return [[r["backend"], r["lam"], r["mu"], r["gamma"], r["equation"], len(r["impacts"]),
             r["max_rel_error"]] for r in result.restitution]


def render_markdown(result) -> str:
    n_fail = sum(not v["passed"] for v in result.verdicts)
    parts = [f"# Validation report: scene `{result.config.scene}`",
             f"{len(result.verdicts) - n_fail} of {len(result.verdicts)} verdicts pass.",
             "## Verdicts", _table(_H["verdicts"], _verdict_rows(result), md=True),
             "## Overturning thresholds (away from mode jumps)",
             _table(_H["thresholds"], _threshold_rows(result), md=True),
             "## Mode-jump frequency shift", _table(_H["jumps"], _jump_rows(result), md=True),
             "## Restitution", _table(_H["restitution"], _restitution_rows(result), md=True),
             "## Time histories A-D", _table(_H["histories"], _history_rows(result), md=True),
             "## Run times", _table(_H["timings"], _timing_rows(result), md=True),
             "## Runs that raised", _table(_H["errors"], _error_rows(result), md=True),
             "## Versions", "\n".join(f"- {k}: {v}" for k, v in result.versions.items())]
    return "\n\n".join(parts) + "\n"


_CSS = ("body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em}"
        "table{border-collapse:collapse;font-size:12px;margin:0.5em 0}"
        "td,th{border:1px solid #bbb;padding:2px 6px}th{background:#eee}"
        "pre{background:#f6f6f6;padding:0.5em;font-size:11px;overflow:auto}")


def render_html(result) -> str:
    esc = html.escape
    n_fail = sum(not v["passed"] for v in result.verdicts)
    body = [f"<h1>Validation report: scene <code>{esc(result.config.scene)}</code></h1>",
            f"<p><b>{len(result.verdicts) - n_fail} of {len(result.verdicts)} verdicts pass.</b> "
            "Reference: the analytic model (accurate path for time histories, compiled path "
            "for spectra).</p>",
            "<h2>Verdicts</h2>", _table(_H["verdicts"], _verdict_rows(result)),
            "<h2>Scene and settings</h2>",
            f"<pre>{esc(json.dumps(clean_nan(result.scene.to_dict()), indent=1))}</pre>",
            f"<pre>{esc(json.dumps(summary_dict(result)['settings'], indent=1))}</pre>",
            f"<pre>{esc(json.dumps(summary_dict(result)['config'], indent=1))}</pre>",
            "<h2>Time histories at the paper's points A-D</h2>",
            _table(_H["histories"], _history_rows(result))]
    for point in result.config.points:
        body.append(_img(_history_figure(result, point), f"histories {point}"))
    body += ["<h2>Restitution (free rocking)</h2>",
             "<p>Without pendulum against Eq. 20, with it against Eq. 19 at the measured ψ.</p>",
             _table(_H["restitution"], _restitution_rows(result)),
             _img(_restitution_figure(result), "restitution"),
             "<h2>Overturning spectra</h2>", _img(_spectra_figure(result), "spectra"),
             _table(_H["thresholds"], _threshold_rows(result)),
             "<h3>Mode-jump frequency shift</h3>",
             "<p>Bisection in Ω at an amplitude between the two threshold levels of the jump, "
             "in the engine and in the reference.</p>", _table(_H["jumps"], _jump_rows(result)),
             "<h2>Run times</h2>", _table(_H["timings"], _timing_rows(result)),
             "<h2>Runs that raised</h2>", _table(_H["errors"], _error_rows(result)),
             "<h2>Versions</h2>", _table(["backend", "version"],
                                         [[k, v] for k, v in result.versions.items()])]
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>trilith-xval report"
            f"</title><style>{_CSS}</style></head><body>" + "\n".join(body) + "</body></html>\n")


def write_report(result, out_dir) -> dict[str, Path]:
    """Write ``index.html``, ``summary.json`` and ``summary.md`` into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"html": out / "index.html", "json": out / "summary.json", "md": out / "summary.md"}
    atomic.write_text(paths["json"], json.dumps(summary_dict(result), indent=1, allow_nan=False))
    atomic.write_text(paths["md"], render_markdown(result))
    atomic.write_text(paths["html"], render_html(result))
    return paths
