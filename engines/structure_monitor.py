"""The verdict of a run of a scene the model does not cover (:mod:`analytic.kinds`).

The parametric trilith is judged by :class:`engines.monitor.RunMonitor` with the
model's own rules (energy barrier, mean column angle).  A column of drums,
unequal columns or a block on a block has no model, so its run is judged from
its bodies' poses by geometry alone, the same for every engine:

* **overturned**: a body that is not a lintel (a drum, a column, a block)
  rotated beyond the run criterion's threshold at its *own* overturning angle
  ``alpha_i = atan(b_i/h_i)`` (``criterion.threshold(alpha_i)``: with the
  default 'topple' criterion it has fallen, ``|angle| >= max(1.5 rad,
  alpha_i)``; with 'alpha' it passed ``alpha_i``), or *fell*: its centre
  dropped more than half its smaller side below its rest height (a drum
  slid or was thrown off the one below);
* **collapsed**: the lintel fell off: its centre dropped more than its own
  thickness below its rest height (it no longer rests on the column tops), or
  it rotated beyond its own ``criterion.threshold(alpha)``;
* **unstable**: a non-finite state, a body farther than ``blowup_distance``
  structure sizes from its start or faster than ``blowup_speed (sqrt(g size)
  + peak ground speed)`` (the thresholds of
  :class:`~engines.monitor.MonitorSettings`);
* **survived**: after the pulse every body at rest (``|angle| <= rest_angle``
  and every speed under ``rest_rate`` times the body's half diagonal, held
  ``rest_hold`` s) with ``early_stop``, or the end of the run (``t_max``, else
  the pulse's end plus ``t_cap``: 'undecided').

The Trajectory's ``theta`` is the mean rotation of the bodies standing on the
ground (for the parametric trilith that is the columns' ``theta``); ``psi`` the
bob's angle if any.  Impacts are counted as sign changes of that mean outside
``uplift_angle``, with no velocities (the impact rule of Eq. 19-20 is the
model's).
"""
from __future__ import annotations

import math

import numpy as np

from trilith_xval.analytic.trajectory import Event, Trajectory, Verdict

from .diagnostics import peak_ground_speed

__all__ = ["StructureMonitor"]


