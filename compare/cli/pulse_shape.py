"""The pulse family at the door: ``--pulse sine|cosine|ricker|ricker-anti|mp`` and
the Mavroeidis-Papageorgiou shape (``--mp-gamma``, ``--mp-nu``), read once into an
:class:`analytic.pulses.PulseShape` for every command that takes a pulse.

Every shape keeps the meaning of ``-A`` (its peak ground acceleration, m/s^2 or
``0.5g``) and of ``-w`` / ``--period`` (its frequency: the pulse's period for
sine and cosine, the Ricker ``T_p = 1/f_p``, the M-P prevailing period
``1/f_p``), so a spectrum or a map of any shape has the same axes.
"""
from __future__ import annotations

import argparse
import math

from trilith_xval.analytic.pulses import MP_GAMMA_RANGE, PULSE_FAMILY, PulseShape

__all__ = ["add_pulse_shape_args", "shape_from_args", "PULSE_HELP"]

PULSE_HELP = ("pulse shape: one-sine (Eq. 22), one-cosine (Eq. 23), symmetric or "
              "antisymmetric Ricker wavelet, Mavroeidis-Papageorgiou (mp); -A is its peak "
              "ground acceleration, -w/--period its frequency (Ricker: T_p = 1/f_p; mp: 1/f_p)")


def add_pulse_shape_args(parser: argparse.ArgumentParser) -> None:
    """``--pulse`` (every shape of :data:`analytic.pulses.PULSE_FAMILY`) and the M-P
    parameters."""
    parser.add_argument("--pulse", choices=PULSE_FAMILY, default="sine", help=PULSE_HELP)
    parser.add_argument("--mp-gamma", default=None, metavar="G",
                        help=f"mp: oscillatory character gamma, in ({MP_GAMMA_RANGE[0]:g}, "
                             f"{MP_GAMMA_RANGE[1]:g}] (default 2; near-fault records fit "
                             "1.5-3)")
    parser.add_argument("--mp-nu", default=None, metavar="RAD",
                        help="mp: phase nu [rad], in [-2 pi, 2 pi] (default 0: a symmetric "
                             "velocity pulse)")


def _number(text, option: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ValueError(f"{option}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{option} must be finite, got {text!r}")
    return value


def shape_from_args(args: argparse.Namespace) -> PulseShape:
    """The checked :class:`PulseShape` of ``--pulse``, ``--mp-gamma``, ``--mp-nu``;
    ``ValueError`` naming the option (the M-P options with another pulse too)."""
    kind = getattr(args, "pulse", "sine")
    given = {name: value for name, value in (("--mp-gamma", getattr(args, "mp_gamma", None)),
                                             ("--mp-nu", getattr(args, "mp_nu", None)))
             if value is not None}
    if kind != "mp":
        if given:
            raise ValueError(f"{' and '.join(given)}: only for --pulse mp (got --pulse "
                             f"{kind})")
        return PulseShape(kind)
    gamma = _number(given["--mp-gamma"], "--mp-gamma") if "--mp-gamma" in given else 2.0
    nu = _number(given["--mp-nu"], "--mp-nu") if "--mp-nu" in given else 0.0
    if not MP_GAMMA_RANGE[0] < gamma <= MP_GAMMA_RANGE[1]:
        raise ValueError(f"--mp-gamma must be in ({MP_GAMMA_RANGE[0]:g}, "
                         f"{MP_GAMMA_RANGE[1]:g}], got {given['--mp-gamma']!r}")
    if abs(nu) > 2.0 * math.pi:
        raise ValueError(f"--mp-nu must be in [-2 pi, 2 pi] rad ([-6.283, 6.283]), got "
                         f"{given['--mp-nu']!r}")
    return PulseShape("mp", gamma, nu)


def shaped_pulse(shape: PulseShape, amplitude: float, omega: float, option: str,
                 amplitude_option: str = "-A/--amplitude"):
    """``shape.at(amplitude, omega)``: ``|amplitude| <= 1e4 m/s^2`` named with
    ``amplitude_option``, then a shape's own bound on the frequency (a Ricker
    period of at most 19.7 s, an M-P pulse of at most 62.8 s) with ``option``."""
    from trilith_xval.analytic.excitation import MAX_ACCELERATION
    if not (math.isfinite(amplitude) and abs(amplitude) <= MAX_ACCELERATION):
        raise ValueError(f"{amplitude_option} must be finite with |A| <= "
                         f"{MAX_ACCELERATION:g} m/s^2, got {amplitude!r}")
    if shape.kind in ("sine", "cosine"):  # Pulse's own message names omega
        return shape.at(amplitude, omega)
    try:
        return shape.at(amplitude, omega)
    except ValueError as exc:
        raise ValueError(f"{option}: the {shape} pulse at Omega = {omega:g} rad/s: "
                         f"{exc}") from None
