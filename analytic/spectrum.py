"""Overturning spectra (paper Section 5.2, Fig. 5): the first overturning amplitude
per pulse frequency, with and without the pendulum, and the gain Delta.

For each ``Omega`` the amplitude ``A`` is raised from ``A_start`` in scan steps
until the first run that overturns, then the last safe / first overturning pair
is bisected down to ``tol``.  The reported amplitude is the *first overturning
amplitude found from below* (the paper's definition: "the amplitude ... which
corresponds to the first overturning occurrence"); safe islands above it are
not explored.

What the scan guarantees
------------------------
Nothing below ``A_start`` overturns: without a pendulum ``A_start = g/lam``, the
uplift acceleration (Eq. 11), below which the frame never leaves the ground.
With a pendulum the swinging mass can lower the uplift amplitude (measured on
the Fig. 5 scene: uplift from ``0.85 g/lam`` for a one-cosine pulse at
``Omega = 1``), so the scan starts at ``start_fraction * g/lam``.

Between scan points nothing is known: an overturning window narrower than the
scan step can be stepped over, and the reported amplitude is then the start of
a later window.  The step is ``max(scan_step, scan_rel_step * A)``.  The
default (0.1 m/s^2, 2 %) was chosen against scans at 0.01 m/s^2 (bisection to
0.005) on the Fig. 5 scene, Omega = 3..30 step 1, both curves: it gives the
same first amplitudes within 0.006 m/s^2 except at Omega = 7 with the pendulum,
where the 0.01 scan finds a first window 0.04 m/s^2 below (a window narrower
than 0.05 m/s^2; a 0.05 m/s^2 scan misses it too, at 6x the cost).  The
narrowest overturning windows measured there are 0.01-0.05 m/s^2 wide, all at
``A < 5`` m/s^2; above, the first window runs on to the largest amplitude
scanned.  ``benchmarks/bench_spectrum.py`` repeats the comparison.  This
was measured for the one-sine pulse only; one-cosine spectra use the same step
unchecked.

Every run is decided by the compiled fast path (:func:`analytic.fast.overturn_verdict`)
with the criterion and ``t_max`` carried into the result.
"""
from __future__ import annotations

import functools
import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field

import numpy as np

from . import _fast_kernels as _k
from . import fast
from .excitation import PULSE_KINDS
from .parameters import Scene
from .trajectory import OverturnCriterion

__all__ = ["SpectrumSettings", "Spectrum", "first_overturn_amplitude", "overturning_spectrum",
           "parse_omega_range"]

_KIND = {"sine": _k.KIND_SINE, "cosine": _k.KIND_COSINE}


@dataclass(frozen=True)
class SpectrumSettings:
    """How a spectrum is searched."""

    # One-sine (Eq. 22) or one-cosine (Eq. 23) pulse.
    pulse: str = "sine"
    # Bisection resolution [m/s^2]: finer than the paper's plots can show.
    tol: float = 0.01
    # Scan step floor [m/s^2]: as good as 0.05 against 0.01 scans (see module doc).
    scan_step: float = 0.1
    # Relative scan step: at high amplitude no narrow first window was measured.
    scan_rel_step: float = 0.02
    # Pendulum curve starts at this fraction of g/lam (measured uplift from 0.85 g/lam).
    start_fraction: float = 0.5
    # Largest amplitude tried [m/s^2] (NaN past it): one-cosine Fig. 5 needs ~650 at Omega=30.
    a_max: float = 1000.0
    # Integrator settings of every run (criterion, t_max, tolerances).
    fast: fast.Settings = field(default_factory=fast.Settings)

    def __post_init__(self) -> None:
        if self.pulse not in PULSE_KINDS:
            raise ValueError(f"pulse must be one of {PULSE_KINDS}, got {self.pulse!r}")
        for name, lo, hi in (("tol", 1e-6, 10.0), ("scan_step", 1e-4, 100.0),
                             ("scan_rel_step", 0.0, 1.0), ("start_fraction", 0.0, 1.0),
                             ("a_max", 0.0, 1e4)):
            v = getattr(self, name)
            ok = isinstance(v, (int, float)) and math.isfinite(v) and (
                (v >= lo) if name == "scan_rel_step" else (v > lo)) and v <= hi
            if not ok:
                raise ValueError(f"{name} must be in ({lo:g}, {hi:g}], got {v!r}")
        if self.tol > self.scan_step:
            raise ValueError(f"tol ({self.tol:g}) must not exceed scan_step ({self.scan_step:g})")
        if not isinstance(self.fast, fast.Settings):
            raise ValueError("fast must be analytic.fast.Settings")

    @property
    def criterion(self) -> OverturnCriterion:
        return self.fast.criterion

    @property
    def t_max(self) -> float | None:
        return self.fast.t_max

    def describe(self) -> dict:
        out = asdict(self)
        out["fast"] = self.fast.describe()
        return out


