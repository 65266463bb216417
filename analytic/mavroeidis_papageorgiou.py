"""The Mavroeidis and Papageorgiou (2003) near-fault pulse, velocity with
``tau = t - t_0``, ``t_0 = gamma / (2 f_p)`` (the pulse starts at ``t = 0``)::

    v(t) = A/2 [1 + cos(2 pi f_p tau / gamma)] cos(2 pi f_p tau + nu),
           |tau| <= gamma / (2 f_p),   0 elsewhere.

Its acceleration is the derivative, its displacement the closed-form integral;
the velocity is zero at both ends (zero net velocity), the net displacement is
not zero in general (it depends on ``nu``).  Members as every ground motion's
(:mod:`analytic.pulses`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .excitation import (MAX_ACCELERATION, MAX_PULSE_LENGTH, Excitation, _check_amplitude,
                         _positive_factor, _real)

__all__ = ["MavroeidisPapageorgiou"]


@dataclass(frozen=True)
class MavroeidisPapageorgiou(Excitation):
    """The Mavroeidis-Papageorgiou (2003) near-fault velocity pulse (module docstring).

    Parameters
    ----------
    velocity_amplitude : float
        ``A`` [m/s], the velocity envelope's peak (``v(t_0) = A cos(nu)``).
    frequency : float
        Prevailing frequency ``f_p`` [Hz], > 0; the pulse lasts ``gamma/f_p`` <= 62.8 s.
    gamma : float, default 2
        Oscillatory character, in (1, 20] (MP fit 1.5-3 to near-fault records).
    nu : float, default 0
        Phase [rad], in [-2 pi, 2 pi].

    Raises
    ------
    ValueError
        A value out of its range, or a peak acceleration bound
        ``pi f_p |A| (1/gamma + 2)`` above 1e4 m/s^2.
    """

    velocity_amplitude: float
    frequency: float
    gamma: float = 2.0
    nu: float = 0.0
    type_name = "mavroeidis-papageorgiou"

    def __post_init__(self) -> None:
        a = _check_amplitude("velocity_amplitude", self.velocity_amplitude, 1e3, "m/s")
        fp = _real("frequency", self.frequency)
        gm = _real("gamma", self.gamma)
        nu = _real("nu", self.nu)
        if not (math.isfinite(gm) and 1.0 < gm <= 20.0):
            raise ValueError(f"gamma must be in (1, 20], got {self.gamma!r}")
        if not (math.isfinite(fp) and fp > 0.0 and gm / fp <= MAX_PULSE_LENGTH
                and fp <= 1e4 / (2.0 * math.pi)):
            raise ValueError(f"frequency must be in [{gm / MAX_PULSE_LENGTH:.3g}, "
                             f"{1e4 / (2 * math.pi):.4g}] Hz (pulse length gamma/f_p <= "
                             f"{MAX_PULSE_LENGTH:.1f} s), got {self.frequency!r}")
        if not (math.isfinite(nu) and abs(nu) <= 2.0 * math.pi):
            raise ValueError(f"nu must be in [-2 pi, 2 pi] rad, got {self.nu!r}")
        if math.pi * fp * abs(a) * (1.0 / gm + 2.0) > MAX_ACCELERATION:
            raise ValueError(f"velocity_amplitude {a:g} m/s at {fp:g} Hz gives accelerations "
                             f"beyond {MAX_ACCELERATION:g} m/s^2")
        for name, value in (("velocity_amplitude", a), ("frequency", fp), ("gamma", gm),
                            ("nu", nu)):
            object.__setattr__(self, name, value)

    @property
    def t0(self) -> float:
        """Centre of the envelope [s]."""
        return 0.5 * self.gamma / self.frequency

    @property
    def end_time(self) -> float:
        return 2.0 * self.t0

    def _phases(self, t):
        w = 2.0 * math.pi * self.frequency
        tau = t - self.t0
        return w, w * tau / self.gamma, w * tau + self.nu

    def acceleration_array(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        w, env, car = self._phases(t)
        a = -(0.5 * self.velocity_amplitude * w / self.gamma) * (
            np.sin(env) * np.cos(car) + self.gamma * np.sin(car) * (1.0 + np.cos(env)))
        return np.where((t >= 0.0) & (t <= self.end_time), a, 0.0)

    def acceleration(self, t: float) -> float:
        return float(self.acceleration_array(t))

    def _antiderivative(self, t: float) -> float:
        """``int v dt`` from the product-to-sum form of ``v`` (needs gamma != 1)."""
        w, env, car = self._phases(t)
        r = 1.0 / self.gamma
        return 0.5 * self.velocity_amplitude * (
            math.sin(car) / w + 0.5 * math.sin(car + env) / (w * (1.0 + r))
            + 0.5 * math.sin(car - env) / (w * (1.0 - r)))

    def velocity(self, t: float) -> float:
        if t <= 0.0 or t >= self.end_time:
            return 0.0
        w, env, car = self._phases(t)
        return 0.5 * self.velocity_amplitude * (1.0 + math.cos(env)) * math.cos(car)

    def displacement(self, t: float) -> float:
        tc = min(max(t, 0.0), self.end_time)
        return self._antiderivative(tc) - self._antiderivative(0.0)

    def _grid(self) -> np.ndarray:
        # 400 samples per carrier cycle: |a| and |v| peaks to ~3e-5 relative.
        n = int(400 * self.gamma) + 1
        return np.linspace(0.0, self.end_time, n)

    @property
    def peak_times(self) -> tuple[float, ...]:
        """Local maxima of ``|a|``: bracketed on a grid, refined by a bounded search."""
        t = self._grid()
        a = np.abs(self.acceleration_array(t))
        inner = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
        from scipy.optimize import minimize_scalar  # here: the CLI's parser imports this module
        out = []
        for i in inner:
            res = minimize_scalar(lambda x: -abs(self.acceleration(x)), method="bounded",
                                  bounds=(float(t[i - 1]), float(t[i + 1])),
                                  options={"xatol": 1e-12 * self.end_time})
            out.append(float(res.x))
        return tuple(out)

    @property
    def pga(self) -> float:
        return max(abs(self.acceleration(x)) for x in self.peak_times)

    @property
    def pgv(self) -> float:
        """Largest ``|v|``: at a zero of the acceleration, refined like the peaks."""
        t = self._grid()
        v = np.abs([self.velocity(float(x)) for x in t])
        i = int(np.argmax(v))
        lo, hi = float(t[max(i - 1, 0)]), float(t[min(i + 1, t.size - 1)])
        from scipy.optimize import minimize_scalar
        res = minimize_scalar(lambda x: -abs(self.velocity(x)), method="bounded",
                              bounds=(lo, hi), options={"xatol": 1e-12 * self.end_time})
        return max(float(v[i]), abs(self.velocity(float(res.x))))

    def scaled(self, factor: float) -> "MavroeidisPapageorgiou":
        return MavroeidisPapageorgiou(_positive_factor(factor) * self.velocity_amplitude,
                                      self.frequency, self.gamma, self.nu)

    def mirrored(self) -> "MavroeidisPapageorgiou":
        return MavroeidisPapageorgiou(-self.velocity_amplitude, self.frequency, self.gamma,
                                      self.nu)

    def describe(self) -> dict:
        return {"type": "mavroeidis-papageorgiou", "velocity_amplitude": self.velocity_amplitude,
                "frequency": self.frequency, "gamma": self.gamma, "nu": self.nu,
                "period": 1.0 / self.frequency}
