"""Near-fault pulses beside the one-sine and one-cosine (Eqs. 22-23): Ricker
wavelets (:mod:`analytic.ricker`) and the Mavroeidis-Papageorgiou pulse
(:mod:`analytic.mavroeidis_papageorgiou`), and the family of pulse shapes that a
spectrum or a map scans (:class:`PulseShape`).

Every ground motion of the project (:class:`~analytic.excitation.Pulse`, the
Ricker and M-P pulses, :class:`~analytic.excitation.SampledRecord`) derives from
:class:`~analytic.excitation.Excitation` and offers its members:
``acceleration(t)`` [m/s^2], ``acceleration_array``, ``velocity`` [m/s] and
``displacement`` [m] (both zero at ``t = 0``), ``end_time`` [s] (the ground is
still after it), ``pga`` [m/s^2], ``pgv`` [m/s], ``scaled(factor)`` and
``describe()``; the pulses also give ``mirrored()`` and ``peak_times`` (the
extrema of ``|xg_ddot|``, where the uplift margin is smallest).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .excitation import MAX_ACCELERATION, _check_amplitude, _real
from .mavroeidis_papageorgiou import MavroeidisPapageorgiou
from .ricker import RICKER_KINDS, RICKER_TAU_MAX, Ricker  # noqa: F401  (in __all__)

__all__ = ["Ricker", "MavroeidisPapageorgiou", "RICKER_KINDS", "RICKER_TAU_MAX", "PULSE_FAMILY",
           "PulseShape", "pulse_of", "MP_GAMMA_RANGE", "MP_NU_LIMIT"]

# Every pulse shape one frequency and one peak acceleration define (PulseShape).
PULSE_FAMILY = ("sine", "cosine", "ricker", "ricker-anti", "mp")
MP_GAMMA_RANGE = (1.0, 20.0)  # open below: gamma = 1 makes the envelope one carrier cycle
MP_NU_LIMIT = 2.0 * math.pi   # |nu| <= 2 pi rad


@dataclass(frozen=True)
class PulseShape:
    """A pulse shape of :data:`PULSE_FAMILY`, placed at a peak ground acceleration
    and a frequency by :meth:`at`: what a spectrum or a map scans.

    Parameters
    ----------
    kind : {'sine', 'cosine', 'ricker', 'ricker-anti', 'mp'}
        One-sine (Eq. 22), one-cosine (Eq. 23), symmetric or antisymmetric
        Ricker wavelet (:mod:`analytic.ricker`), Mavroeidis-Papageorgiou pulse
        (:mod:`analytic.mavroeidis_papageorgiou`).
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
