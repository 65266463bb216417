"""Overturning spectra (paper Section 5.2, Fig. 5): the first overturning amplitude
per pulse frequency, with and without the pendulum, and the gain Delta.

The reported amplitude is the paper's "amplitude ... which corresponds to the
first overturning occurrence": the *lowest* amplitude that overturns.  Above a
first threshold the map has safe islands and, below it, overturning windows
can be narrower than any affordable uniform step (Zhang & Makris 2001);
``docs/overturn-maps.md`` shows them.

The amplitude at each frequency is searched by
:func:`analytic.first_overturn.first_overturn_amplitude` (coarse scan, window
scan, bisection; its guarantee and limits are in that module and in
``docs/overturn-maps.md``), re-exported here with its settings.
"""
from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass

import numpy as np

from ._workers import map_measured
from .first_overturn import (METHODS, SEARCH_ATOL, SEARCH_RTOL, SpectrumSettings,
                             first_overturn_amplitude, search_run_settings)
from .parameters import Scene
from .trajectory import OverturnCriterion

__all__ = ["SpectrumSettings", "Spectrum", "first_overturn_amplitude", "overturning_spectrum",
           "METHODS", "SEARCH_RTOL", "SEARCH_ATOL", "search_run_settings"]


@dataclass(frozen=True, eq=False)
class Spectrum:
    """An overturning spectrum, both curves (paper Fig. 5).

    ``a_*`` [m/s^2]: first overturning amplitude per ``omega`` [rad/s] (NaN: none
    up to ``settings.a_max``); ``a_*_safe``: the safe amplitude bracketing it from
    below within ``tol``; ``mode_*``: 'no-impact' / 'after-impact' / None.
    """

    omega: np.ndarray
    a_no_pendulum: np.ndarray
    a_pendulum: np.ndarray
    a_no_pendulum_safe: np.ndarray
    a_pendulum_safe: np.ndarray
    mode_no_pendulum: tuple
    mode_pendulum: tuple
    settings: SpectrumSettings
    scene: Scene
    n_runs: int = 0
    n_undecided: int = 0
    wall_time: float = math.nan

    @property
    def criterion(self) -> OverturnCriterion:
        return self.settings.criterion

    @property
    def t_max(self) -> float | None:
        return self.settings.t_max

    @property
    def tol(self) -> float:
        return self.settings.tol

    @property
    def gain_percent(self) -> np.ndarray:
        """``Delta = 100 (A_yp - A_np) / A_np`` (Section 5.2); all zero without a
        pendulum, where nothing shows it (:attr:`curves`)."""
        return 100.0 * (self.a_pendulum - self.a_no_pendulum) / self.a_no_pendulum

    @property
    def curves(self) -> tuple[str, ...]:
        """The curves this spectrum has: ``('no_pendulum', 'pendulum')``, or only
        ``('no_pendulum',)`` when the scene has no pendulum (``gamma = 0``): its
        ``a_pendulum`` then repeats ``a_no_pendulum`` and is never shown."""
        return ("no_pendulum", "pendulum") if self.scene.has_pendulum else ("no_pendulum",)

    def mode_jumps(self) -> list[dict]:
        """Where the overturning mode changes between consecutive frequencies, on
        each of :attr:`curves`."""
        out = []
        modes_of = {"no_pendulum": self.mode_no_pendulum, "pendulum": self.mode_pendulum}
        for curve in self.curves:
            modes = modes_of[curve]
            for i in range(len(modes) - 1):
                if modes[i] is not None and modes[i + 1] is not None and modes[i] != modes[i + 1]:
                    out.append({"curve": curve, "omega_before": float(self.omega[i]),
                                "omega_after": float(self.omega[i + 1]),
                                "mode_before": modes[i], "mode_after": modes[i + 1]})
        return out

    def to_dict(self) -> dict:
        def arr(a):
            return [float(x) if math.isfinite(x) else None for x in np.asarray(a)]
        # Without a pendulum the pendulum curve and the gain are left out: they
        # would repeat the one curve and show a flat 0 % gain.
        both = len(self.curves) == 2
        return {
            "omega": arr(self.omega),
            "a_no_pendulum": arr(self.a_no_pendulum),
            **({"a_pendulum": arr(self.a_pendulum)} if both else {}),
            "a_no_pendulum_safe": arr(self.a_no_pendulum_safe),
            **({"a_pendulum_safe": arr(self.a_pendulum_safe),
                "gain_percent": arr(self.gain_percent)} if both else {}),
            "mode_no_pendulum": list(self.mode_no_pendulum),
            **({"mode_pendulum": list(self.mode_pendulum)} if both else {}),
            "mode_jumps": self.mode_jumps(),
            "pulse": self.settings.pulse,
            "criterion": self.criterion.describe(),
            "t_max": self.t_max,
            "tol": self.tol,
            "settings": self.settings.describe(),
            "scene": self.scene.to_dict(),
            "n_runs": self.n_runs,
            "n_undecided": self.n_undecided,
            "wall_time": self.wall_time,
        }

    def to_csv(self, path, validity: dict | None = None) -> None:
        """One row per frequency, a column group per curve of :attr:`curves` (the
        gain only with both); with ``validity``
        (:func:`analytic.threshold_validity.spectrum_validity`) also each curve's
        ``model_valid`` (empty: not checked) and the reason when it is not."""
        import csv
        curves = self.curves
        amps = {"no_pendulum": self.a_no_pendulum, "pendulum": self.a_pendulum}
        modes = {"no_pendulum": self.mode_no_pendulum, "pendulum": self.mode_pendulum}
        gain = len(curves) == 2
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh, lineterminator="\n")
            head = (["omega"] + [f"a_{c}" for c in curves] + ["gain_percent"] * gain
                    + [f"mode_{c}" for c in curves])
            if validity:
                head += ([f"model_valid_{c}" for c in curves]
                         + [f"model_reason_{c}" for c in curves])
            w.writerow(head)
            for i, om in enumerate(self.omega):
                row = ([f"{om:.12g}"] + [f"{amps[c][i]:.12g}" for c in curves]
                       + [f"{self.gain_percent[i]:.12g}"] * gain
                       + [modes[c][i] or "" for c in curves])
                if validity:
                    vs = [validity[c][i] for c in curves]
                    row += ["" if v["model_valid"] is None else v["model_valid"] for v in vs]
                    row += [v["model_reason"] for v in vs]
                w.writerow(row)


