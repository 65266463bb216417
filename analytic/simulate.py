"""Accurate event-driven simulator of the trilith with its pendulum (backend ``"analytic"``).

Phases (the compiled fast path ``analytic/fast.py`` implements the same):

* **REST**: ``theta = theta_dot = 0``; the pendulum obeys Eq. 1
  (:func:`~analytic.equations.rest_pendulum_acceleration`).  Uplift about side
  ``s`` when :func:`~analytic.equations.uplift_margin` (Eq. 9) reaches 0 from
  above (root-found for both sides); if it is already ``<= 0`` when a REST
  segment starts, uplift at once.
* **ROCK s** (``s = +1`` left corners, Eq. 8; ``s = -1`` right corners, Eq. A.1):
  :func:`~analytic.equations.rocking_accelerations`.  Impact when ``s*theta``
  falls through 0: Eq. 19/21 (:func:`~analytic.equations.impact_velocities`),
  then ROCK ``-s``, or REST if ``|theta_dot+| < rest_velocity`` (this ends the
  Zeno accumulation of impacts).  Overturned when ``|theta|`` reaches
  ``criterion.threshold(alpha)``.

Integration segments never straddle a discontinuity of ``xg_ddot`` (the ends of
the excitation window); REST segments also stop at the pulse's ``|xg_ddot|`` peaks
(``peak_times``), and check the margin at a record's samples (integrated in
blocks of up to 4096 samples; a sample past the margin sends the interval
before it to a one-sample segment), where the margin is smallest, so a short
dip below zero is not stepped over.  An uplift whose rocking stays below the integrator's
resolution (``s*theta`` never positive: a margin dip of nanoseconds) keeps the
trilith down until the margin is positive again, then Event('rest').
Without a pendulum (``gamma = 0``) ``psi`` and
``psi_dot`` stay 0 and are not integrated.

Deciding survival exactly (``t_max = None``): after the excitation the base frame
is inertial and the energy (:func:`~analytic.equations.energy`,
:func:`~analytic.equations.rest_energy`) never increases (it only drops at
impacts), so

1. energy below :func:`~analytic.equations.overturn_energy_barrier` with
   ``|theta| < alpha`` at the end of the excitation or after any later impact or
   rest: survived (the well condition matters: past ``alpha`` the potential
   falls below the barrier, so a trilith leaning out at the pulse end can have
   little energy and still topple, e.g. Fig. 5 case D);
2. at REST after the excitation without a pendulum: survived;
3. at REST after the excitation with a swinging pendulum: the free pendulum is
   periodic (:func:`~analytic.events.free_pendulum_period`), so no uplift during
   one full period means none ever: survived;
4. otherwise continue; at ``end_time + t_cap`` the verdict is 'undecided'.

With a fixed ``t_max`` the run always goes on to ``t_max`` (unless it overturns)
and a run that has not overturned is 'survived' (the paper's fixed-window
convention); ``Verdict.reason`` says whether an exact rule had decided it.
See ``docs/overturning.md``.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp

from . import equations as eq
from .events import Settings, SampleBuffer, excitation_window, return_time, segment_acceleration
from .excitation import check_excitation
from .parameters import Scene
from .reactions import validity_diagnostics
from .rest_phase import RestPhase
from .trajectory import Event, Trajectory, Verdict

__all__ = ["NAME", "Settings", "simulate", "version"]

NAME = "analytic"
CAPABILITIES = frozenset({"initial_tilt", "trajectory"})
REASON_BARRIER = "energy below the overturning barrier after the pulse"
REASON_WINDOW = "t_max reached without overturning (fixed window)"
REASON_CAP = "t_cap reached after the pulse before the outcome was certain"


def version() -> str:
    """Backend version string carried into reports."""
    return f"analytic-scipy-{scipy.__version__}"


class _Run(RestPhase):
    """Mutable state of one run (the phase machine of the module docstring); its
    REST phase is :class:`~analytic.rest_phase.RestPhase`."""

    def __init__(self, scene: Scene, excitation, st: Settings) -> None:
        self.st = st
        self.args = scene.model_args()
        b, h, mu, gamma, j, l, g = self.args
        self.pend = gamma > 0.0
        self.alpha = scene.alpha
        self.threshold = st.criterion.threshold(scene.alpha)
        self.barrier = eq.overturn_energy_barrier(b, h, mu, gamma, g)
        self.excitation = excitation
        self.t_on, self.t_off = excitation_window(excitation)
        self.t_stop = st.t_max if st.t_max is not None else self.t_off + st.t_cap
        self.breaks = sorted({x for x in (self.t_on, self.t_off) if 0.0 < x < self.t_stop})
        # A record's xg_ddot has kinks at its samples, where the (then piecewise
        # linear) margin has its minima: REST checks the margin at every sample.
        self.kinks = excitation.kink_times
        self.rest_block = 1  # kinks per REST integration, grows while at rest
        # A pulse's |xg_ddot| extrema, where the margin has its minima: REST
        # segments stop there too, so a short dip below zero cannot hide inside
        # one step (exact without a pendulum, whose margin depends on t only).
        self.peaks = list(excitation.peak_times)
        self.t = 0.0
        self.theta, self.theta_dot = st.theta0, st.theta_dot0
        self.psi, self.psi_dot = st.psi0, st.psi_dot0
        lead = self.theta if self.theta != 0.0 else self.theta_dot
        self.phase = 0 if lead == 0.0 else (1 if lead > 0.0 else -1)
        self.events: list[Event] = []
        self.samples = SampleBuffer(st.sample_dt)
        self.n_impacts = 0
        self.verdict: Verdict | None = None
        self.decided = ""  # exact rule that decided survival (kept going when t_max is set)
        self.diag = {"n_steps": 0, "n_rhs_evals": 0, "n_segments": 0}

    # --- helpers ---------------------------------------------------------------
    def after_pulse(self, t: float) -> bool:
        return t >= self.t_off

    def current_energy(self) -> float:
        b, h, mu, gamma, j, l, g = self.args
        if self.phase == 0:
            return eq.rest_energy(self.psi, self.psi_dot, gamma, l, g)
        return eq.energy(self.theta, self.theta_dot, self.psi, self.psi_dot, self.phase,
                         *self.args)

    def survive(self, reason: str) -> bool:
        """Record an exact survival rule; returns True when the run must stop."""
        if not self.decided:
            self.decided = reason
        if self.st.t_max is None and self.st.early_stop:
            self.verdict = Verdict("survived", None, None, self.n_impacts, reason)
            return True
        return False

    def check_barrier(self) -> bool:
        """Rule 1 (only after the excitation, and only inside the potential well
        ``|theta| < alpha``: past alpha the potential is below the barrier)."""
        if (self.after_pulse(self.t) and abs(self.theta) < self.alpha
                and self.current_energy() < self.barrier):
            return self.survive(REASON_BARRIER)
        return False

    def point(self) -> None:
        self.samples.add_point(self.t, self.theta, self.theta_dot, self.psi, self.psi_dot)

    def solve(self, fun, t_b, y0, events, max_step=np.inf, first_step=None):
        sol = solve_ivp(fun, (self.t, t_b), y0, method=self.st.method, rtol=self.st.rtol,
                        atol=self.st.atol, events=events, dense_output=True,
                        max_step=max_step, first_step=first_step)
        self.diag["n_segments"] += 1
        self.diag["n_steps"] += len(sol.t) - 1
        self.diag["n_rhs_evals"] += int(sol.nfev)
        if sol.status < 0:
            self.events.append(Event("unstable", self.t))
            self.verdict = Verdict("unstable", self.t, None, self.n_impacts,
                                   f"integrator failed: {sol.message}")
        return sol

    @staticmethod
    def first_event(sol) -> tuple[int, float] | None:
        if sol.status != 1:
            return None
        hits = [(float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te)]
        t_hit, index = min(hits)
        return index, t_hit

    # --- phases ----------------------------------------------------------------
    def rock_segment(self, t_b: float) -> None:
        """Integrate ROCK ``self.phase`` up to ``t_b``, an impact or overturning."""
        s = self.phase
        xg = segment_acceleration(self.excitation, self.t, t_b)
        args = self.args
        if self.pend:
            def fun(t, y):
                a, c = eq.rocking_accelerations(y[0], y[1], y[2], y[3], xg(t), s, *args)
                return (y[1], a, y[3], c)
            y0 = [self.theta, self.theta_dot, self.psi, self.psi_dot]
        else:
            def fun(t, y):
                return (y[1], eq.rocking_accelerations(y[0], y[1], 0.0, 0.0, xg(t), s, *args)[0])
            y0 = [self.theta, self.theta_dot]

        def impact(t, y):
            return s * y[0]
        impact.terminal, impact.direction = True, -1
        thr = self.threshold

        def overturn(t, y):
            return s * y[0] - thr
        overturn.terminal, overturn.direction = True, 1
        # Starting at theta = 0 moving out but pulled back: the excursion lasts
        # tau = 2|v/a|; a first step well inside it keeps the impact root bracketed.
        first = None
        a0 = fun(self.t, y0)[1]
        if self.theta == 0.0 and s * self.theta_dot > 0.0 and s * a0 < 0.0:
            tau = 2.0 * abs(self.theta_dot / a0)
            first = min(tau / 8.0, t_b - self.t)
        sol = self.solve(fun, t_b, y0, [impact, overturn], first_step=first)
        hit = self.first_event(sol)
        if hit is not None and hit[0] == 0 and hit[1] <= self.t:
            # s*theta is exactly 0 at the start, so the root finder returns the
            # start: look inside the step for the real return through 0.
            t_ret = return_time(sol.sol.interpolants[-1], s)
            if t_ret is None:  # excursion below resolution (a margin dip of ~ns)
                self.phase, self.theta, self.theta_dot = 0, 0.0, 0.0
                self.rest_segment(t_b, recover=s)
                return
            hit = (0, t_ret)
        t1 = float(sol.t[-1]) if hit is None else hit[1]
        pend = self.pend

        def rows(ts):
            y = sol.sol(ts)
            if pend:
                return y.T
            zero = np.zeros(len(ts))
            return np.column_stack([y[0], y[1], zero, zero])
        self.samples.add_segment(self.t, t1, sol.t, rows)
        y1 = sol.sol(t1) if hit is not None else sol.y[:, -1]
        self.t = t1
        self.theta, self.theta_dot = float(y1[0]), float(y1[1])
        if pend:
            self.psi, self.psi_dot = float(y1[2]), float(y1[3])
        if sol.status < 0:
            return
        if hit is None:
            self.point()
        elif hit[0] == 1:
            self.theta = s * thr
            self.point()
            mode = "no-impact" if self.n_impacts == 0 else "after-impact"
            self.events.append(Event("overturn", t1, side=s, psi=self.psi))
            self.verdict = Verdict("overturned", t1, mode, self.n_impacts,
                                   f"|theta| reached {thr:.6g} rad ({self.st.criterion.kind})")
        else:
            self.theta = 0.0
            self.point()
            self.impact()

    def impact(self) -> None:
        s = self.phase
        b, h, mu, gamma, j, l, g = self.args
        td_minus, pd_minus = self.theta_dot, self.psi_dot
        td_plus, pd_plus = eq.impact_velocities(td_minus, self.psi, pd_minus, -s,
                                                b, h, mu, gamma, j, l,
                                                self.st.restitution_factor)
        self.n_impacts += 1
        self.events.append(Event("impact", self.t, side=-s, theta_dot_before=td_minus,
                                 theta_dot_after=td_plus, psi=self.psi,
                                 psi_dot_before=pd_minus, psi_dot_after=pd_plus))
        self.psi_dot = pd_plus if self.pend else 0.0
        if abs(td_plus) < self.st.rest_velocity:
            self.theta_dot = 0.0
            self.phase = 0
            self.events.append(Event("rest", self.t, side=0, psi=self.psi))
        else:
            self.theta_dot = td_plus
            self.phase = -s
        self.point()
        self.check_barrier()

    def run(self) -> None:
        self.point()
        checked_end = False
        while self.verdict is None:
            if len(self.events) > self.st.max_events:
                self.verdict = Verdict("unstable", self.t, None, self.n_impacts,
                                       f"more than max_events={self.st.max_events} events")
                break
            if not checked_end and self.after_pulse(self.t):
                checked_end = True
                if self.check_barrier():
                    break
            if self.t >= self.t_stop:
                if self.st.t_max is not None or self.decided:
                    until = "t_max" if self.st.t_max is not None else "t_cap (early_stop off)"
                    reason = f"{self.decided}; ran to {until}" if self.decided else REASON_WINDOW
                    self.verdict = Verdict("survived", None, None, self.n_impacts, reason)
                else:
                    self.verdict = Verdict("undecided", None, None, self.n_impacts, REASON_CAP)
                break
            t_b = min([x for x in self.breaks if x > self.t] + [self.t_stop])
            if self.phase == 0:
                self.rest_segment(t_b)
            else:
                self.rock_segment(t_b)


def simulate(scene: Scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Simulate ``scene`` under ``excitation`` with the phase machine of this module.

    Parameters
    ----------
    scene : Scene
    excitation : Excitation
        A :class:`~analytic.excitation.Excitation` (a pulse, a record, a user's
        own subclass); ``TypeError`` otherwise.
    settings : Settings, optional

    Returns
    -------
    Trajectory
        Samples on the ``sample_dt`` grid plus every event instant (an impact
        gives two samples at the same time, before and after), the events
        (uplift, impact, rest, overturn), the verdict and diagnostics
        (``n_steps``, ``n_rhs_evals``, ``n_segments``; and, from the samples, the
        contact checks of :func:`~analytic.reactions.validity_diagnostics` at the
        ground and at the lintel: ``min_vertical_reaction``, ``max_friction_demand``,
        ``min_lintel_normal``, ``max_lintel_friction_demand``, ``model_valid``, ...).
    """
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be an analytic.Scene, got {type(scene).__name__}")
    check_excitation(excitation)
    st = Settings() if settings is None else settings
    if not isinstance(st, Settings):
        raise ValueError(f"settings must be analytic.simulate.Settings, got {type(st).__name__}")
    if abs(st.theta0) >= st.criterion.threshold(scene.alpha):
        raise ValueError(f"theta0 must be in (-{st.criterion.threshold(scene.alpha):.6g}, "
                         f"{st.criterion.threshold(scene.alpha):.6g}) rad (below the overturn "
                         f"threshold), got {st.theta0!r}")
    if not scene.has_pendulum and (st.psi0 != 0.0 or st.psi_dot0 != 0.0):
        raise ValueError("psi0 and psi_dot0 must be 0 without a pendulum (gamma = 0)")
    start = time.perf_counter()
    run = _Run(scene, excitation, st)
    run.run()
    t, theta, theta_dot, psi, psi_dot = run.samples.arrays()
    wall = time.perf_counter() - start  # the simulation proper, as before the checks below
    diagnostics = dict(run.diag)
    if all(np.all(np.isfinite(a)) for a in (theta, theta_dot, psi, psi_dot)):
        # Diagnostics only (docs/model.md, "Ground reaction"): nothing above depends on them.
        diagnostics.update(validity_diagnostics(t, theta, theta_dot, psi, psi_dot,
                                                excitation, scene.model_args(),
                                                scene.alpha, run.verdict.overturned))
    return Trajectory(
        backend=NAME, t=t, theta=theta, theta_dot=theta_dot, psi=psi, psi_dot=psi_dot,
        events=tuple(run.events), verdict=run.verdict, criterion=st.criterion,
        t_max=st.t_max, settings=dataclasses.asdict(st), diagnostics=diagnostics,
        wall_time=wall, scene=scene, excitation=excitation)
