"""Measurements between a backend and the analytic reference (no physics here).

Trajectory comparison, returning a frozen dataclass with ``to_dict()`` that carries
the provenance (backend, engine version, time step, settings, wall time):

* :func:`compare_trajectories`: theta(t) and psi(t) of a backend against the
  reference on a common time grid; RMS and max errors normalised by ``alpha``
  (the static overturning angle) up to the first impact and over the whole
  common window; uplift, impact-time and peak-angle errors; verdict agreement.

Restitution is measured in :mod:`compare.measure.restitution` and overturning thresholds
in :mod:`compare.measure.thresholds` (both run backends).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from trilith_xval.analytic.sampled_events import events_of
from trilith_xval.analytic.trajectory import Trajectory

from trilith_xval.compare.run.jsonable import plain
from trilith_xval.compare.run.keys import backend_version

__all__ = ["Provenance", "TrajectoryComparison", "provenance_of",
           "settings_provenance", "compare_trajectories", "common_grid_values"]

# Grid step of the common time grid [s]: engines sample every ~1 ms and the
# analytic path writes 1 ms samples; a finer grid only interpolates further.
GRID_DT = 1e-3


@dataclass(frozen=True)
class Provenance:
    """What produced a number: backend, its version, time step, settings, wall time
    and CPU time [s] (the run's own, when computed; NaN when not reported)."""

    backend: str
    version: str
    dt: float | None
    settings: dict = field(default_factory=dict)
    wall_time: float = math.nan
    cpu_time: float = math.nan

    def to_dict(self) -> dict:
        return {"backend": self.backend, "version": self.version, "dt": self.dt,
                "settings": plain(self.settings), "wall_time": self.wall_time,
                "cpu_time": self.cpu_time}


def provenance_of(traj: Trajectory, wall_time: float | None = None) -> Provenance:
    """The provenance of a trajectory (``dt`` is None for adaptive backends)."""
    settings = plain(traj.settings or {})
    dt = settings.get("dt") if isinstance(settings, dict) else None
    cpu = (traj.diagnostics or {}).get("cpu_time")
    return Provenance(traj.backend, backend_version(traj.backend),
                      float(dt) if dt is not None else None, settings,
                      float(traj.wall_time if wall_time is None else wall_time),
                      float(cpu) if cpu is not None else math.nan)


def settings_provenance(backend: str, settings, wall_time: float) -> Provenance:
    """Provenance of a result made of several runs with the same ``settings``."""
    values = plain(settings) if settings is not None else {}
    dt = values.get("dt") if isinstance(values, dict) else None
    return Provenance(backend, backend_version(backend),
                      float(dt) if dt is not None else None, values, float(wall_time))


# --------------------------------------------------------------------- angles
def _monotone(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Samples with strictly increasing times.  Backends write two samples at an
    impact instant (pre- and post-impact); theta and psi are continuous there,
    so keeping the last sample of each repeated time loses nothing."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size and np.any(np.diff(t) < 0.0):
        raise ValueError("trajectory times must be non-decreasing")
    keep = np.r_[np.diff(t) > 0.0, True] if t.size else np.zeros(0, bool)
    return t[keep], y[keep]


def common_grid_values(traj: Trajectory, name: str, grid: np.ndarray) -> np.ndarray:
    """``traj.<name>`` (``'theta'`` or ``'psi'``) linearly interpolated on ``grid``."""
    t, y = _monotone(traj.t, getattr(traj, name))
    if t.size == 0:
        raise ValueError(f"trajectory of {traj.backend!r} has no samples")
    return np.interp(grid, t, y)


def _end_time(traj: Trajectory) -> float:
    end = float(traj.t[-1]) if len(traj.t) else 0.0
    if traj.overturn_time is not None:
        end = min(end, float(traj.overturn_time))
    return end


def _first_impact(traj: Trajectory) -> float | None:
    impacts = traj.impacts
    return float(impacts[0].t) if impacts else None


def _first_past(traj: Trajectory, angle: float) -> float | None:
    """First time ``|theta|`` reaches ``angle`` (linear between samples), or None."""
    t, theta = _monotone(traj.t, traj.theta)
    mag = np.abs(theta)
    idx = np.flatnonzero(mag >= angle)
    if not idx.size:
        return None
    i = int(idx[0])
    if i == 0 or mag[i] == mag[i - 1]:
        return float(t[i])
    frac = (angle - mag[i - 1]) / (mag[i] - mag[i - 1])
    return float(t[i - 1] + frac * (t[i] - t[i - 1]))


def _errors(ref: Trajectory, test: Trajectory, name: str, t0: float, t1: float,
            scale: float) -> tuple[float, float]:
    """RMS and max of ``(test - ref)/scale`` on a uniform grid over ``[t0, t1]``."""
    if not t1 > t0:
        return math.nan, math.nan
    n = max(2, int(math.ceil((t1 - t0) / GRID_DT)) + 1)
    grid = np.linspace(t0, t1, n)
    diff = (common_grid_values(test, name, grid) - common_grid_values(ref, name, grid)) / scale
    return float(np.sqrt(np.mean(diff * diff))), float(np.max(np.abs(diff)))


def _peak(traj: Trajectory, name: str, t1: float) -> float:
    t, y = _monotone(traj.t, getattr(traj, name))
    mask = t <= t1
    return float(np.max(np.abs(y[mask]))) if np.any(mask) else 0.0


def _rel(a: float, b: float) -> float:
    return (a - b) / abs(b) if b != 0.0 else math.nan


@dataclass(frozen=True)
class TrajectoryComparison:
    """A backend's theta(t), psi(t) against the reference (analytic) run.

    Angle errors are ``(test - reference)/alpha`` on a uniform 1 ms grid.
    ``*_first``: from the earlier uplift to the earlier first impact, or the
    first time either run reaches ``|theta| = alpha`` (past it the fall is
    unstable and amplifies any difference), or the end of the common window;
    ``*_all``: over the common window,
    up to the earlier of the two end times / overturn times.  Time errors are
    ``test - reference`` [s]; uplift and impacts are read from both runs' samples
    by the rule every backend shares (:mod:`analytic.sampled_events`: uplift at
    ``|theta| = 1e-4`` rad, impacts as sign changes of theta faster than 1e-2
    rad/s, both interpolated), impacts matched in order;
    ``uplift_time_resolution`` bounds the uplift error by the sum of both
    runs' resolutions (each the distance to the farther sample around the
    crossing).
    """

    reference: Provenance
    test: Provenance
    alpha: float
    t_start: float
    t_first_impact: float
    t_end: float
    theta_rms_first: float
    theta_max_first: float
    theta_rms_all: float
    theta_max_all: float
    psi_rms_first: float
    psi_max_first: float
    psi_rms_all: float
    psi_max_all: float
    uplift_time_error: float
    uplift_time_resolution: float
    impact_time_errors: tuple[float, ...]
    n_impacts_reference: int
    n_impacts_test: int
    peak_theta_reference: float
    peak_theta_test: float
    peak_theta_rel_error: float
    peak_psi_reference: float
    peak_psi_test: float
    status_reference: str
    status_test: str
    mode_reference: str | None
    mode_test: str | None

    @property
    def verdict_agrees(self) -> bool:
        """Same status and, when overturned, same mode (with/without impact)."""
        return self.status_reference == self.status_test and self.mode_reference == self.mode_test

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["reference"] = self.reference.to_dict()
        out["test"] = self.test.to_dict()
        out["impact_time_errors"] = list(self.impact_time_errors)
        out["verdict_agrees"] = self.verdict_agrees
        return out


def compare_trajectories(reference: Trajectory, test: Trajectory,
                         alpha: float | None = None) -> TrajectoryComparison:
    """Measure ``test`` against ``reference`` (see :class:`TrajectoryComparison`).

    ``alpha`` defaults to the reference scene's slenderness angle ``atan(b/h)``.
    """
    if alpha is None:
        if reference.scene is None:
            raise ValueError("alpha must be given when the reference trajectory has no scene")
        alpha = reference.scene.alpha
    if not (math.isfinite(alpha) and alpha > 0.0):
        raise ValueError(f"alpha must be in (0, pi/2] rad, got {alpha!r}")
    for traj in (reference, test):
        if len(traj.t) == 0:
            raise ValueError(f"trajectory of {traj.backend!r} has no samples")
    t_end = min(_end_time(reference), _end_time(test))
    t_begin = max(float(reference.t[0]), float(test.t[0]))
    ups = [u for u in (reference.uplift_time, test.uplift_time) if u is not None]
    t_start = max(min(ups), t_begin) if ups else t_begin
    # The "first" window also ends where either run passes alpha: beyond it the
    # trilith falls (unstable equilibrium), any timing difference grows
    # exponentially and says nothing about the engine's accuracy.
    firsts = [f for f in (_first_impact(reference), _first_impact(test),
                          _first_past(reference, alpha), _first_past(test, alpha))
              if f is not None]
    t_fi = min(min(firsts), t_end) if firsts else t_end

    th_rf, th_mf = _errors(reference, test, "theta", t_start, t_fi, alpha)
    th_ra, th_ma = _errors(reference, test, "theta", t_begin, t_end, alpha)
    ps_rf, ps_mf = _errors(reference, test, "psi", t_start, t_fi, alpha)
    ps_ra, ps_ma = _errors(reference, test, "psi", t_begin, t_end, alpha)

    read_ref, read_test = events_of(reference, alpha), events_of(test, alpha)
    up_ref, up_test = read_ref.uplift, read_test.uplift
    up_err = up_res = math.nan
    if up_ref is not None and up_test is not None:
        up_err, up_res = up_test.t - up_ref.t, up_test.resolution + up_ref.resolution
    ref_imp = [e.t for e in read_ref.impacts_before(t_end)]
    test_imp = [e.t for e in read_test.impacts_before(t_end)]
    imp_err = tuple(float(b - a) for a, b in zip(ref_imp, test_imp))
    pk_ref, pk_test = _peak(reference, "theta", t_end), _peak(test, "theta", t_end)
    return TrajectoryComparison(
        reference=provenance_of(reference), test=provenance_of(test), alpha=float(alpha),
        t_start=t_start, t_first_impact=t_fi, t_end=t_end,
        theta_rms_first=th_rf, theta_max_first=th_mf, theta_rms_all=th_ra, theta_max_all=th_ma,
        psi_rms_first=ps_rf, psi_max_first=ps_mf, psi_rms_all=ps_ra, psi_max_all=ps_ma,
        uplift_time_error=float(up_err), uplift_time_resolution=float(up_res),
        impact_time_errors=imp_err,
        n_impacts_reference=len(ref_imp), n_impacts_test=len(test_imp),
        peak_theta_reference=pk_ref, peak_theta_test=pk_test,
        peak_theta_rel_error=_rel(pk_test, pk_ref),
        peak_psi_reference=_peak(reference, "psi", t_end), peak_psi_test=_peak(test, "psi", t_end),
        status_reference=reference.verdict.status, status_test=test.verdict.status,
        mode_reference=reference.verdict.mode, mode_test=test.verdict.mode)
