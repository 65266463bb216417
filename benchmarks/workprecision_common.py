"""Shared plumbing of the work-precision benchmarks: timing, Pareto fronts,
threshold bisection, machine description, plots and the JSON of all points.

No physics here: the benchmarks call the backends through
:func:`engines.simulate` and compare their outputs.
"""
from __future__ import annotations

import json
import math
import os
import platform
import statistics
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable


from trilith_xval.compare.run.jsonable import plain

from trilith_xval.compare.run import atomic

__all__ = ["Point", "timed", "pareto_front", "mark_front", "bisect_threshold", "machine_info",
           "write_json", "plot_work_precision", "OUT_DIR"]

OUT_DIR = Path(__file__).resolve().parent / "out"


@dataclass
class Point:
    """One point of a work-precision diagram.

    ``family`` groups points into one curve (e.g. 'analytic rtol', 'pybullet dt'),
    ``metric`` names the error measured, ``error`` is that error (dimensionless),
    ``time`` the median wall time [s] of the measured work, ``params`` the
    settings that produced it, ``default`` whether they are the backend defaults.
    """

    family: str
    metric: str
    error: float
    time: float
    params: dict
    default: bool = False
    on_front: bool = False
    extra: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        err = self.error if math.isfinite(self.error) else None
        return {"family": self.family, "metric": self.metric, "error": err,
                "time": self.time, "params": self.params, "default": self.default,
                "on_front": self.on_front, "extra": self.extra}


def timed(fn: Callable[[], object], repeats: int = 3, warmup: int = 1) -> tuple[object, float]:
    """Run ``fn`` ``warmup`` times unmeasured (imports, JIT, caches), then
    ``repeats`` times; return the last result and the median wall time [s].

    The median, not the mean: the machine is shared and a single preempted run
    would drag a mean.
    """
    result = None
    for _ in range(warmup):
        result = fn()
    times = []
    for _ in range(max(repeats, 1)):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return result, statistics.median(times)


def pareto_front(points: list[Point]) -> list[Point]:
    """The points no other point beats in both time and error (lower is better).

    Points with a non-finite error (failed runs) are never on the front.
    """
    good = [p for p in points if math.isfinite(p.error)]
    good.sort(key=lambda p: (p.time, p.error))
    front: list[Point] = []
    best = math.inf
    for p in good:
        if p.error < best:
            front.append(p)
            best = p.error
    return front


def mark_front(points: list[Point]) -> list[Point]:
    """Set ``on_front`` on the Pareto points of each (family-prefix, metric) group;
    the prefix is the backend (first word of ``family``) so that all settings
    sweeps of one backend compete on one front."""
    groups: dict[tuple[str, str], list[Point]] = {}
    for p in points:
        groups.setdefault((p.family.split()[0], p.metric), []).append(p)
    for group in groups.values():
        for p in group:
            p.on_front = False
        for p in pareto_front(group):
            p.on_front = True
    return points


def bisect_threshold(overturns: Callable[[float], bool], lo: float, hi: float, rel_tol: float,
                     max_expand: int = 6) -> tuple[float, int]:
    """Smallest amplitude in ``[lo, hi]`` at which ``overturns`` switches from
    False to True, to ``rel_tol`` (relative width of the final bracket).

    If ``lo`` already overturns or ``hi`` does not, the bracket is widened by a
    factor 1.25 per try (at most ``max_expand`` times).  Returns
    ``(midpoint of the final bracket, number of runs)``; ``nan`` if no bracket
    was found.  Bisection assumes one switch inside the bracket: choose the
    frequency away from mode jumps.
    """
    if not (0.0 < lo < hi) or not (0.0 < rel_tol < 1.0):
        raise ValueError(f"need 0 < lo < hi and 0 < rel_tol < 1, got lo={lo}, hi={hi}, "
                         f"rel_tol={rel_tol}")
    runs = 0
    for _ in range(max_expand + 1):
        runs += 1
        if not overturns(lo):
            break
        hi, lo = lo, lo / 1.25
    else:
        return math.nan, runs
    for _ in range(max_expand + 1):
        runs += 1
        if overturns(hi):
            break
        lo, hi = hi, hi * 1.25
    else:
        return math.nan, runs
    while (hi - lo) > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        runs += 1
        if overturns(mid):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi), runs


def machine_info() -> dict:
    """nproc, CPU model, load average, Python and library versions, UTC date."""
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    versions = {"python": platform.python_version()}
    for mod in ("numpy", "scipy", "numba", "pymunk", "matplotlib"):
        try:
            m = __import__(mod)
            versions[mod] = getattr(m, "__version__", None) or getattr(m, "version")
        except Exception:  # noqa: BLE001 -- a missing optional library is reported, not fatal
            versions[mod] = "missing"
    try:
        from trilith_xval.engines._quiet_pybullet import pybullet
        versions["pybullet"] = f"API {pybullet.getAPIVersion()}"
    except Exception:  # noqa: BLE001
        versions["pybullet"] = "missing"
    try:
        load = os.getloadavg()
    except OSError:
        load = (math.nan,) * 3
    return {"nproc": os.cpu_count(), "cpu": cpu, "platform": platform.platform(),
            "loadavg": [round(x, 2) for x in load], "versions": versions,
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}


def write_json(path: Path, machine: dict, points: list[Point], meta: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": machine, "meta": meta, "points": [p.to_dict() for p in points]}
    atomic.write_text(path, json.dumps(plain(payload), indent=1, allow_nan=False))



def plot_work_precision(points: list[Point], metric: str, path: Path, title: str,
                        ylabel: str) -> None:
    """Log-log error versus wall time, one curve per family; the Pareto front is
    drawn as a step line and the defaults are circled."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sel = [p for p in points if p.metric == metric and math.isfinite(p.error) and p.error > 0]
    if not sel:
        return
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    families = sorted({p.family for p in sel})
    for fam in families:
        # sweep order (tolerance or step from loose to tight), not time order
        pts = [p for p in sel if p.family == fam]
        ax.loglog([p.time for p in pts], [p.error for p in pts], "o-", ms=4, label=fam)
        for p in pts:
            value = next(iter(p.params.values()))
            ax.annotate(f"{value:g}", (p.time, p.error), fontsize=5, alpha=0.7,
                        xytext=(2, 2), textcoords="offset points")
            if p.default:
                ax.loglog([p.time], [p.error], "o", ms=13, mfc="none", mec="k", mew=1.5)
    for backend in sorted({f.split()[0] for f in families}):
        front = sorted((p for p in sel if p.on_front and p.family.split()[0] == backend),
                       key=lambda p: p.time)
        if len(front) > 1:
            ax.step([p.time for p in front], [p.error for p in front], where="post",
                    color="0.5", lw=0.8, ls="--")
    ax.set_xlabel("wall time [s] (median)")
    ax.set_ylabel(ylabel)
    ax.set_title(title + "\n(dashed: Pareto front; circled: default settings)", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic.savefig(fig, path, dpi=110)
    plt.close(fig)
