"""Numerical primitives of the fast path, free of physics: the Dormand-Prince
5(4) tableau and its continuous extension, the elliptic integral K by the AGM,
and the growable output buffers.  Used by :mod:`analytic._fast_kernels`.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# --- Dormand-Prince 5(4) tableau and its 4th-order dense output (as in scipy's RK45)
_C = np.array([0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0])
_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [0.2, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0]])
_B = np.array([35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0,
               11.0 / 84.0])
_E = np.array([-71.0 / 57600.0, 0.0, 71.0 / 16695.0, -71.0 / 1920.0, 17253.0 / 339200.0,
               -22.0 / 525.0, 1.0 / 40.0])
_P = np.array([
    [1.0, -8048581381.0 / 2820520608.0, 8663915743.0 / 2820520608.0,
     -12715105075.0 / 11282082432.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 131558114200.0 / 32700410799.0, -68118460800.0 / 10900136933.0,
     87487479700.0 / 32700410799.0],
    [0.0, -1754552775.0 / 470086768.0, 14199869525.0 / 1410260304.0,
     -10690763975.0 / 1880347072.0],
    [0.0, 127303824393.0 / 49829197408.0, -318862633887.0 / 49829197408.0,
     701980252875.0 / 199316789632.0],
    [0.0, -282668133.0 / 205662961.0, 2019193451.0 / 616988883.0,
     -1453857185.0 / 822651844.0],
    [0.0, 40617522.0 / 29380423.0, -110615467.0 / 29380423.0, 69997945.0 / 29380423.0]])

_SAFETY = 0.9          # usual step-size safety factor (Hairer)
_MIN_FACTOR = 0.2      # bounds on the step change per step, as scipy uses
_MAX_FACTOR = 10.0
_ROOT_XTOL = 1e-14     # event location: relative position inside the step
_ROOT_ITER = 200



@njit(cache=True)
def _dense(y0, k, hstep, x, out):
    """DP5 4th-order continuous extension at ``t0 + x*hstep``."""
    x2 = x * x
    q0 = x
    q1 = x2
    q2 = x2 * x
    q3 = x2 * x2
    for c in range(4):
        acc = 0.0
        for i in range(7):
            acc += k[i, c] * (_P[i, 0] * q0 + _P[i, 1] * q1 + _P[i, 2] * q2 + _P[i, 3] * q3)
        out[c] = y0[c] + hstep * acc



@njit(cache=True)
def _ellipk(m):
    """Complete elliptic integral of the first kind ``K(m)``, ``0 <= m < 1``, by
    the arithmetic-geometric mean: ``K = pi / (2 AGM(1, sqrt(1 - m)))``."""
    a = 1.0
    bb = math.sqrt(1.0 - m)
    for _ in range(60):
        if abs(a - bb) <= 1e-16 * a:
            break
        a, bb = 0.5 * (a + bb), math.sqrt(a * bb)
    return math.pi / (2.0 * a)



@njit(cache=True)
def _grow(arr, n):
    out = np.empty((2 * arr.shape[0], arr.shape[1]))
    out[:n] = arr[:n]
    return out


@njit(cache=True)
def _push(buf, n, row):
    if n >= buf.shape[0]:
        buf = _grow(buf, n)
    for c in range(row.shape[0]):
        buf[n, c] = row[c]
    return buf, n + 1


@njit(cache=True)
def _push_event(ev, ne, kind, t, side, tdb, tda, psi, pdb, pda, record):
    if not record:
        return ev, ne + 1
    if ne >= ev.shape[0]:
        ev = _grow(ev, ne)
    ev[ne, 0] = kind
    ev[ne, 1] = t
    ev[ne, 2] = side
    ev[ne, 3] = tdb
    ev[ne, 4] = tda
    ev[ne, 5] = psi
    ev[ne, 6] = pdb
    ev[ne, 7] = pda
    return ev, ne + 1


@njit(cache=True)
def _samples_until(buf, n, next_s, sample_dt, t_end, y0, k, t0, hstep, ytmp, row):
    """Append grid samples in (t0, t_end] from the step's dense output."""
    while next_s <= t_end + 1e-12 * max(1.0, t_end):
        x = (next_s - t0) / hstep if hstep > 0.0 else 1.0
        if x > 1.0:
            x = 1.0
        _dense(y0, k, hstep, x, ytmp)
        row[0] = next_s
        row[1] = ytmp[0]
        row[2] = ytmp[1]
        row[3] = ytmp[2]
        row[4] = ytmp[3]
        buf, n = _push(buf, n, row)
        next_s = (round(next_s / sample_dt) + 1.0) * sample_dt
    return buf, n, next_s