class StructureMonitor:
    """Judges the samples of one run of a :class:`~engines.geometry.Structure`.

    Parameters
    ----------
    scene : analytic.kinds.KindScene
    structure : engines.geometry.Structure
    excitation : Excitation
    options : EngineSettings
        ``criterion``, ``t_max``, ``early_stop`` and ``monitor`` are read.
    """

    def __init__(self, scene, structure, excitation, options) -> None:
        self.scene, self.structure, self.excitation = scene, structure, excitation
        self.cfg = cfg = options.monitor
        self.criterion, self.t_max, self.early_stop = (options.criterion, options.t_max,
                                                       options.early_stop)
        self.t_end_pulse = excitation.end_time
        self.t_stop = options.t_max if options.t_max is not None else (
            excitation.end_time + cfg.t_cap)
        boxes = structure.bodies
        self.limits = [options.criterion.threshold(box.alpha) for box in boxes]
        self.drops = [box.h if box.name == "lintel" else 0.5 * min(box.b, box.h)
                      for box in boxes]
        on_ground = {upper for upper, lower in structure.supports if lower == "ground"}
        self.ground_index = [k for k, box in enumerate(boxes) if box.name in on_ground]
        self.radius = [0.5 * math.hypot(box.b, box.h) for box in boxes]
        size = structure.size
        self.max_distance = cfg.blowup_distance * size
        self.max_speed = cfg.blowup_speed * (math.sqrt(structure.g * size)
                                             + peak_ground_speed(excitation))
        self.start: list[tuple[float, float]] | None = None
        self.samples: list[tuple[float, ...]] = []
        self.verdict: Verdict | None = None
        self.max_ratio = [0.0] * len(boxes)  # largest |angle| / alpha_i of each body
        self._sign, self._impacts = 0, []
        self._rest_since: float | None = None

    def record(self, t: float, state) -> bool:
        """Take the sample ``state`` (a :class:`~engines.diagnostics.PlaneState`
        whose ``bodies`` are the structure's, in order) at time ``t`` [s]; True
        when the verdict is decided."""
        poses, boxes = state.bodies, self.structure.bodies
        values = [v for pose in poses for v in pose] + [state.psi, state.psi_dot, state.ground_x]
        if state.problem is not None or not all(map(math.isfinite, values)):
            self._decide("unstable", t, state.problem or "non-finite state")
            return True
        gx = state.ground_x
        if self.start is None:
            self.start = [(p.x, p.y) for p in poses]
        theta = sum(poses[k].angle for k in self.ground_index) / len(self.ground_index)
        theta_dot = sum(poses[k].omega for k in self.ground_index) / len(self.ground_index)
        self.samples.append((t, theta, theta_dot, state.psi, state.psi_dot))
        if abs(theta) > self.cfg.uplift_angle:
            sign = 1 if theta > 0 else -1
            if self._sign and sign != self._sign:
                self._impacts.append(t)
            self._sign = sign
        for k, (pose, box) in enumerate(zip(poses, boxes)):
            self.max_ratio[k] = max(self.max_ratio[k], abs(pose.angle) / box.alpha)
            x0, y0 = self.start[k]
            if math.hypot(pose.x - x0 - gx, pose.y - y0) > self.max_distance:
                self._decide("unstable", t, f"{box.name} flew away (> "
                                            f"{self.cfg.blowup_distance:g} structure sizes)")
                return True
            if math.hypot(pose.vx, pose.vy) > self.max_speed:
                self._decide("unstable", t, f"{box.name} exceeded {self.max_speed:.3g} m/s")
                return True
        for k, (pose, box) in enumerate(zip(poses, boxes)):
            lintel = box.name == "lintel"
            status = "collapsed" if lintel else "overturned"
            if abs(pose.angle) >= self.limits[k]:
                self._decide(status, t, f"{box.name} rotated {abs(pose.angle):.4g} rad (>= "
                                        f"{self.limits[k]:.4g}, {self.criterion.kind} at its own "
                                        f"alpha {box.alpha:.4g})")
                return True
            drop = box.upright[1] - pose.y
            if drop > self.drops[k]:
                what = "fell off the columns" if lintel else "fell"
                self._decide(status, t, f"{box.name} {what}: its centre dropped {drop:.3g} m")
                return True
        if self.early_stop and t >= self.t_end_pulse:
            cfg = self.cfg
            still = all(abs(p.angle) <= cfg.rest_angle and abs(p.omega) <= cfg.rest_rate
                        and math.hypot(p.vx, p.vy) <= cfg.rest_rate * r
                        for p, r in zip(poses, self.radius))
            if still:
                if self._rest_since is None:
                    self._rest_since = t
                if t - self._rest_since >= cfg.rest_hold:
                    self._decide("survived", None, "every body at rest after the pulse")
                    return True
            else:
                self._rest_since = None
        if t >= self.t_stop:
            self._decide("survived" if self.t_max is not None else "undecided", None,
                         f"end of run at t = {t:.4g} s")
            return True
        return False

    def _decide(self, status: str, t, reason: str) -> None:
        mode = None
        if status == "overturned":
            mode = "after-impact" if self._impacts else "no-impact"
        self.verdict = Verdict(status, t, mode, len(self._impacts), reason)

    def finish(self, backend: str, settings: dict, diagnostics: dict,
               wall_time: float) -> Trajectory:
        """The run as a :class:`~analytic.trajectory.Trajectory` (no model events:
        the uplift, impact velocities and energy rules are the model's)."""
        if self.verdict is None:
            self._decide("undecided", None, "run ended early")
        data = np.asarray(self.samples) if self.samples else np.zeros((0, 5))
        events = [Event("impact", t) for t in self._impacts
                  if self.verdict.time is None or t <= self.verdict.time]
        kinds = {"overturned": "overturn", "collapsed": "collapse", "unstable": "unstable"}
        if self.verdict.status in kinds:
            events.append(Event(kinds[self.verdict.status], self.verdict.time))
        diagnostics = dict(diagnostics, kind=self.structure.kind, n_samples=len(self.samples),
                           **{f"max_angle_over_alpha.{box.name}": ratio
                              for box, ratio in zip(self.structure.bodies, self.max_ratio)})
        return Trajectory(backend=backend, t=data[:, 0], theta=data[:, 1], theta_dot=data[:, 2],
                          psi=data[:, 3], psi_dot=data[:, 4], events=tuple(events),
                          verdict=self.verdict, criterion=self.criterion, t_max=self.t_max,
                          settings=settings, diagnostics=diagnostics, wall_time=wall_time,
                          scene=self.scene, excitation=self.excitation)
