"""The first overturning amplitude at one pulse frequency: the search behind the
overturning spectra (:mod:`analytic.spectrum`) and the overturn maps.

The search (``method='windows'``, default)
-------------------------------------------
1. Coarse scan upward from ``A_start`` in steps ``max(scan_step, scan_rel_step A)``
   until the first run that overturns (runs batched in one compiled loop,
   :func:`analytic._fast_kernels.verdicts`).
2. Window scan: every coarse interval below that hit is re-scanned in steps
   ``w(A) = max(window_step, window_rel_step A)`` (``window_step`` defaults to
   ``tol``), lowest interval first, up to the first overturning run, *unless* it
   is quiet: both ends survived with the same number of impacts and came no
   nearer to overturning than ``(1 - energy_margin)`` times the barrier ``B``.
   How near (``e_out``, :func:`analytic._fast_kernels.run`): the largest of the
   frame's potential at its widest swing during the pulse and the energy carried
   out of the pulse (the pulse-end energy, or, if the frame then rocks inward,
   the larger of that energy with ``theta_dot = 0`` and the energy after its
   next impact).  The potential reaches ``B`` only at ``alpha`` and after the
   pulse the energy only drops, so an overturn needs ``e_out >= B``; ``e_out``
   is continuous in ``A`` while the sequence of impacts stays the same (the
   count at both ends).  A window inside a quiet interval would need ``e_out``
   to climb by ``energy_margin`` x ``B`` and fall back within one coarse step on
   one branch of impacts.
3. Bisection of the last safe / first overturning pair down to ``tol``.

Guarantee: every overturning window at least ``w(A)`` wide that lies in a
re-scanned interval is found, so the reported amplitude is the lowest
overturning amplitude within ``+-w(A)`` (``+-tol`` where ``w = tol``, i.e. below
``window_step / window_rel_step``).  Limit: windows narrower than ``w(A)``, and
windows inside quiet intervals, are not searched for; both are checked against
an independent brute-force scan in ``tests/analytic/test_windows.py`` and
``benchmarks/bench_spectrum.py``.

``method='scan'`` is the previous search (coarse scan, then bisection, no
window scan), kept for comparison: it misses windows narrower than its step.

Nothing below ``A_start`` overturns: without a pendulum ``A_start = g/lam``, the
uplift acceleration (Eq. 11).  With a pendulum the swinging mass can lower the
uplift amplitude (measured on the Fig. 5 scene: uplift from ``0.85 g/lam`` for a
one-cosine pulse at ``Omega = 1``), so the scan starts at ``start_fraction * g/lam``.

Every run is decided by the compiled fast path (:mod:`analytic.fast`, exact
survival rules, a certain overturn ends the run) with the criterion and
``t_max`` carried into the result.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, field

import numpy as np

from .equations import overturn_energy_barrier
from .excitation import OMEGA_RANGE, PULSE_KINDS
from .fast_settings import Settings as FastSettings
from .parameters import Scene
from .pulses import PULSE_FAMILY, PulseShape
from .trajectory import OverturnCriterion

__all__ = ["SpectrumSettings", "first_overturn_amplitude", "METHODS", "SEARCH_RTOL",
           "SEARCH_ATOL", "search_run_settings"]

METHODS = ("windows", "scan")
_CHUNK = 16  # largest batch of coarse runs per compiled call (batches grow 2, 4, ... 16)

# DP5 tolerances of the search's runs.  A verdict needs less than a trajectory
# (analytic.fast's 1e-8): against runs at rtol 1e-10, the thresholds at 1e-6 stay
# within tol on the Fig. 5 fine grid and six other scene/pulse grids (1850
# searches, largest shift 0.0093 m/s^2: one bisection step); 1e-5 moves 6 of them
# beyond tol, 1e-4 over 100 (docs/overturn-maps.md).  Half the time of 1e-8.
SEARCH_RTOL, SEARCH_ATOL = 1e-6, 1e-8


def search_run_settings(**options) -> FastSettings:
    """:class:`analytic.fast.Settings` of a search's runs: ``SEARCH_RTOL`` /
    ``SEARCH_ATOL`` and ``options`` (criterion, t_max, ...)."""
    return FastSettings(**{"rtol": SEARCH_RTOL, "atol": SEARCH_ATOL, **options})


@dataclass(frozen=True)
class SpectrumSettings:
    """How a spectrum is searched (see the module docstring)."""

    # One-sine (Eq. 22) or one-cosine (Eq. 23) pulse (compiled search), or another
    # shape of analytic.pulses.PULSE_FAMILY or a PulseShape (accurate model,
    # analytic.shape_threshold); its amplitude is the peak ground acceleration.
    pulse: str | PulseShape = "sine"
    # Bisection resolution [m/s^2]: finer than the paper's plots can show.
    tol: float = 0.01
    # Coarse scan step floor [m/s^2] and relative step.
    scan_step: float = 0.1
    scan_rel_step: float = 0.02
    # Pendulum curve starts at this fraction of g/lam (measured uplift from 0.85 g/lam).
    start_fraction: float = 0.5
    # Largest amplitude tried [m/s^2] (NaN past it): one-cosine Fig. 5 needs ~650 at Omega=30.
    a_max: float = 1000.0
    # 'windows' (coarse scan, window scan, bisection) or 'scan' (the previous search).
    method: str = "windows"
    # Window scan step floor [m/s^2] (None: tol) and relative step.
    window_step: float | None = None
    window_rel_step: float = 0.003
    # Coarse intervals whose ends both came no nearer than (1 - margin) x barrier,
    # with the same impact count, are not re-scanned.  A heuristic: the typical
    # rise of e_out between such coarse points is 0.01 barrier, but 0.5 % of
    # them rise by 0.1 or more; no window was lost against an exhaustive scan on
    # 11 772 searches (docs/overturn-maps.md).
    energy_margin: float = 0.1
    # Integrator settings of every run (criterion, t_max, tolerances).
    fast: FastSettings = field(default_factory=search_run_settings)

    def __post_init__(self) -> None:
        if not (isinstance(self.pulse, PulseShape) or isinstance(self.pulse, str)
                and self.pulse in PULSE_FAMILY):
            raise ValueError(f"pulse must be one of {PULSE_FAMILY} or a PulseShape, "
                             f"got {self.pulse!r}")
        if isinstance(self.pulse, PulseShape) and self.pulse.kind in PULSE_KINDS:
            object.__setattr__(self, "pulse", self.pulse.kind)
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {self.method!r}")
        for name, lo, hi in (("tol", 1e-6, 10.0), ("scan_step", 1e-4, 100.0),
                             ("scan_rel_step", 0.0, 1.0), ("start_fraction", 0.0, 1.0),
                             ("a_max", 0.0, 1e4), ("window_step", 1e-6, 10.0),
                             ("window_rel_step", 0.0, 0.1), ("energy_margin", 0.0, 1.0)):
            v = getattr(self, name)
            if name == "window_step" and v is None:
                continue
            inclusive = name in ("scan_rel_step", "window_rel_step", "energy_margin")
            ok = isinstance(v, (int, float)) and math.isfinite(v) and (
                (v >= lo) if inclusive else (v > lo)) and v <= hi
            if not ok:
                raise ValueError(f"{name} must be in ({lo:g}, {hi:g}], got {v!r}")
        if self.tol > self.scan_step:
            raise ValueError(f"tol ({self.tol:g}) must not exceed scan_step ({self.scan_step:g})")
        if not isinstance(self.fast, FastSettings):
            raise ValueError("fast must be analytic.fast.Settings")

    @property
    def compiled(self) -> bool:
        """True when the compiled search covers the pulse (one-sine, one-cosine)."""
        return isinstance(self.pulse, str) and self.pulse in PULSE_KINDS

    @property
    def criterion(self) -> OverturnCriterion:
        return self.fast.criterion

    @property
    def t_max(self) -> float | None:
        return self.fast.t_max

    def window_width(self, a: float) -> float:
        """``w(A)`` [m/s^2]: the narrowest window the search is sure to find at ``A``."""
        floor = self.tol if self.window_step is None else self.window_step
        return max(floor, self.window_rel_step * a)

    def describe(self) -> dict:
        out = asdict(self)
        out["fast"] = self.fast.describe()
        return out


def _a_start(scene: Scene, ss: SpectrumSettings) -> float:
    a_np = scene.g / scene.lam  # Eq. 11: no uplift, hence no overturning, below it
    return a_np if scene.gamma == 0.0 else ss.start_fraction * a_np


class _Runner:
    """Runs of one (scene, frequency): compiled verdicts plus counters."""

    def __init__(self, scene: Scene, omega: float, ss: SpectrumSettings):
        from . import _fast_kernels, fast  # numba: imported when a run is made
        self._k = _fast_kernels
        self.args = fast.kernel_args(scene, omega, ss.pulse, ss.fast)
        self.quiet_energy = (1.0 - ss.energy_margin) * overturn_energy_barrier(
            *scene.model_args()[:4], scene.g)
        self.n_runs = 0
        self.n_und = 0

    def __call__(self, amps):
        """``(overturned, n_impacts, quiet)`` arrays for amplitudes ``amps``."""
        _k = self._k
        st, _rs, _tv, ni, e_out = _k.verdicts(np.asarray(amps, dtype=float), *self.args)
        self.n_runs += len(st)
        self.n_und += int(np.sum((st == _k.ST_UNDECIDED) | (st == _k.ST_UNSTABLE)))
        quiet = (st == _k.ST_SURVIVED) & (e_out < self.quiet_energy)
        return st == _k.ST_OVERTURNED, ni, quiet


def _coarse_grid(a_lo: float, ss: SpectrumSettings, n: int) -> list[float]:
    out = []
    a = a_lo
    for _ in range(n):
        a = a + max(ss.scan_step, ss.scan_rel_step * a)
        if a > ss.a_max:
            break
        out.append(a)
    return out


def first_overturn_amplitude(scene: Scene, omega: float, ss: SpectrumSettings
                             ) -> tuple[float, float, str | None, int, int]:
    """Search one frequency (module docstring).

    Returns ``(a_overturn, a_safe, mode, n_runs, n_undecided)``: the smallest
    amplitude found to overturn, the largest amplitude below it found safe
    (``a_overturn - a_safe <= tol``), the overturning mode at ``a_overturn``.
    ``a_overturn`` is NaN (mode None) when nothing overturns up to ``a_max``.
    """
    if isinstance(omega, bool) or not isinstance(omega, numbers.Real) or not (
            math.isfinite(omega) and OMEGA_RANGE[0] <= omega <= OMEGA_RANGE[1]):
        raise ValueError(f"omega must be in [{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}] rad/s, "
                         f"got {omega!r}")
    if not ss.compiled:
        from .shape_threshold import first_overturn_pga
        return first_overturn_pga(scene, omega, ss)
    run = _Runner(scene, omega, ss)
    a0 = _a_start(scene, ss)
    over, ni0, quiet0 = run([a0])
    if over[0]:  # nothing is known below the start: refuse to report a wrong "first"
        raise ValueError(f"a run overturns at the scan start A={a0:.4g} m/s^2 "
                         f"(Omega={omega:g}); lower start_fraction")
    # 1. coarse scan, in compiled batches
    amps, quiet, impacts = [a0], [bool(quiet0[0])], [int(ni0[0])]
    hit = None
    batch = 2  # grows: few runs wasted past the first hit, few calls on a long scan
    while hit is None:
        grid = _coarse_grid(amps[-1], ss, batch)
        batch = min(2 * batch, _CHUNK)
        if not grid:
            return math.nan, amps[-1], None, run.n_runs, run.n_und
        ov, ni, qu = run(grid)
        k = int(np.argmax(ov)) if ov.any() else len(grid)
        amps += grid[:k]
        quiet += [bool(q) for q in qu[:k]]
        impacts += [int(n) for n in ni[:k]]
        if k < len(grid):
            hit = (grid[k], int(ni[k]))
    a_lo, (a_hi, n_hi) = amps[-1], hit
    # 2. window scan of the non-quiet coarse intervals, lowest first
    if ss.method == "windows":
        bounds = amps + [a_hi]
        for i in range(len(amps)):
            last = i == len(amps) - 1
            if not last and quiet[i] and quiet[i + 1] and impacts[i] == impacts[i + 1]:
                continue
            lo, hi = bounds[i], bounds[i + 1]
            fine = []
            a = lo
            while True:
                a = a + ss.window_width(a)
                if a >= hi:
                    break
                fine.append(a)
            if not fine:
                if last:
                    break
                continue
            ov, ni, _ = run(fine)
            if ov.any():
                k = int(np.argmax(ov))
                a_lo = fine[k - 1] if k > 0 else lo
                a_hi, n_hi = fine[k], int(ni[k])
                break
            if last:
                a_lo = fine[-1]
    # 3. bisection of the last safe / first overturning pair
    while a_hi - a_lo > ss.tol:
        mid = 0.5 * (a_lo + a_hi)
        ov, ni, _ = run([mid])
        if ov[0]:
            a_hi, n_hi = mid, int(ni[0])
        else:
            a_lo = mid
    return a_hi, a_lo, ("after-impact" if n_hi > 0 else "no-impact"), run.n_runs, run.n_und