# --- worker side: module globals set before the fork --------------------------------
_JOB: dict = {}


def _one_frequency(omega: float) -> tuple:
    return _frequency(_JOB["scene"], _JOB["settings"], omega)


def _frequency(scene: Scene, ss: SpectrumSettings, omega: float) -> tuple:
    """Both curves at one frequency: ``(no-pendulum result, pendulum result)``."""
    np_res = first_overturn_amplitude(scene.without_pendulum(), omega, ss)
    if scene.gamma == 0.0:
        return np_res, np_res
    return np_res, first_overturn_amplitude(scene, omega, ss)


# More frequencies than any figure plots (the paper's have ~100): a bisection per
# frequency and curve makes 1e5 about an hour of compiled runs.
MAX_FREQUENCIES = 100_000


def _frequencies(omegas) -> np.ndarray:
    """``omegas`` as a 1-D array of 1 to :data:`MAX_FREQUENCIES` values in (0, 1e4]."""
    if isinstance(omegas, (str, bytes)):
        raise TypeError(f"omegas must be numbers, got a {type(omegas).__name__}")
    if hasattr(omegas, "__len__") and len(omegas) > MAX_FREQUENCIES:
        raise ValueError(f"omegas has {len(omegas)} frequencies, more than "
                         f"{MAX_FREQUENCIES}")
    try:
        w = np.atleast_1d(np.asarray(omegas, dtype=float))
    except (TypeError, ValueError):
        raise TypeError("omegas must be a sequence of numbers") from None
    if w.ndim != 1 or w.size == 0 or w.size > MAX_FREQUENCIES or not np.all(np.isfinite(w)) \
            or np.any(w <= 0) or np.any(w > 1e4):
        raise ValueError(f"omegas must be a list of 1 to {MAX_FREQUENCIES} frequencies in "
                         "(0, 1e4] rad/s")
    return w


