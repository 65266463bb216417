"""Uplift, impacts and the last rise past alpha read from sampled ``theta(t)`` by one
rule, for every backend.

The model finds its events exactly (root-found contact conditions, Eqs. 9-10, and
Zeno chatter resolved down to ``rest_velocity``); an engine knows its state only at
its samples (every 8 ms by default) and spreads an impact over a few steps.  Times
and counts that are printed side by side, or compared, are therefore read from each
run's samples ``(t, theta, theta_dot)`` by the rule below, the same for the model and
every engine; the model's exact events stay in ``Trajectory.events``.

* **uplift**: the first time ``|theta|`` reaches ``uplift_angle`` (1e-4 rad), linear
  between the two samples around it.  Contact compliance tilts a resting engine
  trilith by ~1e-6 rad, so the model's exact lift-off (``|theta| > 0``) has no engine
  counterpart; 1e-4 rad is 5e-4 alpha on the Fig. 5 trilith.
* **impact**: ``theta`` changes sign between two samples (samples exactly at 0 are
  skipped) and the larger ``|theta_dot|`` of the samples from the last non-zero one
  before to the first non-zero one after is at least ``impact_speed`` (1e-2 rad/s);
  the time is where the straight line between those two samples crosses 0 (a
  sample exactly at 0 is the time; a run that ends there, moving across, ends with
  that impact).  At
  1e-2 rad/s the Fig. 5 trilith's free excursion after an impact lasts ~25 ms (three
  engine samples) and rises ~6e-5 rad (its free deceleration at ``theta = 0+`` is
  0.86 rad/s^2 with the pendulum, 0.76 without): slower chatter, which the model
  resolves and an engine merges within a step or a sample, is counted by neither.
* **exceeds_alpha** (an overturned verdict only): the last time before the verdict
  that ``|theta|`` rises through ``alpha``, linear between samples.  Past it the
  trilith never came back, so this is where the potential's top was crossed for good
  (with the energy above the barrier).  It is not the overturn time: that is the
  verdict's own time (``Trajectory.overturn_time``: the topple angle reached, or the
  moment the fall became certain), which depends on each backend's stop rule.

Every time carries its **resolution**: the crossing lies between the two samples
that bracket it, so the interpolated time is off by at most its distance to the
farther of them (at most the sample interval; 0 for a sample exactly on it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["EventRule", "TimedEvent", "SampledEvents", "read_events", "events_of"]


@dataclass(frozen=True)
class EventRule:
    """The shared rule's two thresholds (module docstring).

    uplift_angle : |theta| [rad] of the uplift, in (0, 0.1].  Default 1e-4.
    impact_speed : smallest |theta_dot| [rad/s] at a sign change of theta that
        counts as an impact, in [0, 10].  Default 1e-2.
    """

    uplift_angle: float = 1e-4
    impact_speed: float = 1e-2

    def __post_init__(self) -> None:
        for name, lo, hi, lo_open in (("uplift_angle", 0.0, 0.1, True),
                                      ("impact_speed", 0.0, 10.0, False)):
            value = getattr(self, name)
            if (isinstance(value, bool) or not isinstance(value, (int, float))
                    or not math.isfinite(value) or value > hi
                    or (value <= lo if lo_open else value < lo)):
                left = "(" if lo_open else "["
                raise ValueError(f"EventRule: {name} must be in {left}{lo:g}, {hi:g}], "
                                 f"got {value!r}")


@dataclass(frozen=True)
class TimedEvent:
    """One event read by the rule: ``t`` [s] within ``+- resolution`` [s].

    ``side``: for an impact the sign of theta after it (+1 left corners); for uplift
    and exceeds_alpha the side rocked on.  ``speed``: the |theta_dot| [rad/s] that
    qualified an impact (NaN otherwise).
    """

    kind: str
    t: float
    resolution: float
    side: int = 0
    speed: float = math.nan

    def to_dict(self) -> dict:
        out = {"kind": self.kind, "t": self.t, "resolution": self.resolution, "side": self.side}
        if not math.isnan(self.speed):
            out["speed"] = self.speed
        return out

    def text(self, digits: int = 4) -> str:
        """``'0.0252 s +- 0.0048 s'``."""
        return f"{self.t:.{digits}f} s +- {self.resolution:.{digits}f} s"


@dataclass(frozen=True)
class SampledEvents:
    """What the rule reads from one run: uplift and the last rise past alpha
    (``exceeds_alpha``; each None when absent), the impacts."""

    rule: EventRule
    uplift: TimedEvent | None
    impacts: tuple[TimedEvent, ...]
    exceeds_alpha: TimedEvent | None

    @property
    def n_impacts(self) -> int:
        return len(self.impacts)

    def impacts_before(self, t: float) -> tuple[TimedEvent, ...]:
        return tuple(e for e in self.impacts if e.t <= t)

    def to_dict(self) -> dict:
        return {"rule": {"uplift_angle": self.rule.uplift_angle,
                         "impact_speed": self.rule.impact_speed},
                "uplift": None if self.uplift is None else self.uplift.to_dict(),
                "n_impacts": self.n_impacts,
                "impacts": [e.to_dict() for e in self.impacts],
                "exceeds_alpha": (None if self.exceeds_alpha is None
                                  else self.exceeds_alpha.to_dict())}


def _crossing(t0: float, t1: float, y0: float, y1: float, level: float) -> tuple[float, float]:
    """Where the line through ``(t0, y0)``, ``(t1, y1)`` reaches ``level``, and the
    distance to the farther end of ``[t0, t1]`` (the crossing is inside)."""
    if y1 == level or y1 == y0:
        return float(t1), 0.0 if y1 == level else float(t1 - t0)
    if y0 == level:
        tc = t0
    else:
        tc = t0 + (level - y0) / (y1 - y0) * (t1 - t0)
        tc = min(max(tc, t0), t1)
    return float(tc), float(max(tc - t0, t1 - tc))


def _uplift(t, theta, rule: EventRule) -> TimedEvent | None:
    mag = np.abs(theta)
    idx = np.flatnonzero(mag >= rule.uplift_angle)
    if not idx.size:
        return None
    i = int(idx[0])
    side = 1 if theta[i] > 0 else -1
    if i == 0:
        return TimedEvent("uplift", float(t[0]), 0.0, side)
    tc, res = _crossing(t[i - 1], t[i], mag[i - 1], mag[i], rule.uplift_angle)
    return TimedEvent("uplift", tc, res, side)


def _impacts(t, theta, theta_dot, rule: EventRule, t_stop: float) -> tuple[TimedEvent, ...]:
    nonzero = np.flatnonzero(theta != 0.0)
    if not nonzero.size:
        return ()
    a, b = nonzero[:-1], nonzero[1:]
    flips = np.flatnonzero(np.sign(theta[a]) != np.sign(theta[b]))
    events = []
    for k in flips:
        i, j = int(a[k]), int(b[k])
        if t[j] > t_stop:
            break
        speed = float(np.max(np.abs(theta_dot[i:j + 1])))
        if speed < rule.impact_speed:
            continue
        if j > i + 1:  # samples exactly at theta = 0 (the model writes one at each impact)
            zero = int(i + 1)
            tc, res = float(t[zero]), 0.0
        else:
            tc, res = _crossing(t[i], t[j], theta[i], theta[j], 0.0)
        events.append(TimedEvent("impact", tc, res, 1 if theta[j] > 0 else -1, speed))
    last = int(nonzero[-1])
    end = theta.size - 1
    # A run that stops on theta = 0 moving across it (the model writes an impact
    # instant and may stop there) ends with that impact.
    if (last < end and t[last + 1] <= t_stop and theta_dot[end] * theta[last] < 0.0
            and max(abs(theta_dot[last]), abs(theta_dot[end])) >= rule.impact_speed):
        events.append(TimedEvent("impact", float(t[last + 1]), 0.0,
                                 -1 if theta[last] > 0 else 1,
                                 float(np.max(np.abs(theta_dot[last:])))))
    return tuple(events)


def _exceeds_alpha(t, theta, alpha: float, t_verdict: float) -> TimedEvent | None:
    mag = np.abs(theta)
    upto = np.flatnonzero(t <= t_verdict)
    if not upto.size:
        return None
    n = int(upto[-1]) + 1
    below = np.flatnonzero(mag[:n] < alpha)
    if not below.size or int(below[-1]) == n - 1:
        return None  # never below alpha, or not past it at the verdict
    i = int(below[-1])
    tc, res = _crossing(t[i], t[i + 1], mag[i], mag[i + 1], alpha)
    return TimedEvent("exceeds_alpha", tc, res, 1 if theta[i + 1] > 0 else -1)


def read_events(t, theta, theta_dot, alpha: float, overturned_at: float | None = None,
                rule: EventRule | None = None) -> SampledEvents:
    """The rule's events of one run (module docstring).

    Parameters
    ----------
    t, theta, theta_dot : array_like
        The run's samples [s, rad, rad/s], times non-decreasing (two samples at one
        instant, as the model writes at an impact, are allowed).
    alpha : float
        The scene's slenderness angle [rad], > 0.
    overturned_at : float or None
        The verdict's time when the run overturned (None otherwise): impacts are
        counted up to it and the last rise past alpha is read before it.
    rule : EventRule or None
        Default :class:`EventRule()`.
    """
    rule = EventRule() if rule is None else rule
    t = np.asarray(t, dtype=float)
    theta = np.asarray(theta, dtype=float)
    theta_dot = np.asarray(theta_dot, dtype=float)
    if not (t.shape == theta.shape == theta_dot.shape and t.ndim == 1):
        raise ValueError("t, theta and theta_dot must be 1-D arrays of one length")
    if t.size and np.any(np.diff(t) < 0.0):
        raise ValueError("sample times must be non-decreasing")
    if not (math.isfinite(alpha) and 0.0 < alpha <= math.pi / 2):
        raise ValueError(f"alpha must be in (0, pi/2] rad, got {alpha!r}")
    if not t.size:
        return SampledEvents(rule, None, (), None)
    t_stop = math.inf if overturned_at is None else float(overturned_at)
    past = None if overturned_at is None else _exceeds_alpha(t, theta, alpha, t_stop)
    return SampledEvents(rule, _uplift(t, theta, rule),
                         _impacts(t, theta, theta_dot, rule, t_stop), past)


def events_of(traj, alpha: float | None = None, rule: EventRule | None = None) -> SampledEvents:
    """:func:`read_events` of a :class:`~analytic.trajectory.Trajectory` (``alpha``
    defaults to its scene's)."""
    if alpha is None:
        if traj.scene is None:
            raise ValueError("alpha must be given when the trajectory has no scene")
        alpha = traj.scene.alpha
    return read_events(traj.t, traj.theta, traj.theta_dot, alpha,
                       traj.verdict.time if traj.verdict.overturned else None, rule)
