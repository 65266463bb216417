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
import numbers
from dataclasses import dataclass

import numpy as np

__all__ = ["Pulse", "SampledRecord", "Still", "Excitation", "PULSE_KINDS", "OMEGA_RANGE",
           "MAX_PULSE_LENGTH", "MAX_RECORD_LENGTH", "MAX_RECORD_SAMPLES"]

PULSE_KINDS = ("sine", "cosine")
# Pulse frequencies [rad/s]: the upper bound is the former one; the lower bound
# caps a pulse's length (and so a run's) at 2 pi / 0.1 = 62.8 s.
OMEGA_RANGE = (0.1, 1e4)
MAX_PULSE_LENGTH = 2.0 * math.pi / OMEGA_RANGE[0]
# A recorded ground motion: long strong-motion records last a few minutes.
MAX_RECORD_LENGTH = 600.0  # s
MAX_RECORD_SAMPLES = 1_000_000


def _real(name: str, value) -> float:
    """``value`` as a float, ``TypeError`` naming ``name`` for non-numbers
    (``None``, ``str``; ``bool`` too: ``True`` is no amplitude)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r} "
                        f"({type(value).__name__})")
    return float(value)


@dataclass(frozen=True)
class Pulse:
    """One full cycle of ``A sin(Omega t)`` (``kind='sine'``, Eq. 22) or
    ``A cos(Omega t)`` (``kind='cosine'``, Eq. 23).

    Parameters
    ----------
    amplitude : float
        ``A_s`` [m/s^2], finite, ``|A| <= 1e4``.  Negative mirrors the pulse.
    omega : float
        Circular frequency ``Omega`` [rad/s], in [0.1, 1e4]: the pulse lasts
        ``2 pi / Omega`` <= 62.8 s (``MAX_PULSE_LENGTH``), so a run's length and
        step count stay bounded (earthquake pulses last 0.1-10 s).
    kind : {'sine', 'cosine'}

    Raises
    ------
    TypeError
        ``amplitude`` or ``omega`` not a real number (str, bool, None), ``kind``
        not a str.
    ValueError
        A value out of its range, naming the parameter.

    Examples
    --------
    >>> round(Pulse(25.0, 11.0).period, 4)
    0.5712
    """

    amplitude: float
    omega: float
    kind: str = "sine"

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str):
            raise TypeError(f"kind must be a str in {PULSE_KINDS}, got {self.kind!r}")
        if self.kind not in PULSE_KINDS:
            raise ValueError(f"pulse kind must be one of {PULSE_KINDS}, got {self.kind!r}")
        a = _real("amplitude", self.amplitude)
        w = _real("omega", self.omega)
        if not math.isfinite(a) or abs(a) > 1e4:
            raise ValueError(f"amplitude must be finite with |A| <= 1e4 m/s^2, got {self.amplitude!r}")
        if not math.isfinite(w) or not (OMEGA_RANGE[0] <= w <= OMEGA_RANGE[1]):
            raise ValueError(f"omega must be in [{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}] rad/s "
                             f"(pulse length 2 pi/omega <= {MAX_PULSE_LENGTH:.1f} s), "
                             f"got {self.omega!r}")
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
        Strictly increasing sample times [s], first >= 0, at least two, the
        last <= 600 s (``MAX_RECORD_LENGTH``), at most 1e6 samples.
    accelerations : tuple of float
        Ground accelerations at ``times`` [m/s^2], finite, ``|a| <= 1e4``.
    label : str
        A name carried into reports (``scenes.load_record`` uses the file name).
    """

    times: tuple
    accelerations: tuple
    label: str = "record"

    def __post_init__(self) -> None:
        if not isinstance(self.label, str):
            raise TypeError(f"label must be a str, got {self.label!r}")
        try:
            t = np.asarray(self.times, dtype=float)
            a = np.asarray(self.accelerations, dtype=float)
        except (TypeError, ValueError):
            raise TypeError("times and accelerations must be sequences of real numbers") from None
        if t.ndim != 1 or t.size < 2 or t.shape != a.shape:
            raise ValueError("record needs matching 1-D times and accelerations with >= 2 samples")
        if t.size > MAX_RECORD_SAMPLES:
            raise ValueError(f"record has {t.size} samples; at most {MAX_RECORD_SAMPLES}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
            raise ValueError("record times and accelerations must be finite")
        if t[0] < 0.0 or np.any(np.diff(t) <= 0.0):
            raise ValueError("record times must start at >= 0 s and increase strictly")
        if t[-1] > MAX_RECORD_LENGTH:
            raise ValueError(f"record lasts {t[-1]:.6g} s; at most {MAX_RECORD_LENGTH:g} s")
        if np.max(np.abs(a)) > 1e4:
            raise ValueError("record accelerations must satisfy |a| <= 1e4 m/s^2 (as a pulse's)")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "accelerations", tuple(a.tolist()))
        # Arrays kept once: np.interp on the tuples would convert them at every
        # call (O(n) per engine step).  Not fields: equality stays on the tuples.
        v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        for name, arr in (("_t", t), ("_a", a), ("_v", v), ("_x", x)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def end_time(self) -> float:
        return self.times[-1]

    def acceleration(self, t: float) -> float:
        if t < self.times[0] or t > self.times[-1]:
            return 0.0
        return float(np.interp(t, self._t, self._a))

    def acceleration_array(self, t: np.ndarray) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self._t, self._a, left=0.0, right=0.0)

    def velocity(self, t: float) -> float:
        return float(np.interp(t, self._t, self._v, left=0.0, right=self._v[-1]))

    def displacement(self, t: float) -> float:
        if t > self._t[-1]:
            return float(self._x[-1] + self._v[-1] * (t - self._t[-1]))
        return float(np.interp(t, self._t, self._x, left=0.0))

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
