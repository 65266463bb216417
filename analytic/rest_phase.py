"""The REST phase of the event-driven simulator (:mod:`analytic.simulate`).

The frame stands still (``theta = theta_dot = 0``) while the pendulum swings
under the ground motion (Eq. 1); the phase ends at the first uplift, where the
margin of Eq. 9 of either side reaches 0 from above.  The margin's minima sit
at a pulse's ``|xg_ddot|`` peaks and at a record's samples, so REST segments
stop there, and a record's samples are integrated in blocks and checked one by
one.  After the excitation the exact survival rules 2 (no pendulum) and 3 (one
free-pendulum period without uplift) are decided here.

:class:`RestPhase` holds these methods of the run; the run's state (``t``,
``psi``, ``phase``, ``samples``, ``events``, ...) and the helpers they share
with the ROCK phase (``solve``, ``first_event``, ``point``, ``survive``,
``after_pulse``) are the simulator's ``_Run``.
"""
from __future__ import annotations

import math

import numpy as np

from . import equations as eq
from .events import free_pendulum_period, rest_rows, segment_acceleration
from .trajectory import Event

REASON_REST = "at rest after the pulse without pendulum"
REASON_PERIOD = "at rest after the pulse: no uplift during one free-pendulum period"
# Record samples per REST integration: doubled after each block without uplift,
# back to one at an uplift (so at most one block is integrated in vain).
REST_BLOCK_MAX = 4096


