"""Near-fault pulses beside the one-sine and one-cosine (Eqs. 22-23): Ricker
wavelets and the Mavroeidis-Papageorgiou pulse.

Every ground motion of the project (:class:`~analytic.excitation.Pulse`, the
classes here, :class:`~analytic.excitation.SampledRecord`) offers the same
members: ``acceleration(t)`` [m/s^2], ``acceleration_array``, ``velocity`` [m/s]
and ``displacement`` [m] (both zero at ``t = 0``), ``end_time`` [s] (the ground
is still after it), ``pga`` [m/s^2], ``pgv`` [m/s], ``scaled(factor)``,
``mirrored()`` and ``describe()``; the pulses also give ``peak_times`` (the
extrema of ``|xg_ddot|``, where the uplift margin is smallest).

Ricker wavelets (as used for rocking by Vassiliou and Makris), with
``tau = pi (t - t_c) / T_p``:

* symmetric: ``a(t) = A (1 - 2 tau^2) exp(-tau^2)`` (the "Mexican hat"; its
  Fourier amplitude peaks at ``f_p = 1/T_p``);
* antisymmetric: the time derivative of the symmetric wavelet scaled to the peak
  ``A``: ``a(t) = A (6 tau - 4 tau^3) exp(-tau^2) / kappa``, ``kappa`` its largest
  value (at ``tau^2 = (3 - sqrt 6)/2``).

Both are truncated at ``|tau| = 5`` (``exp(-25)``: the jump at the ends is below
1e-9 A); the centre is ``t_c = 5 T_p / pi``, so the wavelet starts at ``t = 0``.
Both have zero net velocity and displacement (exact for the untruncated
wavelet: the velocity is ``A T_p/pi tau exp(-tau^2)`` for the symmetric one).

Mavroeidis and Papageorgiou (2003), velocity with ``tau = t - t_0``,
``t_0 = gamma / (2 f_p)`` (the pulse starts at ``t = 0``)::

    v(t) = A/2 [1 + cos(2 pi f_p tau / gamma)] cos(2 pi f_p tau + nu),
           |tau| <= gamma / (2 f_p),   0 elsewhere.

Its acceleration is the derivative, its displacement the closed-form integral;
the velocity is zero at both ends (zero net velocity), the net displacement is
not zero in general (it depends on ``nu``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .excitation import MAX_ACCELERATION, MAX_PULSE_LENGTH, _positive_factor, _real

__all__ = ["Ricker", "MavroeidisPapageorgiou", "RICKER_KINDS", "RICKER_TAU_MAX", "PULSE_FAMILY",
           "PulseShape", "pulse_of", "MP_GAMMA_RANGE", "MP_NU_LIMIT"]

RICKER_KINDS = ("symmetric", "antisymmetric")
RICKER_TAU_MAX = 5.0  # half-width of the truncated wavelet in tau
# Largest value of (6 tau - 4 tau^3) exp(-tau^2), at tau^2 = (3 - sqrt 6) / 2.
_TAU_ANTI = math.sqrt((3.0 - math.sqrt(6.0)) / 2.0)
_KAPPA = (6.0 * _TAU_ANTI - 4.0 * _TAU_ANTI ** 3) * math.exp(-_TAU_ANTI ** 2)
# Shortest pulse period [s] (as Pulse: Omega <= 1e4 rad/s).
MIN_PERIOD = 2.0 * math.pi / 1e4
# Every pulse shape one frequency and one peak acceleration define (PulseShape).
PULSE_FAMILY = ("sine", "cosine", "ricker", "ricker-anti", "mp")
MP_GAMMA_RANGE = (1.0, 20.0)  # open below: gamma = 1 makes the envelope one carrier cycle
MP_NU_LIMIT = 2.0 * math.pi   # |nu| <= 2 pi rad


def _check_amplitude(name: str, value, limit: float, unit: str) -> float:
    x = _real(name, value)
    if not math.isfinite(x) or abs(x) > limit:
        raise ValueError(f"{name} must be finite with |{name}| <= {limit:.4g} {unit}, got {value!r}")
    return x


@dataclass(frozen=True)
class Ricker:
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


@dataclass(frozen=True)
class MavroeidisPapageorgiou:
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


@dataclass(frozen=True)
class PulseShape:
    """A pulse shape of :data:`PULSE_FAMILY`, placed at a peak ground acceleration
    and a frequency by :meth:`at`: what a spectrum or a map scans.

    Parameters
    ----------
    kind : {'sine', 'cosine', 'ricker', 'ricker-anti', 'mp'}
        One-sine (Eq. 22), one-cosine (Eq. 23), symmetric or antisymmetric
        Ricker wavelet, Mavroeidis-Papageorgiou pulse (module docstring).
    gamma : float, default 2
        M-P oscillatory character, in (1, 20] (only for ``'mp'``).
    nu : float, default 0
        M-P phase [rad], in [-2 pi, 2 pi] (only for ``'mp'``).

    Notes
    -----
    ``at(A, Omega)`` gives every shape the same two meanings: ``|A|`` is its peak
    ground acceleration [m/s^2] (a negative ``A`` mirrors it) and ``Omega``
    [rad/s] its frequency: the pulse's ``2 pi / T_s`` for sine and cosine, the
    Ricker wavelet's ``2 pi / T_p`` (``T_p = 1/f_p``, its Fourier peak), the M-P
    prevailing ``2 pi f_p``.  So spectra and maps of different shapes share
    their axes.  The M-P velocity amplitude follows from the peak: ``A``
    divided by the PGA of the unit pulse of that ``f_p``, ``gamma``, ``nu``.
    """

    kind: str = "sine"
    gamma: float = 2.0
    nu: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in PULSE_FAMILY:
            raise ValueError(f"pulse kind must be one of {', '.join(PULSE_FAMILY)}, "
                             f"got {self.kind!r}")
        gm, nu = _real("gamma", self.gamma), _real("nu", self.nu)
        if not (math.isfinite(gm) and MP_GAMMA_RANGE[0] < gm <= MP_GAMMA_RANGE[1]):
            raise ValueError(f"gamma must be in ({MP_GAMMA_RANGE[0]:g}, {MP_GAMMA_RANGE[1]:g}], "
                             f"got {self.gamma!r}")
        if not (math.isfinite(nu) and abs(nu) <= MP_NU_LIMIT):
            raise ValueError(f"nu must be in [-2 pi, 2 pi] rad, got {self.nu!r}")
        if self.kind != "mp" and (gm, nu) != (2.0, 0.0):
            raise ValueError(f"gamma and nu shape the 'mp' pulse only, not {self.kind!r}")
        object.__setattr__(self, "gamma", gm)
        object.__setattr__(self, "nu", nu)

    def at(self, amplitude: float, omega: float):
        """The pulse of peak acceleration ``|amplitude|`` [m/s^2] at ``omega`` [rad/s]."""
        from .excitation import OMEGA_RANGE, Pulse
        a = _check_amplitude("amplitude", amplitude, MAX_ACCELERATION, "m/s^2")
        w = _real("omega", omega)
        if not (math.isfinite(w) and OMEGA_RANGE[0] <= w <= OMEGA_RANGE[1]):
            raise ValueError(f"omega must be in [{OMEGA_RANGE[0]:g}, {OMEGA_RANGE[1]:g}] rad/s, "
                             f"got {omega!r}")
        if self.kind in ("sine", "cosine"):
            return Pulse(a, w, self.kind)
        if self.kind.startswith("ricker"):
            kind = "symmetric" if self.kind == "ricker" else "antisymmetric"
            return Ricker(a, 2.0 * math.pi / w, kind)
        fp = w / (2.0 * math.pi)
        unit = _mp_unit_pga(fp, self.gamma, self.nu)
        return MavroeidisPapageorgiou(a / unit, fp, self.gamma, self.nu)

    def describe(self) -> dict:
        out = {"kind": self.kind}
        if self.kind == "mp":
            out.update(gamma=self.gamma, nu=self.nu)
        return out

    def __str__(self) -> str:
        return (self.kind if self.kind != "mp" else
                f"mp (gamma {self.gamma:g}, nu {self.nu:g} rad)")


def _mp_unit_pga(frequency: float, gamma: float, nu: float) -> float:
    """PGA [m/s^2] of the M-P pulse of unit velocity amplitude.  The pulse is
    linear in its amplitude, so this scales it to any peak; the amplitude at
    which it is probed keeps it inside the pulse's own bounds."""
    probe = min(1.0, 0.5 * MAX_ACCELERATION / (math.pi * frequency * (1.0 / gamma + 2.0)))
    return MavroeidisPapageorgiou(probe, frequency, gamma, nu).pga / probe


def pulse_of(kind, amplitude: float, omega: float):
    """``PulseShape(kind).at(amplitude, omega)``; ``kind`` a name of
    :data:`PULSE_FAMILY` or a :class:`PulseShape`."""
    shape = kind if isinstance(kind, PulseShape) else PulseShape(kind)
    return shape.at(amplitude, omega)
