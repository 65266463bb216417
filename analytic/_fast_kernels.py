"""Verdict-only entry points of the fast analytic path, and the names of the
kernel :func:`run` (:mod:`analytic._fast_run`) and its codes.

:func:`verdict` and :func:`verdicts` run a pulse (Eq. 22/23): one amplitude, or
many in one compiled loop (no per-run dispatch); :func:`record_verdicts` runs a
sampled record at many scale factors the same way.  They allocate a few small
arrays per *call* and nothing per step.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ._fast_numerics import _ellipk  # noqa: F401  (re-exported: tests, callers)
from ._fast_run import (EV_IMPACT, EV_OVERTURN, EV_REST, EV_UNSTABLE,  # noqa: F401
                        EV_UPLIFT, R_BARRIER, R_CERTAIN, R_NONFINITE, R_OVERTURN,
                        R_PENDULUM_PERIOD, R_REST_NO_PENDULUM, R_STEP_BUDGET,
                        R_STEP_UNDERFLOW, R_T_CAP, R_T_MAX, ST_OVERTURNED, ST_SURVIVED,
                        ST_UNDECIDED, ST_UNSTABLE, run)
from ._fast_steps import (KIND_COSINE, KIND_SAMPLES, KIND_SINE,  # noqa: F401
                          _pendulum_period)

@njit(cache=True)
def _no_record():
    """The record arguments of :func:`run` under a pulse (never read): a fresh
    writeable array, of the type a record's arrays have, so one compiled
    :func:`run` serves both."""
    return np.zeros(1)


@njit(cache=True)
def verdict(amp, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol, atol,
            rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf):
    """Verdict of one pulse only: ``(status, reason, t_verdict, n_impacts)``."""
    st, rs, tv, ni, _s, _ns, _e, _ne, _n, _en = run(
        amp, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol, atol,
        rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf, False, 1.0,
        _no_record(), _no_record())
    return st, rs, tv, ni


@njit(cache=True)
def _many(amps, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol, atol,
          rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf, rec_t, rec_a):
    n = amps.shape[0]
    st = np.empty(n, dtype=np.int64)
    rs = np.empty(n, dtype=np.int64)
    tv = np.empty(n)
    ni = np.empty(n, dtype=np.int64)
    en = np.empty(n)
    steps = np.empty(n, dtype=np.int64)
    for i in range(n):
        out = run(amps[i], b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol,
                  atol, rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit,
                  rf, False, 1.0, rec_t, rec_a)
        st[i] = out[0]
        rs[i] = out[1]
        tv[i] = out[2]
        ni[i] = out[3]
        steps[i] = out[8]
        en[i] = out[9]
    return st, rs, tv, ni, en, steps


@njit(cache=True)
def verdicts(amps, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol, atol,
             rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf):
    """:func:`verdict` for every amplitude of ``amps``: arrays ``(status, reason,
    t_verdict, n_impacts, e_out)``, ``e_out`` how near each run came to the
    barrier (see :func:`analytic._fast_run.run`)."""
    st, rs, tv, ni, en, _steps = _many(amps, b, h, mu, gamma, j, l, g, omega, pkind,
                                       t_end_pulse, thr, rtol, atol, rest_velocity, t_max,
                                       t_cap, max_steps, rest_frac, certain_exit, rf,
                                       _no_record(), _no_record())
    return st, rs, tv, ni, en


@njit(cache=True)
def record_verdicts(scales, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol,
                    atol, rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf,
                    rec_t, rec_a):
    """The verdict of the record ``(rec_t, rec_a)`` (``pkind = KIND_SAMPLES``)
    scaled by every factor of ``scales``: arrays ``(status, reason, t_verdict,
    n_impacts, e_out, n_steps)``."""
    return _many(scales, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol,
                 atol, rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf,
                 rec_t, rec_a)
