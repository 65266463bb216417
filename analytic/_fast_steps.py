"""Step-level pieces of the fast analytic path: the compiled equations, the
right-hand side per phase, one Dormand-Prince 5(4) step, the event functions and
their location on the dense output (used by :mod:`analytic._fast_kernels`).

The physics is *not* re-typed here: the scalar functions of
:mod:`analytic.equations` (Eq. 1, 8, A.1, 9, 19, 21 corrected) are compiled as they
are with ``numba.njit``.  Compiled once per process; ``cache=True`` keeps the
machine code on disk between processes (:mod:`analytic._numba_cache` drops it when
a source changes).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _numba_cache  # noqa: F401  (drops stale machine code before numba loads it)
from . import equations as _eq
from ._fast_numerics import _A, _B, _C, _E, _ROOT_ITER, _ROOT_XTOL, _dense, _ellipk

# --- the equations, compiled from the single source -------------------------------
_rock = njit(cache=True)(_eq.rocking_accelerations)
_rest_acc = njit(cache=True)(_eq.rest_pendulum_acceleration)
_margin = njit(cache=True)(_eq.uplift_margin)
_impact = njit(cache=True)(_eq.impact_velocities)
_energy = njit(cache=True)(_eq.energy)
_rest_energy = njit(cache=True)(_eq.rest_energy)
_barrier = njit(cache=True)(_eq.overturn_energy_barrier)



@njit(cache=True)
def sample_accelerations(theta, theta_dot, psi, psi_dot, xg, sides, b, h, mu, gamma, j, l, g):
    """``(theta_ddot, psi_ddot)`` at every sample, as rows of an ``(n, 2)`` array:
    Eq. 8 / A.1 where ``sides`` is +1 / -1, Eq. 1 where it is 0 (rest; 0 without
    a pendulum).  The same numbers, bit for bit, as
    :func:`analytic.reactions._accelerations` sample by sample."""
    out = np.zeros((theta.shape[0], 2))
    for i in range(theta.shape[0]):
        if sides[i] != 0.0:
            out[i, 0], out[i, 1] = _rock(theta[i], theta_dot[i], psi[i], psi_dot[i], xg[i],
                                         sides[i], b, h, mu, gamma, j, l, g)
        elif gamma > 0.0:
            out[i, 1] = _rest_acc(psi[i], xg[i], l, g)
    return out


# Excitation kinds: the one-sine and one-cosine pulses (Eq. 22 / Eq. 23) and a
# sampled record; analytic.fast maps the names onto them.  KIND_LINE is what the
# run integrates on one sample interval of a record (never passed in).
KIND_SINE, KIND_COSINE, KIND_SAMPLES, KIND_LINE = 0, 1, 2, 3


@njit(cache=True)
def _xg(t, on, amp, omega, kind):
    """Ground acceleration ``xg_ddot(t)`` [m/s^2]; ``on`` is False outside the
    excitation.  Pulses: ``amp sin(omega t)`` (Eq. 22) or ``amp cos(omega t)``
    (Eq. 23).  ``KIND_LINE``: the straight line ``amp + omega t`` (intercept
    [m/s^2], slope [m/s^3]) of a record's linear interpolation on one sample
    interval (:func:`_record_piece`)."""
    if not on:
        return 0.0
    if kind == KIND_LINE:
        return amp + omega * t
    if kind == KIND_COSINE:
        return amp * math.cos(omega * t)
    return amp * math.sin(omega * t)


@njit(cache=True)
def _record_piece(rec_t, rec_a, scale, i, t):
    """The sample interval of a record that holds ``t``, as the run integrates it.

    ``i`` is the index of the interval's first sample at the previous call
    (``-1`` before the record; the run's time only grows, so the search goes on
    from it: O(1) per call, O(n) per run).  Returns ``(i, intercept, slope,
    t_kink)``: the record's linear interpolation ``scale * a(t)`` written as
    ``intercept + slope * t`` on ``[rec_t[i], rec_t[i+1]]`` (the same straight
    line as ``np.interp`` between those two samples, ``SampledRecord``'s
    acceleration), and ``t_kink``, the next sample after ``t``: a breakpoint,
    so no step straddles a kink of the interpolant.  Before the first sample
    the ground is still up to it; after the last, still for good
    (``t_kink = inf``)."""
    n = rec_t.shape[0]
    while i + 1 < n and rec_t[i + 1] <= t:
        i += 1
    if i < 0:
        return i, 0.0, 0.0, rec_t[0]
    if i + 1 >= n:
        return i, 0.0, 0.0, math.inf
    slope = scale * (rec_a[i + 1] - rec_a[i]) / (rec_t[i + 1] - rec_t[i])
    # intercept + slope t = scale a_i + slope (t - t_i); the round-off of the
    # intercept form is ~1e-16 |slope t|, ~1e-11 of the acceleration for an
    # 80 s record at 200 Hz: far below the integrator's rtol.
    return i, scale * rec_a[i] - slope * rec_t[i], slope, rec_t[i + 1]


@njit(cache=True)
def _deriv(phase, y, xg, out, b, h, mu, gamma, j, l, g):
    """Right-hand side in phase ``phase`` (0 = REST, +1/-1 = ROCK about that side)."""
    if phase == 0:
        out[0] = 0.0
        out[1] = 0.0
        if gamma == 0.0:
            out[2] = 0.0
            out[3] = 0.0
        else:
            out[2] = y[3]
            out[3] = _rest_acc(y[2], xg, l, g)
        return
    tdd, pdd = _rock(y[0], y[1], y[2], y[3], xg, float(phase), b, h, mu, gamma, j, l, g)
    out[0] = y[1]
    out[1] = tdd
    out[2] = y[3]
    out[3] = pdd


@njit(cache=True)
def _dp_step(phase, t, t1, y, hstep, on, amp, omega, pkind, rtol, atol, k, ystage, ynew, f,
             b, h, mu, gamma, j, l, g):
    """One Dormand-Prince 5(4) step from ``(t, y)`` with ``k[0] = f(t, y)``; fills
    ``k[1:7]`` (``k[6] = f(t1, ynew)``, first-same-as-last) and ``ynew``.  Returns
    the RMS error norm (``<= 1`` accepts) and whether ``ynew`` is finite."""
    for s in range(1, 6):
        for c in range(4):
            acc = 0.0
            for i in range(s):
                acc += _A[s, i] * k[i, c]
            ystage[c] = y[c] + hstep * acc
        _deriv(phase, ystage, _xg(t + _C[s] * hstep, on, amp, omega, pkind), f, b, h, mu,
               gamma, j, l, g)
        for c in range(4):
            k[s, c] = f[c]
    for c in range(4):
        acc = 0.0
        for i in range(6):
            acc += _B[i] * k[i, c]
        ynew[c] = y[c] + hstep * acc
    _deriv(phase, ynew, _xg(t1, on, amp, omega, pkind), f, b, h, mu, gamma, j, l, g)
    for c in range(4):
        k[6, c] = f[c]
    err = 0.0
    finite = True
    for c in range(4):
        acc = 0.0
        for i in range(7):
            acc += _E[i] * k[i, c]
        sc = atol + rtol * max(abs(y[c]), abs(ynew[c]))
        e = hstep * acc / sc
        err += e * e
        if not math.isfinite(ynew[c]):
            finite = False
    return math.sqrt(err / 4.0), finite


@njit(cache=True)
def _event_value(kind, side, yx, t, on, amp, omega, pkind, thr, b, h, mu, gamma, l, g):
    """Event functions; an event happens where the value becomes <= 0.

    kind 0: uplift margin about ``side`` (REST);  kind 1: ``side*theta`` (impact);
    kind 2: ``thr - side*theta`` (overturn).
    """
    if kind == 0:
        xg = _xg(t, on, amp, omega, pkind)
        return _margin(yx[2], yx[3], xg, float(side), b, h, mu, gamma, l, g)
    if kind == 1:
        return side * yx[0]
    return thr - side * yx[0]


@njit(cache=True)
def _locate(kind, side, y0, k, t0, hstep, on, amp, omega, pkind, thr, b, h, mu, gamma,
            l, g, ytmp):
    """First root in (0, 1] of an event function on the dense output, given
    value > 0 at x = 0 and <= 0 at x = 1.  Illinois regula falsi; returns the
    right end of the final bracket (where the event condition holds)."""
    xa = 0.0
    _dense(y0, k, hstep, 0.0, ytmp)
    fa = _event_value(kind, side, ytmp, t0, on, amp, omega, pkind, thr, b, h, mu, gamma, l, g)
    xb = 1.0
    _dense(y0, k, hstep, 1.0, ytmp)
    fb = _event_value(kind, side, ytmp, t0 + hstep, on, amp, omega, pkind, thr, b, h, mu,
                      gamma, l, g)
    last = 0
    for _ in range(_ROOT_ITER):
        if xb - xa <= _ROOT_XTOL:
            break
        if fa != fb:
            xm = xb - fb * (xb - xa) / (fb - fa)
        else:
            xm = 0.5 * (xa + xb)
        # keep the trial strictly inside; fall back to bisection on a bad secant
        if not (xa < xm < xb):
            xm = 0.5 * (xa + xb)
        _dense(y0, k, hstep, xm, ytmp)
        fm = _event_value(kind, side, ytmp, t0 + xm * hstep, on, amp, omega, pkind, thr, b,
                          h, mu, gamma, l, g)
        if fm <= 0.0:
            xb = xm
            fb = fm
            if last == -1:
                fa *= 0.5
            last = -1
        else:
            xa = xm
            fa = fm
            if last == 1:
                fb *= 0.5
            last = 1
    return xb


@njit(cache=True)
def _pendulum_period(psi, psi_dot, l, g):
    """Free-pendulum period [s] through ``(psi, psi_dot)`` (same cases as
    ``analytic.events.free_pendulum_period``): libration ``4 sqrt(l/g) K(m)``,
    ``m = sin^2(psi_max/2) = e/(2 g l)``; rotation ``4 l K(2gl/e) / sqrt(2e)``
    (one full turn); ``inf`` on the separatrix."""
    e = 0.5 * l * l * psi_dot * psi_dot + g * l * (1.0 - math.cos(psi))
    sep = 2.0 * g * l
    if e < sep:
        return 4.0 * math.sqrt(l / g) * _ellipk(e / sep)
    if e > sep:
        return 4.0 * l * _ellipk(sep / e) / math.sqrt(2.0 * e)
    return math.inf


@njit(cache=True)
def overturn_certain(theta, theta_dot, energy, phase, barrier, alpha, b, h, mu, gamma, l, g):
    """True when, after the pulse (inertial base), the run will reach any
    threshold in ``(alpha, pi/2]`` whatever happens next (proof in
    ``docs/overturn-maps.md``, "Early exit"):

    * past ``alpha`` (``s*theta > alpha``) with ``energy < barrier``: the frame
      cannot come back through ``alpha`` (the potential there is >= barrier),
      and it cannot stay in ``(alpha, pi/2]`` either: the momentum conjugate to
      the common shift of ``theta`` and ``psi`` (the kinetic energy depends on
      ``theta - psi`` only) grows at a rate bounded below while the velocities
      stay bounded, provided ``M R >= 2 gamma l`` (checked here);
    * without pendulum, past ``alpha`` moving outward: ``theta_ddot > 0`` there.
    """
    if phase == 0:
        return False
    st = phase * theta
    if st <= alpha:
        return False
    if gamma == 0.0 and phase * theta_dot >= 0.0:
        return True
    big_m = 1.0 + mu + gamma
    return energy < barrier and big_m * math.hypot(b, h) >= 2.0 * gamma * l


@njit(cache=True)
def _frame_potential(theta_peak, alpha, barrier, b, h, mu, gamma, g):
    """Largest potential per m1 the frame reached swinging to ``|theta| = theta_peak``
    (the pendulum hanging): rises to ``barrier`` at ``alpha``; past alpha, ``barrier``."""
    if theta_peak >= alpha:
        return barrier
    return g * (1.0 + mu + gamma) * (b * math.sin(theta_peak) + h * math.cos(theta_peak) - h)
