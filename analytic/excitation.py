"""Base excitations: one-sine (Eq. 22), one-cosine (Eq. 23) pulses and sampled records.

Every excitation meets the contract of :class:`Excitation`
(:mod:`analytic.excitation_contract`, re-exported here): it gives the ground
acceleration ``xg_ddot(t)`` [m/s^2] and its integrals (for the moving-ground
option of the engines), and ``end_time``: after it the ground is still
(``xg_ddot = 0``), which lets a run stop as soon as its verdict is decided.

Eq. 22 as printed reads ``0 <= t <= T_s`` on both branches (OCR); the intended
form is ``A sin(Omega t)`` for ``0 <= t <= T_s`` and ``0`` for ``t > T_s``, with
``T_s = 2 pi / Omega`` (one full cycle).  The same holds for Eq. 23.
A negative amplitude mirrors the pulse (the response mirrors too).
"""
from __future__ import annotations

import bisect
import math
import numbers
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .excitation_contract import (COMPILED_KINDS, PULSE_KINDS, CompiledForm, Excitation,
                                  check_excitation, check_excitation_contract)

__all__ = ["Pulse", "SampledRecord", "Still", "Excitation", "CompiledForm", "check_excitation",
           "check_excitation_contract", "PULSE_KINDS", "COMPILED_KINDS", "OMEGA_RANGE", "MAX_PULSE_LENGTH",
           "MAX_RECORD_LENGTH", "MAX_RECORD_SAMPLES", "G_STANDARD", "MAX_ACCELERATION"]

# Pulse frequencies [rad/s]: the upper bound is the former one; the lower bound
# caps a pulse's length (and so a run's) at 2 pi / 0.1 = 62.8 s.
OMEGA_RANGE = (0.1, 1e4)
MAX_PULSE_LENGTH = 2.0 * math.pi / OMEGA_RANGE[0]
# A recorded ground motion: long strong-motion records last a few minutes.
MAX_RECORD_LENGTH = 600.0  # s
MAX_RECORD_SAMPLES = 1_000_000
G_STANDARD = 9.80665  # m/s^2: the g of "0.5 g" and of PEER files
MAX_ACCELERATION = 1e4  # m/s^2 (about 1000 g): any pulse or record sample
# Samples converted to Python lists at a time by SampledRecord.interpolant: a
# segment of the integrator reads a few of them, so the cost per segment stays
# bounded whatever the record's length.
_CHUNK = 256


