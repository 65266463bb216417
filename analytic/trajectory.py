"""The result type every backend returns, and the overturning criterion they share.

Sign conventions are the analytic model's (Eq. 5): ``theta > 0`` is rocking about
the *left* base corners (the columns lean to the left, counter-clockwise),
``theta < 0`` about the right ones; ``psi`` is the pendulum's absolute angle from
the downward vertical, counter-clockwise positive.  Radians, seconds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Event", "Verdict", "Trajectory", "OverturnCriterion", "CRITERIA",
           "STATUSES", "MODES"]

CRITERIA = ("topple", "alpha")
STATUSES = ("overturned", "survived", "collapsed", "unstable", "undecided")
MODES = ("no-impact", "after-impact")
EVENT_KINDS = ("uplift", "impact", "rest", "overturn", "collapse", "unstable")

# Default topple angle: just short of pi/2, where a column lies on its side.
# Engines with compliant contacts cannot reach pi/2 exactly; 1.5 rad (86 deg) is
# far past the point of no return for every lam >= 1 (alpha <= 45 deg).
DEFAULT_TOPPLE_ANGLE = 1.5


@dataclass(frozen=True)
class OverturnCriterion:
    """How a backend decides that the trilith has overturned.

    ``kind='topple'`` (default): overturned when ``|theta|`` reaches
    ``topple_angle`` (1.5 rad), i.e. the columns have fallen; a run that passes
    the static instability angle ``alpha`` and comes back is *not* overturned.
    ``kind='alpha'``: overturned as soon as ``|theta| >= alpha`` (the
    conservative, paper-style threshold).  See ``docs/overturning.md``.
    """

    kind: str = "topple"
    topple_angle: float = DEFAULT_TOPPLE_ANGLE

    def __post_init__(self) -> None:
        if self.kind not in CRITERIA:
            raise ValueError(f"criterion must be one of {CRITERIA}, got {self.kind!r}")
        if not (math.isfinite(self.topple_angle) and 0.0 < self.topple_angle <= math.pi / 2):
            raise ValueError(f"topple_angle must be in (0, pi/2] rad, got {self.topple_angle!r}")

    def threshold(self, alpha: float) -> float:
        """The ``|theta|`` [rad] at which the run is declared overturned."""
        return alpha if self.kind == "alpha" else max(self.topple_angle, alpha)

    def describe(self) -> dict:
        return {"kind": self.kind, "topple_angle": self.topple_angle}


@dataclass(frozen=True)
class Event:
    """A discrete event of a run.

    ``kind``: 'uplift', 'impact', 'rest', 'overturn' or 'unstable'.
    For impacts ``theta_dot_before/after`` and ``psi_dot_before/after`` are the
    velocities just before and after; ``psi`` is the pendulum angle at the event.
    ``side`` is +1 (left corners) or -1 (right corners) for the phase *entered*.
    """

    kind: str
    t: float
    side: int = 0
    theta_dot_before: float = math.nan
    theta_dot_after: float = math.nan
    psi: float = math.nan
    psi_dot_before: float = math.nan
    psi_dot_after: float = math.nan

    @property
    def velocity_ratio(self) -> float:
        """``theta_dot_after / theta_dot_before`` (impacts only)."""
        if self.kind != "impact" or self.theta_dot_before == 0.0:
            return math.nan
        return self.theta_dot_after / self.theta_dot_before

    def to_dict(self) -> dict:
        out = {"kind": self.kind, "t": self.t, "side": self.side}
        for name in ("theta_dot_before", "theta_dot_after", "psi", "psi_dot_before",
                     "psi_dot_after"):
            value = getattr(self, name)
            if not math.isnan(value):
                out[name] = value
        return out


@dataclass(frozen=True)
class Verdict:
    """Outcome of a run.

    ``status``: 'overturned', 'survived', 'collapsed' (an engine's bodies stopped
    being the model's mechanism before the outcome was certain: columns out of
    step, a pivot sliding, the lintel rotating on the columns; ``reason`` names
    the diagnostic and its value), 'unstable' (the numerics blew up) or
    'undecided' (``t_max`` reached before the outcome was certain).  Only
    'overturned' counts as overturning.
    ``mode``: 'no-impact' or 'after-impact' when overturned, else None.
    """

    status: str
    time: float | None = None
    mode: str | None = None
    n_impacts: int = 0
    reason: str = ""

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {self.status!r}")
        if self.mode is not None and self.mode not in MODES:
            raise ValueError(f"mode must be one of {MODES} or None, got {self.mode!r}")

    @property
    def overturned(self) -> bool:
        return self.status == "overturned"


@dataclass
class Trajectory:
    """What every backend returns: samples, events, verdict, diagnostics.

    Arrays have equal length.  Without a pendulum ``psi`` and ``psi_dot`` are
    zeros.  ``settings`` is a plain dict of the backend settings that produced
    it (including ``criterion`` and ``t_max``) so a result is self-describing.
    """

    backend: str
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    psi: np.ndarray
    psi_dot: np.ndarray
    events: tuple[Event, ...]
    verdict: Verdict
    criterion: OverturnCriterion
    t_max: float | None
    settings: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    wall_time: float = math.nan
    scene: object | None = None
    excitation: object | None = None

    def __post_init__(self) -> None:
        n = len(self.t)
        for name in ("theta", "theta_dot", "psi", "psi_dot"):
            arr = np.asarray(getattr(self, name), dtype=float)
            if arr.shape != (n,):
                raise ValueError(f"{name} has shape {arr.shape}, expected ({n},)")
            setattr(self, name, arr)
        self.t = np.asarray(self.t, dtype=float)
        self.events = tuple(self.events)

    # --- convenience ----------------------------------------------------------
    @property
    def overturned(self) -> bool:
        return self.verdict.overturned

    @property
    def impacts(self) -> tuple[Event, ...]:
        return tuple(e for e in self.events if e.kind == "impact")

    @property
    def n_impacts(self) -> int:
        return len(self.impacts)

    @property
    def uplift_time(self) -> float | None:
        for e in self.events:
            if e.kind == "uplift":
                return e.t
        return None

    @property
    def overturn_time(self) -> float | None:
        """When the run overturned [s]: the verdict's time (the criterion met,
        |theta| at the topple angle or alpha, or the fall certain), None when it did
        not overturn.  The last rise of |theta| past alpha, earlier, is
        ``sampled_events().exceeds_alpha`` (``exceeds_alpha_time`` in the JSON)."""
        return self.verdict.time if self.verdict.overturned else None

    @property
    def max_abs_theta(self) -> float:
        return float(np.max(np.abs(self.theta))) if len(self.theta) else 0.0

    def sampled_events(self, rule=None):
        """Uplift, impacts and overturn read from the samples by the rule every
        backend shares (:func:`analytic.sampled_events.events_of`); the backend's
        own (for the model: exact) events stay in :attr:`events`."""
        from .sampled_events import events_of
        return events_of(self, rule=rule)

    def summary(self) -> dict:
        """The result part of ``trilith simulate --json``.

        ``uplift_time``, ``n_impacts`` and ``exceeds_alpha_time`` (the last rise
        of ``|theta|`` through alpha, past which the trilith never came back) are
        read by the shared rule of :mod:`analytic.sampled_events`, each time with
        its resolution [s], so that every backend's are comparable;
        ``verdict_time`` is when the backend's criterion was met, and
        ``overturn_time`` is it for an overturned run (None otherwise), as
        :attr:`overturn_time`; ``events`` are the backend's own events.

        ``engine`` names the backend (the key every JSON document uses); wall
        and CPU times (``wall_time``, and the engines' ``diagnostics['wall_time']``
        and ``['cpu_time']``) sit in the last key, ``timings``, so that
        everything before it is identical between reruns.
        """
        diagnostics = dict(self.diagnostics)
        timings = {"wall_time": self.wall_time}
        if "wall_time" in diagnostics:
            timings["engine_wall_time"] = diagnostics.pop("wall_time")
        if "cpu_time" in diagnostics:
            timings["engine_cpu_time"] = diagnostics.pop("cpu_time")
        read = self.sampled_events() if self.scene is not None else None
        return {
            "engine": self.backend,
            "status": self.verdict.status,
            "overturned": self.overturned,
            "mode": self.verdict.mode,
            "verdict_time": self.verdict.time,
            "n_impacts": None if read is None else read.n_impacts,
            "uplift_time": None if read is None or read.uplift is None else read.uplift.t,
            "uplift_resolution": (None if read is None or read.uplift is None
                                  else read.uplift.resolution),
            "overturn_time": self.overturn_time,
            "exceeds_alpha_time": (None if read is None or read.exceeds_alpha is None
                                   else read.exceeds_alpha.t),
            "exceeds_alpha_resolution": (None if read is None or read.exceeds_alpha is None
                                         else read.exceeds_alpha.resolution),
            "sampled_events": None if read is None else read.to_dict(),
            "max_abs_theta": self.max_abs_theta,
            "criterion": self.criterion.kind,
            "topple_angle": self.criterion.topple_angle,
            "t_max": self.t_max,
            "t_end": float(self.t[-1]) if len(self.t) else 0.0,
            "reason": self.verdict.reason,
            "events": [e.to_dict() for e in self.events],
            "settings": self.settings,
            "diagnostics": diagnostics,
            "timings": timings,
        }

    def to_csv(self, path) -> None:
        data = np.column_stack([self.t, self.theta, self.theta_dot, self.psi, self.psi_dot])
        np.savetxt(path, data, delimiter=",", header="t,theta,theta_dot,psi,psi_dot",
                   comments="")
