"""The numba kernel of the fast analytic path: one run over the phases REST /
ROCK(+1) / ROCK(-1) with Dormand-Prince 5(4), dense output and event location,
under a pulse (Eq. 22/23) or a sampled record.

The step-level pieces (compiled equations, one DP step, event location) live in
:mod:`analytic._fast_steps`; the verdict-only entry points in
:mod:`analytic._fast_kernels`.  The phase semantics are the accurate path's
(``analytic/simulate.py``, see ``analytic/fast.py`` for the list).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._fast_numerics import (_MAX_FACTOR, _MIN_FACTOR, _SAFETY, _dense, _push, _push_event,
                             _samples_until)
from ._fast_steps import (KIND_LINE, KIND_SAMPLES, _barrier, _deriv, _dp_step, _energy,
                          _frame_potential, _impact, _locate, _margin, _pendulum_period,
                          _record_piece, _rest_energy, _xg, overturn_certain)

# --- codes shared with analytic/fast.py --------------------------------------------
ST_OVERTURNED, ST_SURVIVED, ST_UNSTABLE, ST_UNDECIDED = 0, 1, 2, 3
EV_UPLIFT, EV_IMPACT, EV_REST, EV_OVERTURN, EV_UNSTABLE = 0, 1, 2, 3, 4
(R_OVERTURN, R_BARRIER, R_REST_NO_PENDULUM, R_PENDULUM_PERIOD, R_T_MAX, R_T_CAP,
 R_NONFINITE, R_STEP_UNDERFLOW, R_STEP_BUDGET, R_CERTAIN) = range(10)


@njit(cache=True)
def run(amp, b, h, mu, gamma, j, l, g, omega, pkind, t_end_pulse, thr, rtol, atol,
        rest_velocity, t_max, t_cap, max_steps, rest_frac, certain_exit, rf, record,
        sample_dt, rec_t, rec_a):
    """Integrate one run.  ``t_max <= 0`` means exact survival (no fixed horizon);
    ``rest_frac``: largest REST step over the pulse period (after the pulse, over
    the small-swing pendulum period); ``certain_exit``: with exact survival, end
    an overturn as soon as it is certain (:func:`overturn_certain`; status
    overturned, reason ``R_CERTAIN``, time = that instant) instead of
    integrating the fall to ``thr``; ``rf``: the restitution factor, which
    multiplies every impact's rocking ratio (Eq. 19/20,
    :func:`analytic.equations.impact_velocities`).

    Excitation: a pulse (``pkind`` ``KIND_SINE``/``KIND_COSINE``, ``amp``
    [m/s^2], ``omega`` [rad/s], ``t_end_pulse = 2 pi/omega``; ``rec_t``,
    ``rec_a`` unused), or ``KIND_SAMPLES``: ``amp`` times the record
    ``(rec_t [s], rec_a [m/s^2])`` linearly interpolated, ``t_end_pulse =
    rec_t[-1]``, every sample a breakpoint (:func:`_record_piece`) and
    ``max_steps`` counted beyond one step per sample.

    Returns ``(status, reason, t_verdict, n_impacts, samples, n_samples, events,
    n_events, n_steps, e_out)`` (``e_out``: how near the run came to the
    overturning barrier, energy per m1, NaN when decided before the pulse end;
    see below); ``samples`` rows are ``t, theta, theta_dot, psi, psi_dot``,
    ``events`` rows ``kind, t, side, td-, td+, psi, pd-, pd+``.  With ``record``
    False the two buffers stay 1-row placeholders (verdict only).
    """
    exact = t_max <= 0.0
    samples_kind = pkind == KIND_SAMPLES
    t_on = rec_t[0] if samples_kind else 0.0
    if samples_kind:  # one step per sample interval at least
        max_steps += rec_t.shape[0]
    # What _xg integrates on the current step: the pulse itself, or the straight
    # line of the record's current sample interval (ip; updated every step).
    xkind, xamp, xom = (KIND_LINE, 0.0, 0.0) if samples_kind else (pkind, amp, omega)
    ip = -1
    t_kink = math.inf
    t_stop = t_end_pulse + t_cap if exact else t_max
    # The exact survival rules also decide a fixed-window run ('survived' at t_max
    # follows from them); only a recorded trajectory must run on to t_max.
    early = exact or not record
    # A certain overturn may end the run only where nobody reads the fall itself
    # and no fixed window could still call a slow fall 'survived'.
    certain = certain_exit and exact and not record
    # The barrier argument only holds on the stable side (|theta| < alpha): beyond
    # alpha an energy below the barrier means the frame can no longer come back.
    barrier = _barrier(b, h, mu, gamma, g)
    alpha = math.atan2(b, h)
    quarter = 0.25 * t_end_pulse
    # Small-swing pendulum period: the time scale of the margin after the pulse.
    pend_period = 2.0 * math.pi * math.sqrt(l / g) if gamma > 0.0 else math.inf

    y = np.zeros(4)
    ynew = np.empty(4)
    ytmp = np.empty(4)
    ystage = np.empty(4)
    k = np.empty((7, 4))
    f = np.empty(4)
    row = np.empty(5)
    if record:
        samples = np.empty((1024, 5))
        events = np.empty((64, 8))
    else:
        samples = np.empty((1, 5))
        events = np.empty((1, 8))
    ns = 0
    ne = 0
    if record:
        row[:] = 0.0
        samples, ns = _push(samples, ns, row)
    next_s = sample_dt

    t = 0.0
    phase = 0
    n_imp = 0
    hstep = min(1e-3, 0.01 * t_end_pulse)  # first trial; error control adapts it
    need_k0 = True
    check_margin = True
    rest_deadline = math.inf
    pulse_done = False
    status = -1
    reason = -1
    t_verdict = math.nan
    n_steps = 0
    # How near the run came to the barrier (e_out): the largest of the frame's
    # potential during the pulse (at its widest swing) and the energy carried out
    # of the pulse.  That energy is the pulse-end energy, or, if the frame is then
    # rocking inward, the larger of the energy with theta_dot set to 0 (continuous
    # where the frame turns at the pulse end) and the energy just after its next
    # impact (unless it turns outward first).  After the pulse the energy only
    # drops, so an overturn needs e_out >= barrier.
    e_out = math.nan
    e_stay = math.nan
    v_pulse = 0.0
    th_peak = 0.0
    await_impact = False

    while True:
        # -- pulse end: the excitation stops, energy can only decrease from now on
        if not pulse_done and t >= t_end_pulse:
            pulse_done = True
            need_k0 = True
            check_margin = True
            if phase == 0:
                en = _rest_energy(y[2], y[3], gamma, l, g)
            else:
                en = _energy(y[0], y[1], y[2], y[3], float(phase), b, h, mu, gamma, j, l, g)
            v_pulse = _frame_potential(th_peak, alpha, barrier, b, h, mu, gamma, g)
            e_out = max(en, v_pulse)
            await_impact = phase != 0 and phase * y[1] < 0.0
            if await_impact:
                e_stay = _energy(y[0], 0.0, y[2], y[3], float(phase), b, h, mu, gamma, j, l, g)
            if gamma == 0.0 and await_impact and (abs(y[0]) < alpha or en > barrier) \
                    and not record:
                # No pendulum, rocking inward (back over alpha if past it: E > barrier):
                # the energy is conserved down to the impact at theta = 0, which
                # keeps r^2 of it (Eq. 20): e_out is known now, and so is the
                # verdict unless it sits exactly on the barrier.  (A recorded run
                # goes on: its reader wants the motion.)
                r = _impact(1.0, 0.0, 0.0, float(-phase), b, h, mu, gamma, j, l, rf)[0]
                e_next = r * r * en
                e_out = max(v_pulse, e_stay, e_next)
                await_impact = False
                if early and e_next < barrier:
                    status, reason, t_verdict = ST_SURVIVED, R_BARRIER, t
                    break
                if certain and e_next > barrier:  # out of the impact past the barrier
                    n_imp += 1
                    status, reason, t_verdict = ST_OVERTURNED, R_CERTAIN, t
                    break
            if early and en < barrier and abs(y[0]) < alpha:
                status, reason, t_verdict = ST_SURVIVED, R_BARRIER, t
                break
            if certain and overturn_certain(y[0], y[1], en, phase, barrier, alpha, b, h, mu,
                                            gamma, l, g):
                status, reason, t_verdict = ST_OVERTURNED, R_CERTAIN, t
                break
            if early and phase == 0:
                if gamma == 0.0:
                    status, reason, t_verdict = ST_SURVIVED, R_REST_NO_PENDULUM, t
                    break
                rest_deadline = t + _pendulum_period(y[2], y[3], l, g)
        on = t_on <= t < t_end_pulse
        if samples_kind:
            entering = ip < 0 and on
            ip, xamp, xom, t_kink = _record_piece(rec_t, rec_a, amp, ip, t)
            # A record that starts late may start with a jump: at rest, the
            # margin is checked at once there (as at t = 0 for a cosine pulse).
            check_margin = check_margin or entering
            need_k0 = need_k0 or entering
        # -- REST: uplift at once when the margin is already <= 0
        if phase == 0 and check_margin:
            check_margin = False
            xg = _xg(t, on, xamp, xom, xkind)
            mp = _margin(y[2], y[3], xg, 1.0, b, h, mu, gamma, l, g)
            mm = _margin(y[2], y[3], xg, -1.0, b, h, mu, gamma, l, g)
            if mp <= 0.0 or mm <= 0.0:
                side = 1 if mp <= mm else -1
                events, ne = _push_event(events, ne, EV_UPLIFT, t, side, 0.0, 0.0, y[2],
                                         y[3], y[3], record)
                phase = side
                y[0] = 0.0
                y[1] = 0.0
                rest_deadline = math.inf
                need_k0 = True
        if early and phase == 0 and pulse_done and t >= rest_deadline:
            status, reason, t_verdict = ST_SURVIVED, R_PENDULUM_PERIOD, t
            break
        if t >= t_stop:
            status = ST_UNDECIDED if exact else ST_SURVIVED
            reason = R_T_CAP if exact else R_T_MAX
            t_verdict = t
            break
        if n_steps >= max_steps:
            status, reason, t_verdict = ST_UNDECIDED, R_STEP_BUDGET, t
            break
        # -- next breakpoint: quarter periods of the pulse (extrema of the sine's
        #    margin, the pulse end) or the record's next sample, the stop time,
        #    the rest deadline
        t_next = t_stop
        if samples_kind:
            if t_kink < t_next:
                t_next = t_kink
        elif on:
            for q in range(1, 5):
                bp = q * quarter if q < 4 else t_end_pulse
                if bp > t * (1.0 + 1e-14) + 1e-300:
                    if bp < t_next:
                        t_next = bp
                    break
        if phase == 0 and rest_deadline < t_next:
            t_next = rest_deadline
        if phase == 0:
            # At rest the error control sees only the pendulum (or nothing): cap the
            # step so a short dip of the uplift margin is not stepped over (the
            # accurate path caps its REST steps the same way).
            h_rest = rest_frac * (t_end_pulse if on else pend_period)
            if hstep > h_rest:
                hstep = h_rest
        if need_k0:
            _deriv(phase, y, _xg(t, on, xamp, xom, xkind), f, b, h, mu, gamma, j, l, g)
            for c in range(4):
                k[0, c] = f[c]
            need_k0 = False
        if phase != 0 and y[0] == 0.0:
            # Rocking starts at theta = 0 moving out but pulled back: the excursion
            # lasts tau = 2|v/a|; a step well inside it keeps the impact bracketed.
            sv = phase * y[1]
            sa = phase * k[0, 1]
            if sv > 0.0 and sa < 0.0:
                tau = 2.0 * sv / -sa
                if hstep > 0.125 * tau:
                    hstep = 0.125 * tau
        hit = False
        if hstep >= t_next - t:
            hstep = t_next - t
            hit = True
        if not (hstep > 1e-14 * max(1.0, t)):
            if hit:  # already at the breakpoint up to round-off
                t = t_next
                continue
            status, reason, t_verdict = ST_UNSTABLE, R_STEP_UNDERFLOW, t
            events, ne = _push_event(events, ne, EV_UNSTABLE, t, phase, math.nan, math.nan,
                                     y[2], math.nan, math.nan, record)
            break
        t1 = t_next if hit else t + hstep
        err, finite = _dp_step(phase, t, t1, y, hstep, on, xamp, xom, xkind, rtol, atol, k,
                               ystage, ynew, f, b, h, mu, gamma, j, l, g)
        n_steps += 1
        if not finite:
            status, reason, t_verdict = ST_UNSTABLE, R_NONFINITE, t
            events, ne = _push_event(events, ne, EV_UNSTABLE, t, phase, math.nan, math.nan,
                                     y[2], math.nan, math.nan, record)
            break
        if err > 1.0:
            hstep *= max(_MIN_FACTOR, _SAFETY * err ** -0.2)
            continue
        if phase != 0 and phase * y[0] <= 0.0 and phase * ynew[0] < 0.0:
            # s*theta went below 0 from the start of a rock phase: the excursion
            # was shorter than the step.  Retry smaller; at round-off there was no
            # excursion at all and the frame is back at rest.
            if hstep > 1e-12 * max(1.0, t):
                hstep *= 0.125
                continue
            # No measurable excursion: the frame is back at rest.  The margin is
            # not re-checked at once (it is still <= 0 for a few ns, which would
            # loop uplift/rest without time advancing); the next uplift needs the
            # margin to come from above again, as in the accurate path's recovery.
            events, ne = _push_event(events, ne, EV_REST, t, 0, y[1], 0.0, y[2], y[3],
                                     y[3], record)
            phase = 0
            y[0] = 0.0
            y[1] = 0.0
            check_margin = False
            need_k0 = True
            hstep = 1e-3 * quarter
            continue
        h_used = hstep
        if err == 0.0:
            factor = _MAX_FACTOR
        else:
            factor = min(_MAX_FACTOR, _SAFETY * err ** -0.2)
        # -- events inside the accepted step: the earliest wins
        ev_kind = -1
        ev_side = 0
        ev_x = 2.0
        if phase == 0:
            xg0 = _xg(t, on, xamp, xom, xkind)
            for side in (1, -1):
                m0 = _margin(y[2], y[3], xg0, float(side), b, h, mu, gamma, l, g)
                m1 = _margin(ynew[2], ynew[3], _xg(t1, on, xamp, xom, xkind), float(side), b,
                             h, mu, gamma, l, g)
                if m0 > 0.0 and m1 <= 0.0:
                    x = _locate(0, side, y, k, t, h_used, on, xamp, xom, xkind, thr, b, h,
                                mu, gamma, l, g, ytmp)
                    if x < ev_x:
                        ev_x, ev_kind, ev_side = x, EV_UPLIFT, side
        else:
            s = float(phase)
            if s * y[0] > 0.0 and s * ynew[0] <= 0.0:
                x = _locate(1, s, y, k, t, h_used, on, xamp, xom, xkind, thr, b, h, mu,
                            gamma, l, g, ytmp)
                ev_x, ev_kind = x, EV_IMPACT
            elif s * ynew[0] >= thr:
                x = _locate(2, s, y, k, t, h_used, on, xamp, xom, xkind, thr, b, h, mu,
                            gamma, l, g, ytmp)
                ev_x, ev_kind = x, EV_OVERTURN
        if ev_kind < 0:
            if record:
                samples, ns, next_s = _samples_until(samples, ns, next_s, sample_dt, t1, y,
                                                     k, t, h_used, ytmp, row)
            t = t1
            for c in range(4):
                y[c] = ynew[c]
                k[0, c] = k[6, c]
            hstep = h_used * factor
            if on and abs(y[0]) > th_peak:
                th_peak = abs(y[0])
            if await_impact and phase * y[1] >= 0.0:
                await_impact = False  # turned outward before the impact: e_out stays
            # Without pendulum, past alpha moving outward is certain at any time
            # after the pulse (the energy test needs only the pulse end: the energy
            # is constant afterwards but for impacts, which happen inside alpha).
            if certain and pulse_done and gamma == 0.0 and overturn_certain(
                    y[0], y[1], barrier, phase, barrier, alpha, b, h, mu, gamma, l, g):
                status, reason, t_verdict = ST_OVERTURNED, R_CERTAIN, t
                break
            continue
        # -- an event at t_e: state from the dense output
        t_e = t + ev_x * h_used
        if ev_x >= 1.0:
            t_e = t1
        _dense(y, k, h_used, ev_x, ytmp)
        if record:
            samples, ns, next_s = _samples_until(samples, ns, next_s, sample_dt, t_e, y, k,
                                                 t, h_used, ynew, row)
        t = t_e
        need_k0 = True
        hstep = h_used * min(factor, 1.0)
        if ev_kind == EV_UPLIFT:
            phase = ev_side
            y[0] = 0.0
            y[1] = 0.0
            y[2] = ytmp[2]
            y[3] = ytmp[3]
            rest_deadline = math.inf
            events, ne = _push_event(events, ne, EV_UPLIFT, t, ev_side, 0.0, 0.0, y[2], y[3],
                                     y[3], record)
        elif ev_kind == EV_OVERTURN:
            for c in range(4):
                y[c] = ytmp[c]
            events, ne = _push_event(events, ne, EV_OVERTURN, t, phase, y[1], y[1], y[2],
                                     y[3], y[3], record)
            status, reason, t_verdict = ST_OVERTURNED, R_OVERTURN, t
            if record:
                row[0] = t
                for c in range(4):
                    row[c + 1] = y[c]
                samples, ns = _push(samples, ns, row)
            break
        else:  # impact at theta = 0 (Eq. 13-21), new side = -phase
            new_side = -phase
            tdm = ytmp[1]
            pdm = ytmp[3]
            tdp, pdp = _impact(tdm, ytmp[2], pdm, float(new_side), b, h, mu, gamma, j, l, rf)
            n_imp += 1
            if record:  # the instant before the impact; the one after is pushed below
                row[0] = t
                row[1] = 0.0
                row[2] = tdm
                row[3] = ytmp[2]
                row[4] = pdm
                samples, ns = _push(samples, ns, row)
            events, ne = _push_event(events, ne, EV_IMPACT, t, new_side, tdm, tdp, ytmp[2],
                                     pdm, pdp, record)
            y[0] = 0.0
            y[2] = ytmp[2]
            y[3] = pdp
            if await_impact:
                await_impact = False
                if abs(tdp) < rest_velocity:
                    e_next = _rest_energy(y[2], y[3], gamma, l, g)
                else:
                    e_next = _energy(0.0, tdp, y[2], y[3], float(new_side), b, h, mu, gamma,
                                     j, l, g)
                e_out = max(v_pulse, e_stay, e_next)
            if abs(tdp) < rest_velocity:
                y[1] = 0.0
                phase = 0
                check_margin = True
                events, ne = _push_event(events, ne, EV_REST, t, 0, tdm, 0.0, y[2], pdm, pdp,
                                         record)
                if pulse_done and early:
                    if _rest_energy(y[2], y[3], gamma, l, g) < barrier:
                        status, reason, t_verdict = ST_SURVIVED, R_BARRIER, t
                    elif gamma == 0.0:
                        status, reason, t_verdict = ST_SURVIVED, R_REST_NO_PENDULUM, t
                    else:
                        rest_deadline = t + _pendulum_period(y[2], y[3], l, g)
            else:
                y[1] = tdp
                phase = new_side
                if pulse_done and early and _energy(
                        0.0, tdp, y[2], y[3], float(new_side), b, h, mu, gamma, j, l,
                        g) < barrier:
                    status, reason, t_verdict = ST_SURVIVED, R_BARRIER, t
        if record:
            row[0] = t
            for c in range(4):
                row[c + 1] = y[c]
            samples, ns = _push(samples, ns, row)
        if status >= 0:
            break
    return status, reason, t_verdict, n_imp, samples, ns, events, ne, n_steps, e_out
