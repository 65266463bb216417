"""Base excitations: one-sine (Eq. 22), one-cosine (Eq. 23) pulses and sampled records.

Every excitation gives the ground acceleration ``xg_ddot(t)`` [m/s^2] and its
integrals (for the moving-ground option of the engines), and ``end_time``: after
it the ground is still (``xg_ddot = 0``), which lets a run stop as soon as its
verdict is decided.

Eq. 22 as printed reads ``0 <= t <= T_s`` on both branches (OCR); the intended
form is ``A sin(Omega t)`` for ``0 <= t <= T_s`` and ``0`` for ``t > T_s``, with
``T_s = 2 pi / Omega`` (one full cycle).  The same holds for Eq. 23.
A negative amplitude mirrors the pulse (the response mirrors too).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Pulse", "SampledRecord", "Still", "Excitation", "PULSE_KINDS"]

PULSE_KINDS = ("sine", "cosine")


@dataclass(frozen=True)
class Pulse:
    """One full cycle of ``A sin(Omega t)`` (``kind='sine'``, Eq. 22) or
    ``A cos(Omega t)`` (``kind='cosine'``, Eq. 23).

    Parameters
    ----------
    amplitude : float
        ``A_s`` [m/s^2], finite, ``|A| <= 1e4``.  Negative mirrors the pulse.
    omega : float
        Circular frequency ``Omega`` [rad/s], in (0, 1e4].
    kind : {'sine', 'cosine'}
    """

    amplitude: float
    omega: float
    kind: str = "sine"

    def __post_init__(self) -> None:
        if self.kind not in PULSE_KINDS:
            raise ValueError(f"pulse kind must be one of {PULSE_KINDS}, got {self.kind!r}")
        a = float(self.amplitude)
        w = float(self.omega)
        if not math.isfinite(a) or abs(a) > 1e4:
            raise ValueError(f"amplitude must be finite with |A| <= 1e4 m/s^2, got {self.amplitude!r}")
        if not math.isfinite(w) or not (0.0 < w <= 1e4):
            raise ValueError(f"omega must be in (0, 1e4] rad/s, got {self.omega!r}")
        object.__setattr__(self, "amplitude", a)
        object.__setattr__(self, "omega", w)

    @property
    def period(self) -> float:
        """``T_s = 2 pi / Omega`` [s]."""
        return 2.0 * math.pi / self.omega

    @property
    def end_time(self) -> float:
        return self.period

    @property
    def is_cosine(self) -> bool:
        return self.kind == "cosine"

    def acceleration(self, t: float) -> float:
        """Ground acceleration ``xg_ddot(t)`` [m/s^2]."""
        if t < 0.0 or t > self.period:
            return 0.0
        arg = self.omega * t
        return self.amplitude * (math.cos(arg) if self.is_cosine else math.sin(arg))

    def acceleration_array(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        arg = self.omega * t
        wave = np.cos(arg) if self.is_cosine else np.sin(arg)
        return np.where((t >= 0.0) & (t <= self.period), self.amplitude * wave, 0.0)

    def velocity(self, t: float) -> float:
        """Ground velocity [m/s], zero at ``t = 0``."""
        tc = min(max(t, 0.0), self.period)
        a, w = self.amplitude, self.omega
        if self.is_cosine:
            return a / w * math.sin(w * tc)
        return a / w * (1.0 - math.cos(w * tc))

    def displacement(self, t: float) -> float:
        """Ground displacement [m], zero at ``t = 0``; drifts at constant speed
        (zero for both pulses) after the pulse."""
        tc = min(max(t, 0.0), self.period)
        a, w = self.amplitude, self.omega
        if self.is_cosine:
            x = a / w ** 2 * (1.0 - math.cos(w * tc))
        else:
            x = a / w * (tc - math.sin(w * tc) / w)
        return x + self.velocity(self.period) * max(t - self.period, 0.0)

    def mirrored(self) -> "Pulse":
        return Pulse(-self.amplitude, self.omega, self.kind)

    def describe(self) -> dict:
        return {"type": "pulse", "kind": self.kind, "amplitude": self.amplitude,
                "omega": self.omega, "period": self.period}


@dataclass(frozen=True)
class SampledRecord:
    """A sampled ground-acceleration record, linearly interpolated, zero outside.

    Parameters
    ----------
    times : tuple of float
        Strictly increasing sample times [s], first >= 0, at least two.
    accelerations : tuple of float
        Ground accelerations at ``times`` [m/s^2], finite.
    """

    times: tuple
    accelerations: tuple
    label: str = "record"

    def __post_init__(self) -> None:
        t = np.asarray(self.times, dtype=float)
        a = np.asarray(self.accelerations, dtype=float)
        if t.ndim != 1 or t.size < 2 or t.shape != a.shape:
            raise ValueError("record needs matching 1-D times and accelerations with >= 2 samples")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
            raise ValueError("record times and accelerations must be finite")
        if t[0] < 0.0 or np.any(np.diff(t) <= 0.0):
            raise ValueError("record times must start at >= 0 s and increase strictly")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "accelerations", tuple(a.tolist()))

    @property
    def end_time(self) -> float:
        return self.times[-1]

    def acceleration(self, t: float) -> float:
        if t < self.times[0] or t > self.times[-1]:
            return 0.0
        return float(np.interp(t, self.times, self.accelerations))

    def acceleration_array(self, t: np.ndarray) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self.times, self.accelerations,
                         left=0.0, right=0.0)

    def _cumulative(self):
        t = np.asarray(self.times)
        a = np.asarray(self.accelerations)
        v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        return t, v, x

    def velocity(self, t: float) -> float:
        tt, v, _ = self._cumulative()
        return float(np.interp(t, tt, v, left=0.0, right=v[-1]))

    def displacement(self, t: float) -> float:
        tt, v, x = self._cumulative()
        if t > tt[-1]:
            return float(x[-1] + v[-1] * (t - tt[-1]))
        return float(np.interp(t, tt, x, left=0.0))

    def mirrored(self) -> "SampledRecord":
        return SampledRecord(self.times, tuple(-a for a in self.accelerations), self.label)

    def describe(self) -> dict:
        return {"type": "record", "label": self.label, "n_samples": len(self.times),
                "end_time": self.end_time,
                "peak": float(np.max(np.abs(self.accelerations)))}


@dataclass(frozen=True)
class Still:
    """No base motion: for free rocking released from a tilt (restitution runs)."""

    @property
    def end_time(self) -> float:
        return 0.0

    def acceleration(self, t: float) -> float:
        return 0.0

    def acceleration_array(self, t: np.ndarray) -> np.ndarray:
        return np.zeros_like(np.asarray(t, dtype=float))

    def velocity(self, t: float) -> float:
        return 0.0

    def displacement(self, t: float) -> float:
        return 0.0

    def mirrored(self) -> "Still":
        return self

    def describe(self) -> dict:
        return {"type": "still"}


Excitation = Pulse | SampledRecord | Still
