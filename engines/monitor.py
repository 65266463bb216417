"""The run monitor every engine shares: when to stop, the verdict, impact measurement.

An engine (:class:`engines.base.Engine`) steps its world and hands sampled column angles to a
:class:`RunMonitor`, which decides when the run can stop (same overturning
criterion and survival rules as the analytic model) and turns the samples into a
:class:`~analytic.trajectory.Trajectory`.

Impact velocities are *not* read from the samples around a zero crossing: an
engine spreads an impact over several steps.  Instead the engine state at the
last sample clearly before the impact (``|theta| >= window``) is propagated with
the analytic rocking equations (the smooth dynamics between impacts, which the
engine must reproduce anyway) forward to ``theta = 0``, and the first sample
clearly after it backward to ``theta = 0``.  This is the "fit away from the
impact" of ``DESIGN.md``; without a pendulum it equals the energy-equivalent
speed at ``theta = 0``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.events import free_pendulum_period
from trilith_xval.analytic.options import check_real
from trilith_xval.analytic.sampled_events import EventRule, read_events
from trilith_xval.analytic.trajectory import Event, Trajectory, Verdict

__all__ = ["RunMonitor", "MonitorSettings", "propagate_to_zero"]


@dataclass(frozen=True)
class MonitorSettings:
    """Thresholds of the run monitor (shared by every engine).

    uplift_angle : |theta| [rad] above which the trilith counts as uplifted
        (contact compliance tilts a resting engine trilith by ~1e-6 rad); the
        uplift event is timed between samples by the rule every backend shares
        (:mod:`analytic.sampled_events`), and the mode's impacts are sign changes
        of theta outside this angle.
    impact_window : |theta| [rad] outside which a sample counts as "clearly away
        from an impact" for the velocity measurement (impacts in engines last a
        few steps, i.e. |theta| below ~1e-4 rad at dt = 1e-4 s).
    rest_angle, rest_rate : |theta| [rad] and |theta_dot| [rad/s] under which the
        trilith counts as at rest.
    rest_hold : s; how long it must stay at rest after the pulse (at least one free
        pendulum period is added when there is a pendulum).
    t_cap : s after the pulse end before an undecided run stops ('undecided').
    max_mismatch : largest ``|theta_left - theta_right|`` [in units of alpha]
        before the outcome is certain.  0.25: the lintel ties the columns
        together (engines keep them within ~1e-5 rad while the model is valid),
        so a larger mismatch means the frame the model describes no longer
        exists (columns parting, lintel thrown off): 'collapsed', never
        'overturned' or 'survived'.  Once an overturn is certain (past
        ``alpha`` after the pulse with the energy below the barrier) the
        columns may part in the fall: that is the overturn.
    max_sliding : largest pivot sliding [in units of the column width ``b``]
        while both columns stand (``|theta| < alpha``).  0.01 (6 mm at fig5):
        the engines' pivots slide < 1e-5 m at the paper's points A-D (docs/
        engine-trust.md); a slide of 1 % of ``b`` changes the model's lever arm
        by 1 %.  Beyond it: 'collapsed'.
    max_lintel_rotation : largest lintel rotation, and (3D engines) largest
        out-of-plane rotation of any body [in units of alpha] while both columns
        stand.  0.1: the model's lintel translates without rotating (it rests on
        both column tops) and every body stays in its plane; engines keep both
        within ~1e-5 rad at A-D (PyBullet's out-of-plane roll 2e-6 rad).  Beyond
        it: 'collapsed' (PyBullet's 18 m columns at lam 30 roll out of their
        plane by 0.35 rad, docs/engine-trust.md).
    max_out_of_plane : largest out-of-plane drift of any body (3D engines) [in
        trilith sizes, :func:`engines.geometry.size`] while both columns stand.
        0.1: far beyond PyBullet's ~1e-5 m of noise.  Beyond it: 'unstable' (the
        solver, not the mechanism, moved the body off its plane).
    blowup_distance : a body (column or lintel) farther than this many trilith
        sizes from its start, relative to the ground, marks the run 'unstable'.
        10: no motion of the mechanism, even a column lying down, reaches it.
    blowup_speed : a body faster than ``blowup_speed * (sqrt(g size) + peak
        ground speed)`` [m/s] (the pendulum: ``l |psi_dot|``) marks the run
        'unstable'.  20: a toppling column's tip never exceeds ``~2 sqrt(g
        size)`` relative to the ground, so 20 is a tenfold margin.

    Whether the run stops as soon as the verdict is certain is the run option
    ``early_stop`` (:class:`analytic.options.RunOptions`), not a monitor setting.
    """

    uplift_angle: float = 1e-4
    impact_window: float = 1e-3
    rest_angle: float = 1e-4
    rest_rate: float = 1e-3
    rest_hold: float = 0.5
    t_cap: float = 60.0
    max_mismatch: float = 0.25
    max_sliding: float = 0.01
    max_lintel_rotation: float = 0.1
    max_out_of_plane: float = 0.1
    blowup_distance: float = 10.0
    blowup_speed: float = 20.0

    def __post_init__(self) -> None:
        for name, lo, hi in (("uplift_angle", 0.0, 0.1), ("impact_window", 0.0, 0.5),
                             ("rest_angle", 0.0, 0.1), ("rest_rate", 0.0, 1.0),
                             ("rest_hold", 0.0, 1e4), ("t_cap", 0.0, 1e5),
                             ("max_mismatch", 0.0, 10.0), ("max_sliding", 0.0, 10.0),
                             ("max_lintel_rotation", 0.0, 10.0),
                             ("max_out_of_plane", 0.0, 10.0), ("blowup_distance", 1.0, 1e6),
                             ("blowup_speed", 1.0, 1e6)):
            check_real("MonitorSettings", name, getattr(self, name), lo, hi)


def propagate_to_zero(scene, excitation, t0: float, state0, side: int,
                      direction: int, span: float) -> tuple[float, float, float, float] | None:
    """Integrate the analytic rocking equations from ``(t0, state0)`` (theta,
    theta_dot, psi, psi_dot) on ``side`` forward (``direction=+1``) or backward
    (``-1``) until ``theta = 0``, within ``span`` seconds.

    Returns ``(t_zero, theta_dot, psi, psi_dot)`` at ``theta = 0`` or None.
    """
    b, h, mu, gamma, j, l, g = scene.model_args()

    def rhs(t, y):
        td, pd = eq.rocking_accelerations(y[0], y[1], y[2], y[3], excitation.acceleration(t),
                                          side, b, h, mu, gamma, j, l, g)
        return (y[1], td, y[3], pd)

    def crossing(t, y):
        return y[0]

    crossing.terminal = True
    sol = solve_ivp(rhs, (t0, t0 + direction * span), np.asarray(state0, dtype=float),
                    method="DOP853", rtol=1e-10, atol=1e-12, events=crossing)
    if sol.t_events[0].size == 0:
        return None
    y = sol.y_events[0][0]
    return float(sol.t_events[0][0]), float(y[1]), float(y[2]), float(y[3])


class RunMonitor:
    """Collects an engine's samples, decides when to stop, builds the Trajectory.

    Call :meth:`record` at every sample (not necessarily every step); it returns
    True when the verdict is decided.  Then call :meth:`finish`.
    """

    def __init__(self, scene, excitation, options) -> None:
        """``options``: the run's settings (:class:`engines.base.EngineSettings`:
        ``criterion``, ``t_max``, ``early_stop`` and ``monitor``)."""
        self.scene = scene
        self.excitation = excitation
        self.criterion = criterion = options.criterion
        self.t_max = t_max = options.t_max
        self.early_stop = options.early_stop
        self.verdict_only = options.verdict_only
        self.certain_at: float | None = None  # when an overturn became certain
        self.cfg = options.monitor
        self.args = scene.model_args()
        self.threshold = criterion.threshold(scene.alpha)
        self.barrier = eq.overturn_energy_barrier(*self.args[:4], self.args[6])
        self.t_end_pulse = excitation.end_time
        self.samples: list[tuple[float, ...]] = []
        self.mismatch = 0.0
        self._past_alpha = False
        self._parted = False
        self.verdict: Verdict | None = None
        self._sign = 0
        self._impacts: list[float] = []
        self._rest_since: float | None = None
        self.t_stop = (t_max if t_max is not None else self.t_end_pulse + self.cfg.t_cap)
        # Read once: record() runs every sample and Scene.alpha is a computed property.
        self._alpha = scene.alpha
        self._linked = scene.mu > 0.0
        self._mismatch_limit = self.cfg.max_mismatch * self._alpha

    # ------------------------------------------------------------------ online
    def record(self, t: float, theta_left: float, theta_right: float, theta_dot: float,
               psi: float = 0.0, psi_dot: float = 0.0) -> bool:
        theta = 0.5 * (theta_left + theta_right)
        isfinite = math.isfinite
        if not (isfinite(t) and isfinite(theta) and isfinite(theta_dot) and isfinite(psi)
                and isfinite(psi_dot)):
            self.mark_unstable(t, "non-finite state")
            return True
        self.samples.append((t, theta, theta_dot, psi, psi_dot))
        mismatch = abs(theta_left - theta_right)
        if mismatch > self.mismatch:
            self.mismatch = mismatch
        steepest = max(abs(theta), abs(theta_left), abs(theta_right))
        self._past_alpha = self._past_alpha or steepest >= self._alpha
        if self._linked and mismatch > self._mismatch_limit:
            if self.certain_at is None:
                self.mark_collapsed(t, f"columns out of step by {mismatch:.3g} rad "
                                       f"(> {self.cfg.max_mismatch:g} alpha) before the outcome "
                                       f"was certain: the frame of the model no longer exists")
                return True
            # Parted in a certain fall: the mean angle no longer describes the
            # trilith, so the rules below must not read it.
            self._parted = True
        cfg = self.cfg
        # Parted columns: a sign change of their mean angle is no impact.
        if abs(theta) > cfg.uplift_angle and not self._parted:
            sign = 1 if theta > 0 else -1
            if self._sign and sign != self._sign:
                self._impacts.append(t)
            self._sign = sign
        # One toppled column is a collapsed trilith, even if the other (parted
        # from it past alpha, see max_mismatch) keeps the mean below the threshold.
        if steepest >= self.threshold:
            mode = "after-impact" if self._impacts else "no-impact"
            what = "|theta|" if abs(theta) >= self.threshold else "a column's |theta|"
            self.verdict = Verdict("overturned", t, mode, len(self._impacts),
                                   f"{what} reached {self.threshold:.4g} rad ({self.criterion.kind})")
            return True
        if (self.certain_at is None and t >= self.t_end_pulse and not self._parted
                and self._overturn_certain(theta, theta_dot, psi, psi_dot)):
            self.certain_at = t
            # A fixed window keeps the paper's convention, as the model's fixed-window
            # runs do: overturned only if the threshold is reached before t_max.
            if self.verdict_only and self.t_max is None:
                mode = "after-impact" if self._impacts else "no-impact"
                self.verdict = Verdict("overturned", t, mode, len(self._impacts),
                                       "certain: past alpha after the pulse with the energy "
                                       "below the overturning barrier")
                return True
        # The survival rules stop a run early; without early_stop it runs to t_max.
        if self.early_stop and t >= self.t_end_pulse and not self._parted:
            if self._survived_by_energy(theta, theta_dot, psi, psi_dot):
                self.verdict = Verdict("survived", None, None, len(self._impacts),
                                       "energy below the overturning barrier after the pulse")
                return True
            if abs(theta) < cfg.rest_angle and abs(theta_dot) < cfg.rest_rate:
                if self._rest_since is None:
                    self._rest_since = t
                hold = cfg.rest_hold
                if self.scene.has_pendulum:
                    hold += free_pendulum_period(psi, psi_dot, self.args[5], self.args[6])
                if t - self._rest_since >= hold:
                    self.verdict = Verdict("survived", None, None, len(self._impacts),
                                           "at rest after the pulse")
                    return True
            else:
                self._rest_since = None
        if t >= self.t_stop:
            status = "survived" if self.t_max is not None else "undecided"
            self.verdict = Verdict(status, None, None, len(self._impacts),
                                   f"end of run at t = {t:.4g} s")
            return True
        return False

    def mark_unstable(self, t: float, reason: str) -> None:
        self.verdict = Verdict("unstable", t, None, len(self._impacts), reason)

    def mark_collapsed(self, t: float, reason: str) -> None:
        self.verdict = Verdict("collapsed", t, None, len(self._impacts), reason)

    def check_frame(self, t: float, diag: dict) -> bool:
        """Read an engine world's contact diagnostics (taken while both columns
        stand); True, with the verdict 'collapsed', when the bodies stopped being
        the model's mechanism before the outcome was certain."""
        if self.certain_at is not None or self.verdict is not None:
            return False
        cfg, b = self.cfg, self.scene.b
        slide = diag.get("pivot_sliding_max", 0.0)
        if slide > cfg.max_sliding * b:
            self.mark_collapsed(t, f"a pivot slid {slide:.3g} m (> {cfg.max_sliding:g} b) "
                                   f"while the columns stood: the model's pivots do not slide")
            return True
        roll = diag.get("out_of_plane_rotation_max", 0.0)  # 3D engines only
        if roll > cfg.max_lintel_rotation * self._alpha:
            self.mark_collapsed(t, f"a body rotated {roll:.3g} rad out of the plane "
                                   f"(> {cfg.max_lintel_rotation:g} alpha): the model is planar")
            return True
        rot = diag.get("lintel_rotation_max", 0.0)
        if rot > cfg.max_lintel_rotation * self._alpha:
            self.mark_collapsed(t, f"the lintel rotated {rot:.3g} rad "
                                   f"(> {cfg.max_lintel_rotation:g} alpha) on the columns: the "
                                   f"model's lintel translates")
            return True
        return False

    def _overturn_certain(self, theta, theta_dot, psi, psi_dot) -> bool:
        """After the pulse (inertial base, energy never increases): past ``alpha``
        with the energy below the barrier the trilith cannot return across
        ``alpha``, where the potential has its top: it falls.  Without a pendulum,
        past ``alpha`` and moving outwards is certain too: beyond ``alpha`` the
        potential only falls outwards, so nothing can turn the motion round
        (docs/overturn-maps.md; with a pendulum the swinging mass could)."""
        if abs(theta) <= self._alpha:
            return False
        if not self.scene.has_pendulum and theta * theta_dot > 0.0:
            return True
        b, h, mu, gamma, j, l, g = self.args
        side = 1 if theta > 0 else -1
        return eq.energy(theta, theta_dot, psi, psi_dot, side, b, h, mu, gamma, j, l, g) \
            < self.barrier

    def _survived_by_energy(self, theta, theta_dot, psi, psi_dot) -> bool:
        # Only inside the potential well: past alpha the trilith falls with any energy.
        if abs(theta) >= self.scene.alpha:
            return False
        b, h, mu, gamma, j, l, g = self.args
        side = 1 if (theta > 0 or (theta == 0 and theta_dot > 0)) else -1
        energy = eq.energy(theta, theta_dot, psi, psi_dot, side, b, h, mu, gamma, j, l, g)
        return energy < self.barrier

    # ----------------------------------------------------------------- offline
    def measured_impacts(self) -> list[Event]:
        """Impact events with velocities propagated to ``theta = 0`` from samples
        clearly away from the impact (see module docstring)."""
        if not self.samples:
            return []
        data = np.asarray(self.samples)
        t, theta = data[:, 0], data[:, 1]
        window = self.cfg.impact_window
        events = []
        away = np.abs(theta) >= window
        sign = np.sign(theta)
        idx_away = np.flatnonzero(away)
        for a, b_ in zip(idx_away[:-1], idx_away[1:]):
            if sign[a] == sign[b_] or sign[a] == 0:
                continue
            side_before = int(sign[a])
            span = max(4.0 * (t[b_] - t[a]), 0.05)
            pre = propagate_to_zero(self.scene, self.excitation, t[a], data[a, 1:], side_before,
                                    +1, span)
            post = propagate_to_zero(self.scene, self.excitation, t[b_], data[b_, 1:],
                                     -side_before, -1, span)
            if pre is None or post is None:
                continue
            events.append(Event("impact", 0.5 * (pre[0] + post[0]), -side_before,
                                theta_dot_before=pre[1], theta_dot_after=post[1],
                                psi=0.5 * (pre[2] + post[2]), psi_dot_before=pre[3],
                                psi_dot_after=post[3]))
        return events

    def finish(self, backend: str, settings: dict, diagnostics: dict,
               wall_time: float) -> Trajectory:
        if self.verdict is None:  # the engine stopped on its own (should not happen)
            self.verdict = Verdict("undecided", None, None, len(self._impacts), "run ended early")
        data = np.asarray(self.samples) if self.samples else np.zeros((0, 5))
        events: list[Event] = []
        # The uplift is timed by the rule every backend shares, between samples.
        uplift = read_events(data[:, 0], data[:, 1], data[:, 2], self._alpha,
                             rule=EventRule(uplift_angle=self.cfg.uplift_angle)).uplift
        if uplift is not None:
            events.append(Event("uplift", uplift.t, uplift.side))
        # A verdict-only run (a threshold probe) needs no impact velocities: the
        # propagation across each impact is skipped, the impacts are still counted.
        impacts = [] if self.verdict_only else self.measured_impacts()
        if self.verdict.overturned:
            impacts = [e for e in impacts if e.t <= self.verdict.time]
        events.extend(impacts)
        kinds = {"overturned": "overturn", "collapsed": "collapse", "unstable": "unstable"}
        if self.verdict.status in kinds:
            events.append(Event(kinds[self.verdict.status], self.verdict.time))
        events.sort(key=lambda e: e.t)
        diagnostics = dict(diagnostics)
        diagnostics.setdefault("column_mismatch_max", self.mismatch)
        diagnostics.setdefault("n_samples", len(self.samples))
        return Trajectory(backend=backend, t=data[:, 0], theta=data[:, 1], theta_dot=data[:, 2],
                          psi=data[:, 3], psi_dot=data[:, 4], events=tuple(events),
                          verdict=self.verdict, criterion=self.criterion, t_max=self.t_max,
                          settings=settings, diagnostics=diagnostics, wall_time=wall_time,
                          scene=self.scene, excitation=self.excitation)