class RestPhase:
    """REST segments and the uplift that ends them (mixed into the run)."""

    def margins(self, xg: float, psi: float, psi_dot: float) -> tuple[float, float]:
        """Uplift margins (Eq. 9) about the left (``s = +1``) and right corners."""
        b, h, mu, gamma, j, l, g = self.args
        return (eq.uplift_margin(psi, psi_dot, xg, 1.0, b, h, mu, gamma, l, g),
                eq.uplift_margin(psi, psi_dot, xg, -1.0, b, h, mu, gamma, l, g))

    def uplift(self, side: int) -> None:
        self.events.append(Event("uplift", self.t, side=side, psi=self.psi))
        self.phase = side
        self.theta = self.theta_dot = 0.0

    def rest_segment(self, t_b: float, recover: int = 0) -> None:
        """Integrate REST up to ``t_b`` or the first uplift.

        ``recover = s``: an uplift about ``s`` whose rocking the integrator could
        not resolve (``s*theta`` never became positive: the margin dips below 0
        for a few ns); the frame stays down until the margin is positive again,
        then Event('rest').  No impact is counted."""
        xg = segment_acceleration(self.excitation, self.t, t_b)
        m_plus, m_minus = self.margins(xg(self.t), self.psi, self.psi_dot)
        if not recover and min(m_plus, m_minus) <= 0.0:  # past the uplift condition: at once
            self.uplift(1 if m_plus <= m_minus else -1)
            return
        period_end = None
        if self.after_pulse(self.t) and not self.pend and not recover:
            if self.survive(REASON_REST):  # rule 2
                return
            # t_max given: nothing moves any more, no need to integrate.
            self.samples.add_segment(self.t, t_b, np.array([]), lambda ts: np.zeros((len(ts), 4)))
            self.t = t_b
            self.point()
            return
        if self.after_pulse(self.t) and not self.decided and not recover:  # rule 3
            period = free_pendulum_period(self.psi, self.psi_dot, self.args[5], self.args[6])
            if self.t + period < t_b:
                t_b = period_end = self.t + period
        b, h, mu, gamma, j, l, g = self.args
        block_kinks = None
        if self.pend:
            def fun(t, y):
                return (y[1], eq.rest_pendulum_acceleration(y[0], xg(t), l, g))
        else:
            def fun(t, y):
                return (0.0, 0.0)

        def margin_event(side, direction=-1):
            def ev(t, y):
                return eq.uplift_margin(y[0], y[1], xg(t), side, b, h, mu, gamma, l, g)
            ev.terminal, ev.direction = True, direction
            return ev
        if self.after_pulse(self.t):
            # Free pendulum: the margin varies on its time scale only; at least 100
            # checks per small-amplitude period (the error control takes smaller steps).
            max_step = 2.0 * math.pi * math.sqrt(l / g) / 100.0
        elif self.kinks is not None:
            # Between kinks xg_ddot is linear: the margin's minima are at the kinks
            # (no pendulum) or on the pendulum's slow time scale.  One integration
            # covers a block of kinks (the margin is then checked at each kink),
            # so the cost per sample is not that of one solve_ivp call.
            k = int(np.searchsorted(self.kinks, self.t, side="right"))
            block = 1 if recover else self.rest_block
            if k < len(self.kinks):
                k_end = min(k + block, len(self.kinks)) - 1
                t_b = min(t_b, float(self.kinks[k_end]))
                block_kinks = self.kinks[k:k_end + 1]
            max_step = (2.0 * math.pi * math.sqrt(l / g) / 100.0 if self.pend and block > 1
                        else math.inf)
        else:
            t_b = min([t_b] + [p for p in self.peaks if p > self.t])
            max_step = self.st.rest_step_fraction * self.excitation.end_time
        events = ([margin_event(recover, +1)] if recover else
                  [margin_event(1), margin_event(-1)])
        while True:
            sol = self.solve(fun, t_b, [self.psi, self.psi_dot], events, max_step=max_step)
            hit = self.first_event(sol)
            t1 = float(sol.t[-1]) if hit is None else hit[1]
            if block_kinks is None:
                break
            # The margin may cross zero between two kinks inside a long step: the
            # first kink past it bounds the crossing, whose interval is then
            # integrated alone (one kink, the events resolve the root).
            i = (None if block_kinks.size < 2 else
                 self._first_kink_past_margin(sol.sol, xg, block_kinks[block_kinks < t1]))
            if i is None:
                self.rest_block = min(2 * self.rest_block, REST_BLOCK_MAX) if hit is None else 1
                break
            self.rest_block = 1
            if i > 0:
                t1, hit = float(block_kinks[i - 1]), None
                break
            t_b, block_kinks, max_step = float(block_kinks[0]), block_kinks[:1], math.inf
        side = 0
        if hit is not None:
            side = recover or (1 if hit[0] == 0 else -1)
            # The root is found to ~1e-15 s; step to the first instant where the
            # margin is <= 0 (> 0 when recovering) so the phases start cleanly.
            t1 = self._nudge(sol.sol, xg, side, t1, recover=bool(recover))
        self.samples.add_segment(self.t, t1, sol.t, lambda ts: rest_rows(sol.sol(ts)))
        self.t = t1
        self.psi, self.psi_dot = (float(v) for v in sol.sol(t1))
        if sol.status < 0:
            return
        self.point()
        if hit is not None and recover:
            self.events.append(Event("rest", t1, side=0, psi=self.psi))
        elif hit is not None:
            self.uplift(side)
        elif period_end is not None and t1 == period_end:
            self.survive(REASON_PERIOD)

    def _first_kink_past_margin(self, dense, xg, kinks: np.ndarray) -> int | None:
        """Index of the first of ``kinks`` (record samples inside a REST segment)
        where the uplift margin of either side is ``<= 0``; None if there is none."""
        if kinks.size == 0:
            return None
        psi, psi_dot = dense(kinks)
        for i, (tk, p, pd) in enumerate(zip(kinks.tolist(), psi.tolist(), psi_dot.tolist())):
            if min(self.margins(xg(tk), p, pd)) <= 0.0:
                return i
        return None

    def _nudge(self, dense, xg, side, t1, recover=False):
        b, h, mu, gamma, j, l, g = self.args
        step = max(abs(t1), 1.0) * float(np.finfo(float).eps)
        for _ in range(60):
            psi, psi_dot = dense(t1)
            m = eq.uplift_margin(psi, psi_dot, xg(t1), side, b, h, mu, gamma, l, g)
            if (m > 0.0) if recover else (m <= 0.0):
                break
            t1 += step
            step *= 2.0
        return t1
