"""The paper's labelled cases on the Fig. 5 trilith, defined once.

Points A-D are the pulses of Figs. 6 and 7 (one-sine, Eq. 22) on the ``fig5``
scene; :data:`PAPER_OUTCOMES` is what the paper's figures show for each, with and
without the pendulum, as this project reproduces it (``docs/paper-figures.md``):
A overturns the bare trilith after one impact and the pendulum saves it; B
survives; C overturns after an impact; D overturns without one.
"""
from __future__ import annotations

from trilith_xval.analytic.excitation import Pulse

__all__ = ["POINTS", "PAPER_OUTCOMES", "point_pulse"]

# point -> (A_s [m/s^2], Omega [rad/s]): Fig. 6 (A, B), Fig. 7 (C, D).
POINTS: dict[str, tuple[float, float]] = {"A": (19.0, 15.0), "B": (4.0, 9.0),
                                          "C": (10.0, 9.0), "D": (25.0, 11.0)}

# (point, with pendulum) -> (status, mode) of the corrected model (and the paper).
PAPER_OUTCOMES: dict[tuple[str, bool], tuple[str, str | None]] = {
    ("A", True): ("survived", None), ("A", False): ("overturned", "after-impact"),
    ("B", True): ("survived", None), ("B", False): ("survived", None),
    ("C", True): ("overturned", "after-impact"), ("C", False): ("overturned", "after-impact"),
    ("D", True): ("overturned", "no-impact"), ("D", False): ("overturned", "no-impact"),
}


def point_pulse(point: str) -> Pulse:
    """The one-sine pulse of a labelled point.

    Examples
    --------
    >>> point_pulse("A")
    Pulse(amplitude=19.0, omega=15.0, kind='sine')
    """
    if point not in POINTS:
        raise ValueError(f"point must be one of {', '.join(POINTS)}, got {point!r}")
    amplitude, omega = POINTS[point]
    return Pulse(amplitude, omega)