def parse_omega_range(spec: str, option: str = "--omega") -> np.ndarray:
    """``'START:STOP:STEP'`` (STOP included) or ``'W1,W2,...'`` -> frequencies [rad/s]."""
    text = str(spec).strip()
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) != 3:
                raise ValueError
            start, stop, step = parts
            if not all(math.isfinite(p) for p in parts) or step <= 0 or stop < start:
                raise ValueError
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            values = np.round(start + step * np.arange(n), 12)
        else:
            values = np.array([float(p) for p in text.split(",")])
    except ValueError:
        raise ValueError(f"{option} expects START:STOP:STEP with 0 < START <= STOP, STEP > 0 "
                         f"(or a comma list), got {spec!r}") from None
    if values.size == 0 or values.size > 100_000:
        raise ValueError(f"{option} must give 1 to 100000 frequencies, got {values.size}")
    if not np.all(np.isfinite(values)) or np.any(values <= 0) or np.any(values > 1e4):
        raise ValueError(f"{option}: every frequency must be in (0, 1e4] rad/s, got {spec!r}")
    return values


def _a_start(scene: Scene, ss: SpectrumSettings) -> float:
    a_np = scene.g / scene.lam  # Eq. 11: no uplift, hence no overturning, below it
    return a_np if scene.gamma == 0.0 else ss.start_fraction * a_np


