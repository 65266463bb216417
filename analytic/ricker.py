"""Ricker wavelets of ground acceleration (as used for rocking by Vassiliou and
Makris), with ``tau = pi (t - t_c) / T_p``:

* symmetric: ``a(t) = A (1 - 2 tau^2) exp(-tau^2)`` (the "Mexican hat"; its
  Fourier amplitude peaks at ``f_p = 1/T_p``);
* antisymmetric: the time derivative of the symmetric wavelet scaled to the peak
  ``A``: ``a(t) = A (6 tau - 4 tau^3) exp(-tau^2) / kappa``, ``kappa`` its largest
  value (at ``tau^2 = (3 - sqrt 6)/2``).

Both are truncated at ``|tau| = 5`` (``exp(-25)``: the jump at the ends is below
1e-9 A); the centre is ``t_c = 5 T_p / pi``, so the wavelet starts at ``t = 0``.
Both have zero net velocity and displacement (exact for the untruncated
wavelet: the velocity is ``A T_p/pi tau exp(-tau^2)`` for the symmetric one).
Members as every ground motion's (:mod:`analytic.pulses`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .excitation import (MAX_ACCELERATION, MAX_PULSE_LENGTH, Excitation, _check_amplitude,
                         _positive_factor, _real)

__all__ = ["Ricker", "RICKER_KINDS", "RICKER_TAU_MAX"]

RICKER_KINDS = ("symmetric", "antisymmetric")
RICKER_TAU_MAX = 5.0  # half-width of the truncated wavelet in tau
# Largest value of (6 tau - 4 tau^3) exp(-tau^2), at tau^2 = (3 - sqrt 6) / 2.
_TAU_ANTI = math.sqrt((3.0 - math.sqrt(6.0)) / 2.0)
_KAPPA = (6.0 * _TAU_ANTI - 4.0 * _TAU_ANTI ** 3) * math.exp(-_TAU_ANTI ** 2)
# Shortest pulse period [s] (as Pulse: Omega <= 1e4 rad/s).
MIN_PERIOD = 2.0 * math.pi / 1e4


@dataclass(frozen=True)
class Ricker(Excitation):
    """A Ricker wavelet of ground acceleration (module docstring).

    Parameters
    ----------
    amplitude : float
        Peak acceleration ``A`` [m/s^2], ``|A| <= 1e4``; negative mirrors it.
    period : float
        ``T_p = 1/f_p`` [s], in [6.3e-4, 19.7]: the truncated wavelet lasts
        ``10 T_p / pi``, at most 62.8 s like the other pulses.
    kind : {'symmetric', 'antisymmetric'}

    Examples
    --------
    >>> w = Ricker(2.0, 0.5)
    >>> round(w.acceleration(w.centre), 12), round(w.end_time, 6)
    (2.0, 1.591549)
    """

    amplitude: float
    period: float
    kind: str = "symmetric"
    type_name = "ricker"

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in RICKER_KINDS:
            raise ValueError(f"Ricker kind must be one of {RICKER_KINDS}, got {self.kind!r}")
        a = _check_amplitude("amplitude", self.amplitude, MAX_ACCELERATION, "m/s^2")
        tp = _real("period", self.period)
        top = MAX_PULSE_LENGTH * math.pi / (2.0 * RICKER_TAU_MAX)
        if not (math.isfinite(tp) and MIN_PERIOD <= tp <= top):
            raise ValueError(f"period must be in [{MIN_PERIOD:.2g}, {top:.3g}] s, got {self.period!r}")
        object.__setattr__(self, "amplitude", a)
        object.__setattr__(self, "period", tp)

    @property
    def centre(self) -> float:
        """``t_c`` [s]: the wavelet's centre."""
        return RICKER_TAU_MAX * self.period / math.pi

    @property
    def end_time(self) -> float:
        return 2.0 * self.centre

    @property
    def _symmetric(self) -> bool:
        return self.kind == "symmetric"

    def _tau(self, t):
        return math.pi * (t - self.centre) / self.period

    @property
    def peak_times(self) -> tuple[float, ...]:
        roots = ((-math.sqrt(1.5), 0.0, math.sqrt(1.5)) if self._symmetric else
                 tuple(s * math.sqrt((3.0 + k * math.sqrt(6.0)) / 2.0)
                       for s in (-1.0, 1.0) for k in (-1.0, 1.0)))
        return tuple(sorted(self.centre + r * self.period / math.pi for r in roots))

    def acceleration_array(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        tau = self._tau(t)
        shape = ((1.0 - 2.0 * tau ** 2) if self._symmetric else
                 (6.0 * tau - 4.0 * tau ** 3) / _KAPPA) * np.exp(-tau ** 2)
        return np.where((t >= 0.0) & (t <= self.end_time), self.amplitude * shape, 0.0)

    def acceleration(self, t: float) -> float:
        return float(self.acceleration_array(t))

    def _velocity_shape(self, tau: float) -> float:
        """``v / (A T_p / pi)`` up to a constant: the antiderivative in tau."""
        if self._symmetric:
            return tau * math.exp(-tau * tau)
        return -(1.0 - 2.0 * tau * tau) * math.exp(-tau * tau) / _KAPPA

    def _displacement_shape(self, tau: float) -> float:
        if self._symmetric:
            return -0.5 * math.exp(-tau * tau)
        return -tau * math.exp(-tau * tau) / _KAPPA

    def velocity(self, t: float) -> float:
        tc = min(max(t, 0.0), self.end_time)
        k = self.amplitude * self.period / math.pi
        return k * (self._velocity_shape(self._tau(tc)) - self._velocity_shape(-RICKER_TAU_MAX))

    def displacement(self, t: float) -> float:
        tc = min(max(t, 0.0), self.end_time)
        k = self.amplitude * self.period / math.pi
        v0 = self._velocity_shape(-RICKER_TAU_MAX)
        x = k * self.period / math.pi * (self._displacement_shape(self._tau(tc))
                                         - self._displacement_shape(-RICKER_TAU_MAX))
        x -= k * v0 * tc
        return x + self.velocity(self.end_time) * max(t - self.end_time, 0.0)

    @property
    def pga(self) -> float:
        return abs(self.amplitude)

    @property
    def pgv(self) -> float:
        """``|A| T_p / pi`` times ``exp(-1/2)/sqrt 2`` (symmetric, at ``tau^2 = 1/2``)
        or ``1/kappa`` (antisymmetric, at ``tau = 0``)."""
        peak = math.exp(-0.5) / math.sqrt(2.0) if self._symmetric else 1.0 / _KAPPA
        return abs(self.amplitude) * self.period / math.pi * peak

    def scaled(self, factor: float) -> "Ricker":
        return Ricker(_positive_factor(factor) * self.amplitude, self.period, self.kind)

    def mirrored(self) -> "Ricker":
        return Ricker(-self.amplitude, self.period, self.kind)

    def describe(self) -> dict:
        return {"type": "ricker", "kind": self.kind, "amplitude": self.amplitude,
                "period": self.period}
