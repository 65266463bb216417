"""Closed forms derived independently in the tests (not from analytic/)."""
from __future__ import annotations

import math


def makris_vassiliou(alpha: float, gamma_mv: float) -> float:
    """Rocking-frame restitution (Makris & Vassiliou 2013), uniform columns,
    ``gamma_mv`` = cap-beam mass / total column mass.  Derived here from the
    moment of momentum about the new pivots: ``I e = 2 J_G + m1 (h^2 - b^2)/2 +
    m3 (h^2 - b^2)`` over ``I = 2 J_G + (b^2+h^2)(m1/2 + m3)``, which with
    ``J_G = m1 (b^2+h^2)/12`` becomes the expression below."""
    s2 = math.sin(alpha) ** 2
    return (1.0 - 1.5 * s2 + 3.0 * gamma_mv * math.cos(2.0 * alpha)) / (1.0 + 3.0 * gamma_mv)