def first_overturn_amplitude(scene: Scene, omega: float, ss: SpectrumSettings
                             ) -> tuple[float, float, str | None, int, int]:
    """Scan and bisect one frequency.

    Returns ``(a_overturn, a_safe, mode, n_runs, n_undecided)``: the smallest
    amplitude found to overturn, the largest amplitude below it found safe
    (``a_overturn - a_safe <= tol``), the overturning mode at ``a_overturn``.
    ``a_overturn`` is NaN (mode None) when nothing overturns up to ``a_max``.
    """
    b, h, mu, gamma, j, l, g = scene.model_args()
    st = ss.fast
    thr = st.criterion.threshold(scene.alpha)
    t_max = -1.0 if st.t_max is None else float(st.t_max)
    kind = _KIND[ss.pulse]
    period = 2.0 * math.pi / omega
    n_runs = 0
    n_und = 0

    def run(a):
        nonlocal n_runs, n_und
        n_runs += 1
        status, _r, _t, n_imp = _k.verdict(b, h, mu, gamma, j, l, g, a, omega, kind, period,
                                           thr, st.rtol, st.atol, st.rest_velocity, t_max,
                                           st.t_cap, st.max_steps, st.rest_step_fraction)
        if status == _k.ST_UNDECIDED or status == _k.ST_UNSTABLE:
            n_und += 1
        return status == _k.ST_OVERTURNED, n_imp

    a_lo = _a_start(scene, ss)
    over, _ = run(a_lo)
    if over:  # nothing is known below the start: refuse to report a wrong "first"
        raise ValueError(f"a run overturns at the scan start A={a_lo:.4g} m/s^2 "
                         f"(Omega={omega:g}); lower start_fraction")
    a_hi = math.nan
    n_hi = 0
    while True:
        a = a_lo + max(ss.scan_step, ss.scan_rel_step * a_lo)
        if a > ss.a_max:
            return math.nan, a_lo, None, n_runs, n_und
        over, n_imp = run(a)
        if over:
            a_hi, n_hi = a, n_imp
            break
        a_lo = a
    while a_hi - a_lo > ss.tol:
        mid = 0.5 * (a_lo + a_hi)
        over, n_imp = run(mid)
        if over:
            a_hi, n_hi = mid, n_imp
        else:
            a_lo = mid
    return a_hi, a_lo, ("after-impact" if n_hi > 0 else "no-impact"), n_runs, n_und


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
        """``Delta = 100 (A_yp - A_np) / A_np`` (Section 5.2)."""
        return 100.0 * (self.a_pendulum - self.a_no_pendulum) / self.a_no_pendulum

    def mode_jumps(self) -> list[dict]:
        """Where the overturning mode changes between consecutive frequencies."""
        out = []
        for curve, modes in (("no_pendulum", self.mode_no_pendulum),
                             ("pendulum", self.mode_pendulum)):
            for i in range(len(modes) - 1):
                if modes[i] is not None and modes[i + 1] is not None and modes[i] != modes[i + 1]:
                    out.append({"curve": curve, "omega_before": float(self.omega[i]),
                                "omega_after": float(self.omega[i + 1]),
                                "mode_before": modes[i], "mode_after": modes[i + 1]})
        return out

    def to_dict(self) -> dict:
        def arr(a):
            return [float(x) if math.isfinite(x) else None for x in np.asarray(a)]
        return {
            "omega": arr(self.omega),
            "a_no_pendulum": arr(self.a_no_pendulum),
            "a_pendulum": arr(self.a_pendulum),
            "a_no_pendulum_safe": arr(self.a_no_pendulum_safe),
            "a_pendulum_safe": arr(self.a_pendulum_safe),
            "gain_percent": arr(self.gain_percent),
            "mode_no_pendulum": list(self.mode_no_pendulum),
            "mode_pendulum": list(self.mode_pendulum),
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

    def to_csv(self, path) -> None:
        with open(path, "w") as fh:
            fh.write("omega,a_no_pendulum,a_pendulum,gain_percent,mode_no_pendulum,"
                     "mode_pendulum\n")
            for i, w in enumerate(self.omega):
                fh.write(f"{w:.12g},{self.a_no_pendulum[i]:.12g},{self.a_pendulum[i]:.12g},"
                         f"{self.gain_percent[i]:.12g},{self.mode_no_pendulum[i] or ''},"
                         f"{self.mode_pendulum[i] or ''}\n")


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
        Processes (fork); results are ordered as ``omegas`` whatever the count.
    progress : bool
        Show a tqdm bar (on stderr, only once the run has lasted 1 s).
    map_fn : callable, optional
        ``map_fn(fn, omegas)`` -> ``fn(omega)`` for each, in order: the caller's
        parallel map (e.g. :func:`compare.runs.run_many` with a run store or a
        Dask cluster); replaces ``workers``.
    """
    ss = SpectrumSettings() if settings is None else settings
    if not isinstance(ss, SpectrumSettings):
        raise ValueError("settings must be analytic.spectrum.SpectrumSettings")
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be an analytic.Scene, got {type(scene).__name__}")
    w = np.atleast_1d(np.asarray(omegas, dtype=float))
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0) \
            or np.any(w > 1e4):
        raise ValueError("omegas must be a non-empty list of frequencies in (0, 1e4] rad/s")
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")
    t0 = time.perf_counter()
    fast.warm_up(record=False)  # compile (or load) once, before any fork
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
        elif workers == 1 or w.size == 1:
            for omega in w:
                results.append(_one_frequency(float(omega)))
                if bar is not None:
                    bar.update(1)
        else:
            ctx = multiprocessing.get_context("fork")
            # Highest frequencies first: they scan the most amplitudes, and starting
            # with them keeps both workers busy to the end.  Results are placed by
            # index, so the order (and every number) is the same for any count.
            order = np.argsort(-w, kind="stable")
            slots: list = [None] * int(w.size)
            with ProcessPoolExecutor(max_workers=min(workers, int(w.size)), mp_context=ctx) as ex:
                futures = {ex.submit(_one_frequency, float(w[i])): int(i) for i in order}
                for fut in as_completed(futures):
                    slots[futures[fut]] = fut.result()
                    if bar is not None:
                        bar.update(1)
            results = slots
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
