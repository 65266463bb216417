"""Helpers of the event-driven simulator (:mod:`analytic.simulate`).

Its ``Settings`` and pure helpers: the free-pendulum period used by the exact
survival rule, the piecewise-smooth ground acceleration of one integration
segment, the collection of output samples and the return-through-zero search of
one step.  Kept apart so ``simulate.py`` holds only the phase logic.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipk

from .options import RunOptions, check_restitution_factor
from .trajectory import OverturnCriterion  # noqa: F401  (re-exported for callers)

__all__ = ["Settings", "METHODS", "free_pendulum_period", "excitation_window",
           "segment_acceleration", "SampleBuffer", "return_time", "rest_rows"]


METHODS = ("DOP853", "RK45", "Radau", "LSODA")


@dataclass(frozen=True)
class Settings(RunOptions):
    """Settings of the accurate simulator :func:`analytic.simulate.simulate`.

    The shared run options (``criterion``, ``t_max``, ``theta0``, ``psi0``,
    ``early_stop``) are :class:`analytic.options.RunOptions`; the rest are this
    backend's own.  Every field is validated here (``ValueError`` naming the field
    and its range).  The initial state defaults to the trilith at rest with the
    pendulum hanging; ``theta0 != 0`` (or ``theta0 = 0``, ``theta_dot0 != 0``)
    starts rocking about the side of its sign.  ``restitution_factor`` (in (0, 1],
    default 1) multiplies the rocking angular-velocity ratio of every impact
    (:func:`analytic.equations.impact_velocities`; docs/model.md).
    """

    t_cap: float = 120.0  # s after the excitation: safety net of the exact rules (>> rocking decay)
    rtol: float = 1e-10  # energy drift between impacts ~1e-10, far below any engine's error
    atol: float = 1e-12  # rad, rad/s: below rest_velocity by six decades
    method: str = "DOP853"  # 8th order with 7th-order dense output for the event roots
    sample_dt: float | None = 1e-3  # s; 1 ms resolves the fastest rocking (periods ~0.1 s)
    rest_velocity: float = 1e-6  # rad/s: an impact slower than this ends in rest (Zeno)
    rest_step_fraction: float = 1e-2  # max REST step / pulse period; REST also stops at |xg| peaks
    max_events: int = 100_000  # guard against a non-progressing event loop
    theta_dot0: float = 0.0  # rad/s: initial rocking speed
    psi_dot0: float = 0.0  # rad/s: initial pendulum speed
    # Measured over exact impact ratio (Eq. 19/20), in (0, 1]: docs/model.md.
    restitution_factor: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        _check("t_cap", self.t_cap, 0.0, 1e5)
        _check("rtol", self.rtol, 1e-14, 1e-2, lo_open=False)
        _check("atol", self.atol, 0.0, 1.0)
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {self.method!r}")
        if self.sample_dt is not None:
            _check("sample_dt", self.sample_dt, 0.0, 10.0)
        _check("rest_velocity", self.rest_velocity, 0.0, 1.0)
        _check("rest_step_fraction", self.rest_step_fraction, 0.0, 0.1)
        if not isinstance(self.max_events, int) or self.max_events < 1:
            raise ValueError(f"max_events must be an integer >= 1, got {self.max_events!r}")
        for name in ("theta_dot0", "psi_dot0"):
            _check(name, getattr(self, name), -1e3, 1e3, lo_open=False)
        check_restitution_factor(type(self).__name__, self.restitution_factor)


def _check(name: str, value, lo: float, hi: float, lo_open: bool = True) -> None:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    ok = math.isfinite(v) and (v > lo if lo_open else v >= lo) and v <= hi
    if not ok:
        left = "(" if lo_open else "["
        raise ValueError(f"{name} must be in {left}{lo:g}, {hi:g}], got {value!r}")


def free_pendulum_period(psi: float, psi_dot: float, l: float, g: float) -> float:
    """Period [s] of the free pendulum (trilith at rest, ground still) through
    ``(psi, psi_dot)``.

    With the per-unit-mass energy ``e = l^2 psi_dot^2/2 + g l (1 - cos psi)``:

    * libration (``e < 2 g l``): ``T = 4 sqrt(l/g) K(m)``, ``m = sin^2(psi_max/2)
      = e / (2 g l)``;
    * rotation (``e > 2 g l``): ``T = 4 l K(2 g l / e) / sqrt(2 e)``, the time of
      one full turn (the state, and so the uplift margin of Eq. 9, repeats);
    * separatrix (``e = 2 g l``): ``inf`` (the motion is not periodic).

    ``K`` is the complete elliptic integral of the first kind with parameter
    ``m = k^2`` (``scipy.special.ellipk``).  A pendulum hanging still has the
    small-amplitude period ``2 pi sqrt(l/g)``.
    """
    e = 0.5 * l * l * psi_dot * psi_dot + g * l * (1.0 - math.cos(psi))
    sep = 2.0 * g * l
    if e < sep:
        return 4.0 * math.sqrt(l / g) * float(ellipk(e / sep))
    if e > sep:
        return 4.0 * l * float(ellipk(sep / e)) / math.sqrt(2.0 * e)
    return math.inf


def excitation_window(excitation) -> tuple[float, float]:
    """``(t_on, t_off)``: outside this interval the ground is still.

    Both ends are breakpoints of the integration: the one-cosine pulse jumps at
    ``t = 0`` and at ``T_s`` (Eq. 23), a record may start with a non-zero value.
    """
    return float(excitation.start_time), float(excitation.end_time)


def segment_acceleration(excitation, t_a: float, t_b: float) -> Callable[[float], float]:
    """``xg_ddot(t)`` for a segment ``[t_a, t_b]`` that lies inside one smooth
    piece of the excitation: the pulse formula with its values at the segment's
    ends taken from *inside* the segment (one-sided limits at the jumps)."""
    t_on, t_off = excitation_window(excitation)
    mid = 0.5 * (t_a + t_b)
    if mid < t_on or mid > t_off:
        return lambda t: 0.0
    lo, hi = max(t_a, t_on), min(t_b, t_off)
    return excitation.interpolant(lo, hi)


class SampleBuffer:
    """Output samples: a uniform grid ``k * dt`` (from dense output) plus the
    event instants.  ``dt = None`` keeps the integrator's own steps instead."""

    def __init__(self, dt: float | None) -> None:
        self.dt = dt
        self._t: list[np.ndarray] = []
        self._y: list[np.ndarray] = []

    def add_point(self, t: float, theta: float, theta_dot: float, psi: float,
                  psi_dot: float) -> None:
        self._t.append(np.array([t]))
        self._y.append(np.array([[theta, theta_dot, psi, psi_dot]]))

    def add_segment(self, t0: float, t1: float, steps: np.ndarray,
                    evaluate: Callable[[np.ndarray], np.ndarray]) -> None:
        """Samples in ``(t0, t1)``; ``evaluate(times)`` returns rows
        ``(theta, theta_dot, psi, psi_dot)``.  Both ends are added by the caller as
        points (event instants, breakpoints, the start and the end)."""
        if self.dt is None:
            times = np.asarray(steps, dtype=float)
        else:
            k0 = math.ceil(t0 / self.dt - 1e-9)
            k1 = math.ceil(t1 / self.dt - 1e-9)
            times = np.arange(k0, k1, dtype=float) * self.dt
        times = times[(times > t0) & (times < t1)]
        if times.size:
            self._t.append(times)
            self._y.append(np.asarray(evaluate(times), dtype=float).reshape(times.size, 4))

    def arrays(self) -> tuple[np.ndarray, ...]:
        if not self._t:
            return tuple(np.zeros(0) for _ in range(5))
        t = np.concatenate(self._t)
        y = np.concatenate(self._y, axis=0)
        return t, y[:, 0], y[:, 1], y[:, 2], y[:, 3]


def return_time(dense, s: int) -> float | None:
    """First time in one step's dense output where ``s*theta`` falls back through 0
    after being positive; None if it never is positive (unresolved excursion)."""
    ts = np.linspace(dense.t_old, dense.t, 257)
    g = s * dense(ts)[0]
    pos = np.flatnonzero(g > 0.0)
    if pos.size == 0:
        return None
    m = pos[0] + int(np.flatnonzero(g[pos[0]:] <= 0.0)[0])
    return float(brentq(lambda t: s * dense(t)[0], ts[m - 1], ts[m], xtol=1e-15, rtol=1e-15))


def rest_rows(y: np.ndarray) -> np.ndarray:
    """Sample rows ``(0, 0, psi, psi_dot)`` from a REST dense output ``y`` (2 x n)."""
    n = y.shape[1]
    return np.column_stack([np.zeros(n), np.zeros(n), y[0], y[1]])
