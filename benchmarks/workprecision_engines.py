"""Work-precision of the engines (PyBullet, Pymunk): error against the analytic
model versus wall time, swept over the time step and the main solver settings.

Three errors, all dimensionless:

* ``restitution``: ``max_k |measured_k / Eq.20 - 1|`` over the first two impacts of
  free rocking released from ``alpha/2``, worst of two triliths without pendulum:
  Fig. 5 (lam 5) and a squatter lam 3 (where Pymunk's solver iterations matter:
  10 iterations give 3.4 % there and 0.06 % at lam 5);
  :func:`compare.measure.restitution.measure_restitution`;
* ``theta-rms``: RMS of ``theta_engine - theta_analytic`` before the first impact,
  over ``alpha`` (Fig. 5 trilith with pendulum, one-sine 3 m/s^2 at 6 rad/s:
  uplift at 0.26 s, first impact at ~0.9 s);
* ``threshold``: ``|A_engine - A_analytic| / A_analytic`` for the smallest one-sine
  amplitude that overturns the Fig. 5 trilith at Omega = 4 rad/s within a 6 s
  window (the reference uses the same window).  The bisection is bracketed by
  the analytic threshold (``[0.8, 1.25] A_ref``, widened if needed) and stops at
  0.1 % (quick: 2 %) relative width: an error below half that width is not
  resolved and is reported as that half width (``extra['resolved']`` False).  Measured for the dt sweep only (a bisection costs 8-10 runs), and
  in ``--quick`` for Pymunk at its default step only.

Each point's work is the wall time of the measured runs (one run for the first
two metrics, the whole bisection for the threshold).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from trilith_xval.analytic import Pulse, Scene
from trilith_xval.analytic.simulate import Settings as AccSettings
from trilith_xval.compare.run import runs  # untimed references only: through the run store
from trilith_xval.engines import get_backend
from trilith_xval.compare.measure.restitution import measure_restitution

from .workprecision_common import Point, bisect_threshold

__all__ = ["run_engines", "ENGINE_SWEEPS"]

SCENE = Scene(name="fig5")
SCENE_NOPEND = SCENE.without_pendulum()
RESTITUTION_SCENES = (SCENE_NOPEND, SCENE_NOPEND.replace(lam=3.0, name="lam3"))
RMS_CASE = {"amplitude": 3.0, "omega": 6.0}
THR_CASE = {"omega": 4.0, "t_max": 6.0}
THETA0_FRACTION = 0.5  # release from alpha/2: large, clean impacts

# Settings swept around each engine's defaults (each list is one curve).
ENGINE_SWEEPS = {
    "pybullet": {"solver_iterations": [10, 25, 100], "contact_erp": [0.05, 0.8],
                 "contact_slop": [1e-5, 1e-3]},
    "pymunk": {"iterations": [10, 60], "slop_fraction": [1e-5, 1e-3, 1e-2]},
    "mujoco": {"timeconst_steps": [2.0, 10.0], "dampratio": [1.0, 6.0], "iterations": [10]},
}
DTS_FULL = [2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5]
DTS_QUICK = [1e-3, 1e-4]
# Threshold bisections (8-10 runs of ~4 s of rocking): below 1e-4 only Pymunk is
# affordable (PyBullet at 5e-5 took 126 s under load).
THR_DTS_FULL = {"pymunk": [1e-3, 5e-4, 2e-4, 1e-4, 5e-5], "pybullet": [1e-3, 5e-4, 2e-4, 1e-4],
                "mujoco": [1e-3, 5e-4, 2e-4, 1e-4]}
# quick: PyBullet's bisection is ~30 s, MuJoCo's ~15 s
THR_DTS_QUICK = {"pymunk": [1e-4], "pybullet": [], "mujoco": []}


def _settings(backend, **changes):
    """Backend defaults with ``changes``; samples kept ~1 ms apart whatever dt."""
    base = backend.Settings()
    if "dt" in changes:
        changes.setdefault("sample_every", max(1, round(1e-3 / changes["dt"])))
    return dataclasses.replace(base, **changes)


def _is_default(backend, st) -> bool:
    base = backend.Settings()
    return all(getattr(st, f.name) == getattr(base, f.name)
               for f in dataclasses.fields(base) if f.name not in ("t_max", "theta0", "psi0"))


def _timed_run(fn, cheap: bool):
    """One measured call; repeated (median of 3, after the first as warm-up) only
    when the call is cheap (< 0.5 s), so small steps stay affordable."""
    import statistics
    import time

    t0 = time.perf_counter()
    out = fn()
    first = time.perf_counter() - t0
    if not cheap or first > 0.5:
        return out, first
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)


class _Reference:
    """Analytic references, computed once."""

    def __init__(self, quick: bool) -> None:
        c = RMS_CASE
        self.pulse = Pulse(c["amplitude"], c["omega"])
        tr = runs.simulate("analytic", SCENE, self.pulse, AccSettings(sample_dt=1e-4, t_max=3.0))
        impacts = [e.t for e in tr.events if e.kind == "impact"]
        self.t_impact = impacts[0]
        self.t_ref, self.theta_ref = tr.t, tr.theta
        th = THR_CASE
        self.a_thr, _ = bisect_threshold(
            lambda A: runs.simulate("analytic", SCENE, Pulse(A, th["omega"]),
                                    AccSettings(t_max=th["t_max"], sample_dt=None)).overturned,
            2.0, 3.5, 1e-8)
        self.thr_tol = 0.02 if quick else 0.001


def _rms_error(backend, st, ref: _Reference) -> tuple[float, dict]:
    st = dataclasses.replace(st, t_max=ref.t_impact)
    tr = backend.simulate(SCENE, ref.pulse, st)
    # Stop short of the impact by 5 ms: engines spread an impact over a few steps.
    keep = tr.t <= ref.t_impact - 5e-3
    if tr.verdict.status == "unstable" or keep.sum() < 10:
        return math.inf, {"status": tr.verdict.status}
    diff = tr.theta[keep] - np.interp(tr.t[keep], ref.t_ref, ref.theta_ref)
    return float(np.sqrt(np.mean(diff ** 2))) / SCENE.alpha, {"status": tr.verdict.status}


def _restitution_error(name: str, st) -> tuple[float, dict]:
    worst, extra = 0.0, {}
    for scene in RESTITUTION_SCENES:
        res = measure_restitution(name, scene, THETA0_FRACTION * scene.alpha, st, n_impacts=2)
        errors = [i.rel_error for i in res.impacts]
        if not res.complete or not errors or any(math.isnan(e) for e in errors):
            return math.inf, {"scene": scene.name, "status": res.status,
                              "n_impacts": res.n_impacts}
        extra[f"{scene.name}_max_rel_error"] = res.max_rel_error
        worst = max(worst, res.max_rel_error)
    return worst, extra


def _threshold_error(backend, st, ref: _Reference) -> tuple[float, dict]:
    st = dataclasses.replace(st, t_max=THR_CASE["t_max"])
    statuses = []

    def overturns(amp: float) -> bool:
        tr = backend.simulate(SCENE, Pulse(amp, THR_CASE["omega"]), st)
        statuses.append(tr.verdict.status)
        return tr.overturned

    a, runs = bisect_threshold(overturns, 0.8 * ref.a_thr, 1.25 * ref.a_thr, ref.thr_tol)
    if not math.isfinite(a):
        return math.inf, {"runs": runs, "statuses": statuses}
    err = abs(a - ref.a_thr) / ref.a_thr
    return err, {"A_thr": a, "A_ref": ref.a_thr, "runs": runs, "bracket_rel": ref.thr_tol,
                 "unstable_runs": statuses.count("unstable")}


def _configs(name: str, quick: bool):
    """(family, params) pairs: the dt sweep, then each solver-setting sweep at the
    default dt."""
    dts = DTS_QUICK if quick else DTS_FULL
    for dt in dts:
        yield f"{name} dt", {"dt": dt}
    if quick:
        return
    fields = {f.name for f in dataclasses.fields(get_backend(name).Settings)}
    for key, values in ENGINE_SWEEPS.get(name, {}).items():
        if key not in fields:  # a setting this engine version does not have
            continue
        for v in values:
            yield f"{name} {key}", {key: v}


def run_engines(quick: bool, engines=("pybullet", "pymunk", "mujoco"), log=print) -> list[Point]:
    ref = _Reference(quick)
    log(f"  analytic references: first impact at {ref.t_impact:.4f} s; threshold "
        f"A = {ref.a_thr:.6g} m/s^2 at Omega = {THR_CASE['omega']} rad/s ({THR_CASE['t_max']} s window)")
    points: list[Point] = []
    for name in engines:
        backend = get_backend(name)
        backend.simulate(SCENE, Pulse(0.5, 6.0), _settings(backend, t_max=0.05))  # warm-up
        thr_dts = (THR_DTS_QUICK if quick else THR_DTS_FULL).get(name, [])
        for family, params in _configs(name, quick):
            st = _settings(backend, **params)
            default = _is_default(backend, st)
            for metric, fn in (
                    ("restitution", lambda: _restitution_error(name, st)),
                    ("theta-rms", lambda: _rms_error(backend, st, ref)),
                    ("threshold", lambda: _threshold_error(backend, st, ref))):
                if metric == "threshold":
                    dt = params.get("dt", backend.Settings().dt)
                    if not family.endswith(" dt") or not any(math.isclose(dt, d)
                                                             for d in thr_dts):
                        continue
                try:
                    (err, extra), wall = _timed_run(fn, cheap=metric != "threshold")
                except ValueError as exc:  # a setting the engine refuses: recorded, not fatal
                    err, extra, wall = math.nan, {"error": str(exc)}, math.nan
                points.append(Point(family, metric, err, wall, params, default=default,
                                    extra=extra))
                log(f"  {family:28s} {_fmt(params):18s} {metric:11s} err={err:.3e}  "
                    f"t={wall:.3f} s")
    return points


def _fmt(params: dict) -> str:
    return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                     for k, v in params.items())
