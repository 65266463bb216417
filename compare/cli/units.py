"""Engineering units at the door and in outputs.

Accepted on the command line (the one place that reads them):

* accelerations: a number in m/s^2, or with a ``g`` suffix (``0.5g``, ``0.5 g``)
  in standard gravity 9.80665 m/s^2;
* frequencies: a number in rad/s, or with an ``Hz`` suffix (``2Hz``) as
  ``Omega = 2 pi f``; a pulse period ``T`` [s] is ``--period`` (``Omega = 2 pi / T``);
* velocities: a number in m/s, or with ``cm/s``.

Shown to a person: SI first, g / Hz and the period beside (``4.9 m/s^2 (0.5 g)``,
``12.57 rad/s (2 Hz, T = 0.5 s)``).  Every parse error is a ``ValueError`` naming
the option, the text and the accepted forms.
"""
from __future__ import annotations

import math
import re

from trilith_xval.analytic.excitation import G_STANDARD

__all__ = ["parse_acceleration", "parse_frequency", "parse_period", "parse_velocity",
           "acceleration_text", "frequency_text", "velocity_text"]

_NUMBER = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"


def _split(text, option: str, units: dict[str, float], forms: str) -> float:
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        match = re.fullmatch(_NUMBER + r"\s*([A-Za-z/^0-9]*)", str(text).strip())
        unit = match.group(2) if match else None
        if match is None or unit not in units:
            raise ValueError(f"{option}: {text!r} is not {forms}")
        value = float(match.group(1)) * units[unit]
    if not math.isfinite(value):
        raise ValueError(f"{option}: must be finite, got {text!r}")
    return value


def parse_acceleration(text, option: str) -> float:
    """``'0.5g'`` -> 4.903325, ``'3'`` / ``'3 m/s^2'`` -> 3.0 [m/s^2]."""
    return _split(text, option, {"": 1.0, "m/s^2": 1.0, "m/s2": 1.0, "g": G_STANDARD},
                  "an acceleration (m/s^2, or with a g suffix: 0.5g)")


def parse_frequency(text, option: str) -> float:
    """``'2Hz'`` -> 4 pi, ``'11'`` / ``'11 rad/s'`` -> 11.0 [rad/s]."""
    return _split(text, option, {"": 1.0, "rad/s": 1.0, "Hz": 2.0 * math.pi,
                                 "hz": 2.0 * math.pi},
                  "a frequency (rad/s, or with an Hz suffix: 2Hz)")


def parse_period(text, option: str) -> float:
    """A pulse period [s] (``'0.5'`` or ``'0.5s'``) as ``Omega = 2 pi / T`` [rad/s]."""
    t = _split(text, option, {"": 1.0, "s": 1.0}, "a period in seconds (0.5 or 0.5s)")
    if t <= 0.0:
        raise ValueError(f"{option}: the period must be > 0 s, got {text!r}")
    return 2.0 * math.pi / t


def parse_velocity(text, option: str) -> float:
    """``'25cm/s'`` -> 0.25, ``'0.3'`` -> 0.3 [m/s]."""
    return _split(text, option, {"": 1.0, "m/s": 1.0, "cm/s": 0.01},
                  "a velocity (m/s, or with cm/s: 25cm/s)")


def acceleration_text(a: float) -> str:
    """``'4.903 m/s^2 (0.5 g)'``."""
    return f"{a:.4g} m/s^2 ({a / G_STANDARD:.3g} g)"


def frequency_text(omega: float) -> str:
    """``'12.57 rad/s (2 Hz, T = 0.5 s)'``."""
    return f"{omega:.4g} rad/s ({omega / (2.0 * math.pi):.4g} Hz, T = {2.0 * math.pi / omega:.4g} s)"


def velocity_text(v: float) -> str:
    """``'0.25 m/s (25 cm/s)'``."""
    return f"{v:.4g} m/s ({100.0 * v:.3g} cm/s)"
