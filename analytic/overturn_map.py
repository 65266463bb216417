"""Overturn maps (Zhang & Makris 2001): the verdict of every pulse on an
amplitude x frequency grid, and the first-overturning curve on it.

A cell is labelled by the run's verdict: ``'overturned (no-impact)'``,
``'overturned (after-impact)'``, ``'survived'``, or any other status a backend
reports (``'unstable'``, ``'undecided'``, ``'collapsed'``...).  Above the first
overturning amplitude the map shows safe islands; below it, overturning windows
(``docs/overturn-maps.md``).

:func:`analytic_map` runs the compiled verdict kernel (one compiled loop per
frequency); :func:`verdict_map` runs any ``run(amplitude, omega) -> Verdict``
callable (an engine's ``simulate``), cell by cell in a process pool.  This module
never imports an engine.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from . import _fast_kernels as _k
from . import fast
from ._workers import cpu_seconds, fork_pool
from .parameters import Scene
from .spectrum import SpectrumSettings, first_overturn_amplitude

__all__ = ["OverturnMap", "analytic_map", "verdict_map", "verdict_label", "BASE_LABELS",
           "MAX_ACCURATE_CELLS"]

BASE_LABELS = ("survived", "overturned (no-impact)", "overturned (after-impact)")
MAX_CELLS = 2_000_000  # ~100 s of compiled runs: beyond, a typo rather than a wish
# Accurate-model maps (Ricker, M-P): ~20 ms a cell, so ~100 CPU s at most.
MAX_ACCURATE_CELLS = 5_000


def verdict_label(status: str, mode: str | None) -> str:
    """The map label of a verdict."""
    return f"overturned ({mode})" if status == "overturned" else status


@dataclass(frozen=True, eq=False)
class OverturnMap:
    """Verdict labels on a grid.

    ``cells[i, j]`` indexes ``labels`` for ``amplitude[i]`` [m/s^2] and
    ``omega[j]`` [rad/s]; ``first[j]`` is the first overturning amplitude at
    ``omega[j]`` from :func:`analytic.spectrum.first_overturn_amplitude` (NaN:
    none up to the grid's top, or not computed).  ``wall_time`` [s] and
    ``cpu_s`` (CPU seconds of the process and its workers) are what the map took.
    """

    omega: np.ndarray
    amplitude: np.ndarray
    cells: np.ndarray
    labels: tuple
    first: np.ndarray
    backend: str
    pulse: str
    scene: Scene
    wall_time: float = math.nan
    cpu_s: float = math.nan

    def counts(self) -> dict:
        """Number of cells per label."""
        return {lab: int(np.sum(self.cells == i)) for i, lab in enumerate(self.labels)}

    def to_dict(self) -> dict:
        return {"backend": self.backend, "pulse": self.pulse, "scene": self.scene.to_dict(),
                "omega": self.omega.tolist(), "amplitude": self.amplitude.tolist(),
                "labels": list(self.labels), "cells": self.cells.tolist(),
                "first_overturn": [float(a) if math.isfinite(a) else None for a in self.first],
                "counts": self.counts(), "wall_time": self.wall_time, "cpu_s": self.cpu_s}

    def csv_rows(self):
        """``(omega, amplitude, label)`` for every cell, omega-major."""
        for j, w in enumerate(self.omega):
            for i, a in enumerate(self.amplitude):
                yield float(w), float(a), self.labels[int(self.cells[i, j])]


def _check_grid(omegas, amplitudes) -> tuple[np.ndarray, np.ndarray]:
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    a = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0) \
            or np.any(w > 1e4):
        raise ValueError("omegas must be a non-empty list of frequencies in (0, 1e4] rad/s")
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0) \
            or np.any(a > 1e4):
        raise ValueError("amplitudes must be a non-empty list in (0, 1e4] m/s^2")
    if w.size * a.size > MAX_CELLS:
        raise ValueError(f"the map has {w.size * a.size} cells, more than {MAX_CELLS}")
    return w, a


# --- worker side: module globals set before the fork --------------------------------
_JOB: dict = {}


def _analytic_column(omega: float) -> tuple[np.ndarray, float]:
    scene, ss, amps, with_first = _JOB["scene"], _JOB["ss"], _JOB["amps"], _JOB["first"]
    if ss.compiled:
        st, _rs, _tv, ni, _e = _k.verdicts(amps, *fast.kernel_args(scene, omega, ss.pulse,
                                                                   ss.fast))
        col = np.select([st == _k.ST_OVERTURNED, st == _k.ST_SURVIVED, st == _k.ST_UNSTABLE],
                        [np.where(ni > 0, 2, 1), 0, 3], 4)
    else:
        col = np.array([_accurate_cell(scene, ss, float(a), omega) for a in amps], dtype=int)
    first = first_overturn_amplitude(scene, omega, ss)[0] if with_first else math.nan
    return col, first


def _accurate_cell(scene: Scene, ss: SpectrumSettings, amplitude: float, omega: float) -> int:
    """The label index of one cell run by the accurate model (the shapes the
    kernels do not cover), with the same criterion and window."""
    from .events import Settings
    from .pulses import pulse_of
    from .simulate import simulate
    v = simulate(scene, pulse_of(ss.pulse, amplitude, omega),
                 Settings(criterion=ss.criterion, t_max=ss.t_max, verdict_only=True,
                          sample_dt=None)).verdict
    if v.status == "overturned":
        return 2 if v.mode == "after-impact" else 1
    return {"survived": 0, "unstable": 3}.get(v.status, 4)


def _verdict_cell(ij: tuple[int, int]) -> tuple[str, str | None]:
    v = _JOB["run"](float(_JOB["amps"][ij[0]]), float(_JOB["omegas"][ij[1]]))
    return v.status, v.mode


def _pool_map(fn, items, workers: int) -> list:
    if workers == 1 or len(items) == 1:
        return [fn(x) for x in items]
    with fork_pool(min(workers, len(items))) as ex:
        return list(ex.map(fn, items, chunksize=max(1, len(items) // (4 * workers))))


def analytic_map(scene: Scene, omegas, amplitudes, settings: SpectrumSettings | None = None,
                 workers: int = 1, first_curve: bool = True) -> OverturnMap:
    """The compiled analytic model's overturn map of ``scene`` (the accurate
    model's for the pulse shapes the kernels do not cover: Ricker, M-P; ~20 ms
    a cell, :data:`MAX_ACCURATE_CELLS` at most).

    Parameters
    ----------
    scene : Scene
    omegas, amplitudes : array_like
        Grid [rad/s] x [m/s^2], each value in (0, 1e4].
    settings : SpectrumSettings, optional
        Pulse kind, run settings and the first-curve search (its ``a_max`` is
        capped at the grid's top amplitude).
    workers : int
        Processes (fork), one frequency per task; results do not depend on it.
    first_curve : bool
        Also search the first overturning amplitude per frequency.

    Examples
    --------
    >>> from trilith_xval.scenes import load_scene
    >>> m = analytic_map(load_scene("fig5"), [7.0], [2.0, 3.0, 4.0], first_curve=False)
    >>> [m.labels[c] for c in m.cells[:, 0]]
    ['survived', 'survived', 'overturned (after-impact)']
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be an analytic.Scene, got {type(scene).__name__}")
    ss = SpectrumSettings() if settings is None else settings
    if not isinstance(ss, SpectrumSettings):
        raise ValueError("settings must be analytic.spectrum.SpectrumSettings")
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")
    w, a = _check_grid(omegas, amplitudes)
    if not ss.compiled and w.size * a.size > MAX_ACCURATE_CELLS:
        raise ValueError(f"a {ss.pulse} map of {w.size * a.size} cells runs the accurate model "
                         f"(~20 ms a cell); at most {MAX_ACCURATE_CELLS} cells")
    ss = replace(ss, a_max=float(min(ss.a_max, a.max())))
    t0, c0 = time.perf_counter(), cpu_seconds()
    if ss.compiled:
        fast.warm_up(record=False)
    _JOB.update(scene=scene, ss=ss, amps=a, first=first_curve)
    try:
        cols = _pool_map(_analytic_column, [float(x) for x in w], workers)
    finally:
        _JOB.clear()
    labels = BASE_LABELS + ("unstable", "undecided")  # the kernel's other statuses
    cells = np.stack([c for c, _ in cols], axis=1)
    return OverturnMap(omega=w, amplitude=a, cells=cells, labels=labels,
                       first=np.array([f for _, f in cols]),
                       backend=fast.NAME if ss.compiled else "analytic",
                       pulse=ss.pulse, scene=scene, wall_time=time.perf_counter() - t0,
                       cpu_s=cpu_seconds() - c0)


def verdict_map(run, scene: Scene, omegas, amplitudes, backend: str, pulse: str = "sine",
                workers: int = 1) -> OverturnMap:
    """Overturn map from any ``run(amplitude, omega) -> Verdict`` (e.g. an
    engine's ``simulate(...).verdict``), one process-pool task per cell.  Labels
    are the statuses met, in order of first appearance after the base ones."""
    if not callable(run):
        raise ValueError("run must be a callable (amplitude, omega) -> Verdict")
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")
    w, a = _check_grid(omegas, amplitudes)
    t0, c0 = time.perf_counter(), cpu_seconds()
    cells_ij = [(i, j) for j in range(w.size) for i in range(a.size)]
    _JOB.update(run=run, amps=a, omegas=w)
    try:
        out = _pool_map(_verdict_cell, cells_ij, workers)
    finally:
        _JOB.clear()
    labels = list(BASE_LABELS)
    cells = np.zeros((a.size, w.size), dtype=int)
    for (i, j), (status, mode) in zip(cells_ij, out):
        lab = verdict_label(status, mode)
        if lab not in labels:
            labels.append(lab)
        cells[i, j] = labels.index(lab)
    return OverturnMap(omega=w, amplitude=a, cells=cells, labels=tuple(labels),
                       first=np.full(w.size, math.nan), backend=backend, pulse=pulse,
                       scene=scene, wall_time=time.perf_counter() - t0,
                       cpu_s=cpu_seconds() - c0)
