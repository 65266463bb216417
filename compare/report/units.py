"""Quantities as a reader of the report wants them: SI first, with g and Hz beside,
and errors printed only to the resolution they were measured with.

An engine threshold is a bracket (it survives at one end and overturns at the
other, a relative width ``rel_tol``, 0.2 % by default) compared against the
model's own bracket (``tol``, 0.01 m/s^2).  A relative error smaller than the
bracket is not a number but "within the bracket", and a larger one carries
one decimal of a percent, the bracket's order.
"""
from __future__ import annotations

import math

__all__ = ["G", "TWO_PI", "accel", "freq", "rel_error", "resolution_pct", "period",
           "g_hz_axes"]

G = 9.80665  # m/s^2: standard gravity, the unit of "g" beside an acceleration
TWO_PI = 2.0 * math.pi  # rad per cycle: Hz beside an angular frequency


def _finite(x) -> bool:
    return x is not None and not isinstance(x, bool) and math.isfinite(float(x))


def accel(a, digits: int = 3) -> str:
    """``"8.07 m/s² (0.82 g)"``; "n/a" when ``a`` is None or not finite."""
    if not _finite(a):
        return "n/a"
    return f"{a:.{digits}g} m/s² ({a / G:.2g} g)"


def freq(omega, digits: int = 3) -> str:
    """``"12 rad/s (1.91 Hz)"`` for an angular frequency [rad/s]."""
    if not _finite(omega):
        return "n/a"
    return f"{omega:.{digits}g} rad/s ({omega / (2 * math.pi):.3g} Hz)"


def period(omega) -> str:
    """The pulse period ``2 pi / Omega`` [s] of a one-sine or one-cosine pulse."""
    if not _finite(omega) or omega <= 0:
        return "n/a"
    return f"{2 * math.pi / omega:.3g} s"


def resolution_pct(rel_tol) -> str:
    """A bracket's relative width as ``"0.2 %"``."""
    return "n/a" if not _finite(rel_tol) else f"{100 * rel_tol:.2g} %"


def rel_error(err, rel_tol=None) -> str:
    """A relative error at its resolution: ``"+3.4 %"``, or ``"|e| ≤ 0.2 %"``
    when it is no larger than the bracket ``rel_tol`` (then its sign and digits
    say nothing: both thresholds are ends of brackets); ``"not bracketed"``
    for None."""
    if not _finite(err):
        return "not bracketed"
    if _finite(rel_tol) and abs(err) <= rel_tol * (1 + 1e-9):
        return f"|e| ≤ {resolution_pct(rel_tol)}"
    return f"{100 * err:+.1f} %"


def g_hz_axes(ax, g: bool = True, hz: bool = True, hz_label: str = "f = Ω/2π [Hz]"):
    """The twin axes of a plot of an acceleration [m/s^2] against an angular
    frequency [rad/s]: g on the right, Hz on top (the same data, other units).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Its y axis in m/s^2 (with ``g``), its x axis in rad/s (with ``hz``).
    g, hz : bool
        Which twin axes to add.
    hz_label : str
        The top axis's label.

    Returns
    -------
    tuple
        ``(g_axis, hz_axis)``, each None when not asked for.
    """
    g_axis = hz_axis = None
    if g:
        g_axis = ax.secondary_yaxis("right", functions=(lambda a: a / G, lambda a: a * G))
        g_axis.set_ylabel("[g]")
    if hz:
        hz_axis = ax.secondary_xaxis("top", functions=(lambda w: w / TWO_PI,
                                                       lambda f: f * TWO_PI))
        hz_axis.set_xlabel(hz_label)
    return g_axis, hz_axis
