"""The linearized rocking block under a one-sine pulse, solved in closed form
(written here, independently of analytic/): Housner (1963); Zhang & Makris (2001),
"Rocking response of free-standing blocks under cycloidal pulses", J. Eng. Mech.
127(5), 473-483, whose Type-A pulse is the one-sine acceleration pulse
``u_g'' = a_p sin(w_p t)``, ``0 <= t <= 2 pi / w_p`` (the paper's Eq. 22).

For a slender block (small ``alpha``) rocking about the corner of side ``s``
(``s = +1``: ``theta > 0``), ``sin(s alpha - theta) ~ s alpha - theta`` and
``cos ~ 1`` turn the equation of motion into::

    theta'' = p^2 theta - p^2 (s alpha + u_g''/g),      p^2 = 3 g / (4 R)

linear with constant coefficients between events, so each phase is::

    theta(t) = s alpha + K sin(w t) + c1 exp(p t) + c2 exp(-p t)   (during the pulse)
    K = (a_p/g) p^2 / (p^2 + w^2)

(``K = 0`` after it).  Events: uplift from rest when ``s u_g''/g < -alpha``; an
impact when ``theta`` crosses 0, after which ``theta'`` is multiplied by the
restitution ``e`` and the side changes.  After the pulse the motion is free:
``u = theta - s alpha`` obeys ``u'' = p^2 u``, so the block falls over on its
side iff the growing mode carries it outward (``s (u' + p u) > 0``); otherwise it
comes back to ``theta = 0`` with ``theta'^2 = u'^2 - p^2 u^2 + p^2 alpha^2`` and
after the impact escapes to the other side iff ``e |theta'| >= p alpha``; a lower
speed only loses energy at every later impact (survival).

Only root finding is numerical (the crossing time of a closed-form expression).
"""
from __future__ import annotations

import math

from scipy.optimize import brentq

__all__ = ["overturns", "min_overturning_amplitude"]


def _coeffs(theta, dtheta, t0, s, alpha, p, k, w):
    """``(c1, c2)`` of ``theta = s alpha + k sin(w t) + c1 e^{p(t-t0)} + c2 e^{-p(t-t0)}``
    through ``(theta, dtheta)`` at ``t0``."""
    u = theta - s * alpha - k * math.sin(w * t0)
    du = dtheta - k * w * math.cos(w * t0)
    return 0.5 * (u + du / p), 0.5 * (u - du / p)


def _state(t, t0, s, alpha, p, k, w, c1, c2):
    ep, em = math.exp(p * (t - t0)), math.exp(-p * (t - t0))
    return (s * alpha + k * math.sin(w * t) + c1 * ep + c2 * em,
            k * w * math.cos(w * t) + p * (c1 * ep - c2 * em))


def _next_uplift(t: float, T: float, a_over_g: float, alpha: float, w: float):
    """The first time >= ``t`` before ``T`` at which ``|u_g''/g| > alpha``, or None."""
    if abs(a_over_g * math.sin(w * t)) > alpha:
        return t
    x = math.asin(alpha / a_over_g) / w
    starts = [x, math.pi / w + x]  # the two windows of the positive and negative half
    later = [u for u in starts if t < u < T]
    return later[0] if later else None


def overturns(a_over_g: float, w: float, p: float, alpha: float, e: float) -> tuple[bool, int]:
    """``(overturned, n_impacts)`` of the linearized block under the one-sine pulse
    of amplitude ``a_over_g`` g and frequency ``w`` [rad/s]; ``p`` [rad/s] its
    frequency parameter, ``e`` the restitution (Housner: ``1 - 1.5 sin^2 alpha``)."""
    T = 2.0 * math.pi / w
    k = a_over_g * p * p / (p * p + w * w)
    t, n = 0.0, 0
    # At rest until |u_g''/g| first exceeds alpha: the positive half lifts the block
    # onto side s = -1 (the ground pushes the base forward, the block tips back).
    if a_over_g <= alpha:
        return False, 0
    t = math.asin(alpha / a_over_g) / w
    s, theta, dtheta = -1, 0.0, 0.0
    while t < T:
        c1, c2 = _coeffs(theta, dtheta, t, s, alpha, p, k, w)
        # The first crossing of theta = 0 (away from the start) before the pulse end,
        # on a grid fine against both time scales, then refined.
        step = min(1.0 / p, 1.0 / w) / 200.0
        t_a = t
        hit = None
        while t_a < T:
            t_b = min(t_a + step, T)
            th_b = _state(t_b, t, s, alpha, p, k, w, c1, c2)[0]
            if s * th_b < 0.0:
                hit = (t_a, t_b)
                break
            t_a = t_b
        if hit is not None and hit[0] == t:
            # Back through 0 within the first grid step: the ground pulls the
            # block down faster than it rises (a chatter of vanishing impacts):
            # at rest, as the model's rest rule has it.
            t_up = _next_uplift(t_b, T, a_over_g, alpha, w)
            if t_up is None:
                return False, n
            t, s, theta, dtheta = t_up, (-1 if math.sin(w * t_up) > 0.0 else 1), 0.0, 0.0
            continue
        if hit is None:
            theta, dtheta = _state(T, t, s, alpha, p, k, w, c1, c2)
            t = T
            break
        t_i = brentq(lambda x: _state(x, t, s, alpha, p, k, w, c1, c2)[0], *hit,
                     xtol=1e-14, rtol=1e-14)
        v = _state(t_i, t, s, alpha, p, k, w, c1, c2)[1]
        n += 1
        t, theta, dtheta, s = t_i, 0.0, e * v, -s
        if abs(dtheta) < 1e-12:  # at rest again: uplift as soon as the pulse allows it
            t_up = _next_uplift(t, T, a_over_g, alpha, w)
            if t_up is None:
                return False, n
            t, s, theta, dtheta = t_up, (-1 if math.sin(w * t_up) > 0.0 else 1), 0.0, 0.0
    # Free motion after the pulse.
    u, du = theta - s * alpha, dtheta
    if s * (du + p * u) > 0.0:
        return True, n
    v2 = du * du - p * p * u * u + p * p * alpha * alpha
    return e * math.sqrt(max(v2, 0.0)) >= p * alpha, n + 1


def min_overturning_amplitude(w: float, p: float, alpha: float, e: float, tol: float = 1e-5,
                              a_max: float = 60.0) -> tuple[float, int]:
    """``(a_p/g, n_impacts)``: the smallest amplitude that overturns, found by a
    scan in relative steps of 0.2 % from the uplift ``alpha`` and a bisection of
    the first overturning interval to ``tol`` relative."""
    lo = alpha
    a = alpha * 1.002
    while a < a_max * alpha:
        if overturns(a, w, p, alpha, e)[0]:
            hi = a
            while hi - lo > tol * hi:
                mid = 0.5 * (lo + hi)
                if overturns(mid, w, p, alpha, e)[0]:
                    hi = mid
                else:
                    lo = mid
            return hi, overturns(hi, w, p, alpha, e)[1]
        lo, a = a, a * 1.002
    return math.nan, 0