def _real(name: str, value) -> float:
    """``value`` as a float, ``TypeError`` naming ``name`` for non-numbers
    (``None``, ``str``; ``bool`` too: ``True`` is no amplitude)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r} "
                        f"({type(value).__name__})")
    return float(value)


def _positive_factor(factor) -> float:
    """A scale factor: real, finite, > 0 (a mirror is ``mirrored()``)."""
    f = _real("factor", factor)
    if not (math.isfinite(f) and f > 0.0):
        raise ValueError(f"scale factor must be finite and > 0, got {factor!r}")
    return f


def _check_amplitude(name: str, value, limit: float, unit: str) -> float:
    x = _real(name, value)
    if not math.isfinite(x) or abs(x) > limit:
        raise ValueError(f"{name} must be finite with |{name}| <= {limit:.4g} {unit}, got {value!r}")
    return x


@dataclass(frozen=True)
class Pulse(Excitation):
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
    type_name = "pulse"

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

    def acceleration_bound(self) -> float:
        return abs(self.amplitude)

    def velocity_bound(self) -> float:
        """``2 |A| / Omega``: the integral of one sine or cosine lobe bounds it."""
        return 2.0 * abs(self.amplitude) / self.omega

    def compiled_form(self) -> CompiledForm:
        """The kernels of :mod:`analytic.fast` integrate Eq. 22/23 themselves."""
        return CompiledForm(self.kind, self.amplitude, self.omega)

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

    @property
    def peak_times(self) -> tuple[float, ...]:
        """Instants of the extrema of ``|xg_ddot|`` [s] (where an uplift margin is
        smallest): the quarter periods of the sine, the half period of the cosine."""
        quarter = 0.25 * self.period
        return (quarter, 3.0 * quarter) if self.kind == "sine" else (2.0 * quarter,)

    @property
    def pga(self) -> float:
        """Peak ground acceleration ``|A|`` [m/s^2]."""
        return abs(self.amplitude)

    @property
    def pgv(self) -> float:
        """Peak ground velocity [m/s]: ``2|A|/Omega`` (sine), ``|A|/Omega`` (cosine)."""
        return (1.0 if self.is_cosine else 2.0) * abs(self.amplitude) / self.omega

    def scaled(self, factor: float) -> "Pulse":
        """The pulse with its amplitude times ``factor`` (> 0)."""
        return Pulse(_positive_factor(factor) * self.amplitude, self.omega, self.kind)

    def mirrored(self) -> "Pulse":
        return Pulse(-self.amplitude, self.omega, self.kind)

    def describe(self) -> dict:
        return {"type": "pulse", "kind": self.kind, "amplitude": self.amplitude,
                "omega": self.omega, "period": self.period}


@dataclass(frozen=True)
class SampledRecord(Excitation):
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
    type_name = "record"

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
        if np.max(np.abs(a)) > MAX_ACCELERATION:
            raise ValueError("record accelerations must satisfy |a| <= 1e4 m/s^2 (as a pulse's)")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "accelerations", tuple(a.tolist()))
        # Arrays kept once: np.interp on the tuples would convert them at every
        # call (O(n) per engine step).  Not fields: equality stays on the tuples.
        # Left writeable: np.interp copies a read-only array at every call
        # (measured: 308 us per call at 4e4 samples against 1 us), which made
        # an engine's run quadratic in the record's length.
        v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        for name, arr in (("_t", t), ("_a", a), ("_v", v), ("_x", x)):
            object.__setattr__(self, name, arr)

    @property
    def end_time(self) -> float:
        return self.times[-1]

    @property
    def start_time(self) -> float:
        return self.times[0]

    @property
    def kink_times(self) -> np.ndarray:
        """The samples: linear interpolation has kinks there."""
        return np.asarray(self.times, dtype=float)

    def acceleration_bound(self) -> float:
        """Linear interpolation peaks at a sample."""
        return max(abs(a) for a in self.accelerations)

    @property
    def pga(self) -> float:
        """Peak ground acceleration ``max |a|`` [m/s^2]."""
        return float(np.max(np.abs(self._a)))

    @property
    def pgv(self) -> float:
        """Peak ground velocity ``max |v|`` [m/s] of the trapezoidal velocity
        (zero at the first sample; no baseline correction: the record as given)."""
        return float(np.max(np.abs(self._v)))

    def scaled(self, factor: float, label: str | None = None) -> "SampledRecord":
        """The record with every acceleration times ``factor`` (> 0, finite; a
        mirror is :meth:`mirrored`).  The result obeys the same bounds
        (``|a| <= 1e4 m/s^2``), ``ValueError`` naming the factor otherwise."""
        f = _positive_factor(factor)
        if f * self.pga > MAX_ACCELERATION:
            raise ValueError(f"scale factor {f:g} takes the record's PGA {self.pga:.4g} m/s^2 "
                             f"beyond {MAX_ACCELERATION:g} m/s^2; at most "
                             f"{MAX_ACCELERATION / self.pga:.4g}")
        return SampledRecord(self.times, tuple((f * self._a).tolist()),
                             self.label if label is None else label)

    def to_pga(self, target: float) -> "SampledRecord":
        """The record scaled to a peak ground acceleration ``target`` [m/s^2] (> 0)."""
        t = _real("target PGA", target)
        if not (math.isfinite(t) and 0.0 < t <= MAX_ACCELERATION):
            raise ValueError(f"target PGA must be in (0, {MAX_ACCELERATION:g}] m/s^2, got {target!r}")
        return self.scaled(t / self._nonzero("pga"))

    def to_pgv(self, target: float) -> "SampledRecord":
        """The record scaled to a peak ground velocity ``target`` [m/s] (> 0)."""
        t = _real("target PGV", target)
        if not (math.isfinite(t) and t > 0.0):
            raise ValueError(f"target PGV must be finite and > 0 m/s, got {target!r}")
        return self.scaled(t / self._nonzero("pgv"))

    def _nonzero(self, measure: str) -> float:
        value = getattr(self, measure)
        if value <= 0.0:
            raise ValueError(f"record {self.label!r} has {measure.upper()} = 0: it cannot be "
                             f"scaled to a target {measure.upper()}")
        return value

    def compiled_form(self) -> CompiledForm:
        """The kernels of :mod:`analytic.fast` integrate the same linear
        interpolation of the samples (:meth:`acceleration`), stopping at every
        sample (a kink of the interpolant)."""
        return CompiledForm("samples", 1.0, 0.0, self._t, self._a)

    def acceleration(self, t: float) -> float:
        if t < self.times[0] or t > self.times[-1]:
            return 0.0
        return float(np.interp(t, self._t, self._a))

    def acceleration_array(self, t: np.ndarray) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self._t, self._a, left=0.0, right=0.0)

    def interpolant(self, lo: float, hi: float) -> Callable[[float], float]:
        """``xg_ddot(t)`` with ``t`` clamped to ``[lo, hi]`` (inside the record), for
        an integrator's right-hand side.

        The same linear interpolation as :meth:`acceleration`, but on Python lists
        of at most 256 samples around the last query, rebuilt when a query leaves
        them: a scalar ``np.interp`` costs ~1 us per call, and converting the
        whole record per segment would cost O(n) per segment (O(n^2) per run).
        """
        t_all, a_all = self._t, self._a
        n = t_all.size
        chunk: list = [[], []]

        def xg(t: float) -> float:
            t = min(max(t, lo), hi)
            tt = chunk[0]
            if not tt or t < tt[0] or t > tt[-1]:
                i = int(np.searchsorted(t_all, t, side="right")) - 1
                i0 = max(min(i - 8, n - _CHUNK), 0)
                tt = chunk[0] = t_all[i0:i0 + _CHUNK].tolist()
                chunk[1] = a_all[i0:i0 + _CHUNK].tolist()
            aa = chunk[1]
            j = min(max(bisect.bisect_right(tt, t) - 1, 0), len(tt) - 2)
            w = (t - tt[j]) / (tt[j + 1] - tt[j])
            return aa[j] + w * (aa[j + 1] - aa[j])
        return xg

    def velocity(self, t: float) -> float:
        return float(np.interp(t, self._t, self._v, left=0.0, right=self._v[-1]))

    def displacement(self, t: float) -> float:
        if t > self._t[-1]:
            return float(self._x[-1] + self._v[-1] * (t - self._t[-1]))
        return float(np.interp(t, self._t, self._x, left=0.0))

    def mirrored(self) -> "SampledRecord":
        return SampledRecord(self.times, tuple((-self._a).tolist()), self.label)

    def describe(self) -> dict:
        return {"type": "record", "label": self.label, "n_samples": len(self.times),
                "end_time": self.end_time, "peak": self.pga, "pgv": self.pgv}


@dataclass(frozen=True)
class Still(Excitation):
    """No base motion: for free rocking released from a tilt (restitution runs)."""

    type_name = "still"

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

    def scaled(self, factor: float) -> "Still":
        """Still: no motion times ``factor`` (> 0) is no motion."""
        _positive_factor(factor)
        return self

    def mirrored(self) -> "Still":
        return self

    def describe(self) -> dict:
        return {"type": "still"}