def overturning_spectrum(scene: Scene, omegas, settings: SpectrumSettings | None = None,
                         workers: int = 1, progress: bool = False, map_fn=None) -> Spectrum:
    """Both curves of the overturning spectrum of ``scene`` over ``omegas``.

    Parameters
    ----------
    scene : Scene
        With its pendulum (``gamma > 0``); the no-pendulum curve uses
        ``scene.without_pendulum()``.  With ``gamma = 0`` both curves coincide.
    omegas : array_like
        Pulse frequencies [rad/s], each in (0, 1e4].
    settings : SpectrumSettings, optional
    workers : int
        The most processes (fork) to use: the highest frequency runs here first
        and :func:`analytic._workers.pool_size` decides from its CPU time how
        many workers the rest is worth.  Results are ordered as ``omegas`` and
        identical whatever the count.
    progress : bool
        Show a tqdm bar (on stderr, only once the run has lasted 1 s).
    map_fn : callable, optional
        ``map_fn(fn, omegas)`` -> ``fn(omega)`` for each, in order: the caller's
        parallel map (e.g. :func:`compare.run.runs.run_many` with a run store or a
        Dask cluster); replaces ``workers``.
    """
    ss = SpectrumSettings() if settings is None else settings
    if not isinstance(ss, SpectrumSettings):
        raise ValueError("settings must be analytic.spectrum.SpectrumSettings")
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be an analytic.Scene, got {type(scene).__name__}")
    w = _frequencies(omegas)
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")
    t0 = time.perf_counter()
    if map_fn is None:  # compile (or load) once, before any fork
        from . import fast
        fast.warm_up(record=False)
    # (A caller's map_fn loads the kernels where runs are made: a store that
    # already holds every frequency then needs no numba at all.)
    _JOB.update(scene=scene, settings=ss)
    bar = None
    if progress:
        from tqdm import tqdm
        # delay: the bar appears only if the run lasts more than a second.
        bar = tqdm(total=int(w.size), unit="freq", desc="spectrum", delay=1.0)
    results = []
    try:
        if map_fn is not None:
            for res in map_fn(functools.partial(_frequency, scene, ss), [float(x) for x in w]):
                results.append(res)
                if bar is not None:
                    bar.update(1)
        else:
            # Highest frequencies first: they scan the most amplitudes, so the one
            # run here before any fork is the costliest (map_measured decides the
            # workers from it) and the workers stay busy to the end.  Results are
            # placed by index, so the order (and every number) is the same for
            # any count.
            order = np.argsort(-w, kind="stable")
            done = map_measured(_one_frequency, [float(w[i]) for i in order], workers,
                                on_done=None if bar is None else (lambda i, r: bar.update(1)))
            results = [None] * int(w.size)
            for k, i in enumerate(order):
                results[int(i)] = done[k]
    finally:
        if bar is not None:
            bar.close()
        _JOB.clear()
    npr = [r[0] for r in results]
    ypr = [r[1] for r in results]
    return Spectrum(
        omega=w, a_no_pendulum=np.array([r[0] for r in npr]),
        a_pendulum=np.array([r[0] for r in ypr]),
        a_no_pendulum_safe=np.array([r[1] for r in npr]),
        a_pendulum_safe=np.array([r[1] for r in ypr]),
        mode_no_pendulum=tuple(r[2] for r in npr), mode_pendulum=tuple(r[2] for r in ypr),
        settings=ss, scene=scene,
        n_runs=sum(r[3] for r in npr) + (sum(r[3] for r in ypr) if scene.gamma else 0),
        n_undecided=sum(r[4] for r in npr) + (sum(r[4] for r in ypr) if scene.gamma else 0),
        wall_time=time.perf_counter() - t0)
