"""Work-precision of the two analytic paths: error against a tight reference versus
wall time, swept over the integrator tolerance.

Two errors, both dimensionless:

* ``theta-grid``: ``max |theta(t) - theta_ref(t)| / alpha`` on the 1 ms output grid
  over a fixed window (Fig. 5 trilith, one-sine pulse A = 3 m/s^2, Omega = 6 rad/s,
  which rocks with a few impacts and survives; t_max = 4 s);
* ``threshold``: ``|A_thr - A_ref| / A_ref``, the smallest one-sine amplitude that
  overturns the Fig. 5 trilith at Omega = 4 rad/s (A ~ 2.71 m/s^2, 'after-impact';
  the next switch of the verdict is 75 % higher, so a bisection in [2.5, 3.2]
  m/s^2 sees exactly one switch).  Bisection to 1e-9 relative: its own error is
  below every tolerance swept except the tightest.

The reference is the accurate path (scipy DOP853) at rtol 1e-13, atol 1e-15.
"""
from __future__ import annotations

import math

import numpy as np

from trilith_xval.analytic import Scene, Pulse, fast
from trilith_xval.analytic.simulate import Settings as AccSettings
from trilith_xval.analytic.simulate import simulate as simulate_acc
from trilith_xval.compare.run import runs  # untimed references only: through the run store

from .workprecision_common import Point, bisect_threshold, timed

__all__ = ["run_analytic", "GRID_CASE", "THRESHOLD_CASE"]

SCENE = Scene(name="fig5")  # the paper's Fig. 5 trilith (lam 5, b 0.6, mu 1, gamma 0.3)
GRID_CASE = {"amplitude": 3.0, "omega": 6.0, "t_max": 4.0, "sample_dt": 1e-3}
THRESHOLD_CASE = {"omega": 4.0, "lo": 2.5, "hi": 3.2, "rel_tol": 1e-9}
REF_RTOL, REF_ATOL = 1e-13, 1e-15
ACC_DEFAULT_RTOL = AccSettings().rtol
FAST_DEFAULT_RTOL = fast.Settings().rtol


def _grid(tr, dt: float, t_end: float) -> np.ndarray:
    """theta on the common grid ``k dt`` (theta is continuous: impacts only jump
    theta_dot, so interpolating between the dense samples is exact at grid points
    that are samples, and the grid points all are)."""
    ts = np.arange(0.0, t_end + 0.5 * dt, dt)
    return np.interp(ts, tr.t, tr.theta)


def _acc(rtol: float, **kw) -> AccSettings:
    return AccSettings(rtol=rtol, atol=rtol * 1e-2, **kw)


def _fast(rtol: float, **kw) -> fast.Settings:
    return fast.Settings(rtol=rtol, atol=rtol * 1e-2, **kw)


def run_analytic(quick: bool, log=print) -> list[Point]:
    """All analytic points (both paths, both metrics)."""
    fast.warm_up()
    c = GRID_CASE
    pulse = Pulse(c["amplitude"], c["omega"])
    ref = runs.simulate("analytic", SCENE, pulse,
                        AccSettings(rtol=REF_RTOL, atol=REF_ATOL, t_max=c["t_max"],
                                    sample_dt=c["sample_dt"]))
    ref_grid = _grid(ref, c["sample_dt"], c["t_max"])
    alpha = SCENE.alpha
    rtols = [1e-4, 1e-6, 1e-8, 1e-10] if quick else [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9,
                                                      1e-10, 1e-11, 1e-12]
    repeats = 3 if quick else 5
    points: list[Point] = []
    for family, make, sim, default_rtol in (
            ("analytic rtol", _acc, simulate_acc, ACC_DEFAULT_RTOL),
            ("analytic-fast rtol", _fast, fast.simulate, FAST_DEFAULT_RTOL)):
        for rtol in rtols:
            st = make(rtol, t_max=c["t_max"], sample_dt=c["sample_dt"])
            tr, wall = timed(lambda: sim(SCENE, pulse, st), repeats=repeats)
            err = float(np.max(np.abs(_grid(tr, c["sample_dt"], c["t_max"]) - ref_grid))) / alpha
            points.append(Point(family, "theta-grid", err, wall,
                                {"rtol": rtol, "atol": rtol * 1e-2},
                                default=math.isclose(rtol, default_rtol),
                                extra={"status": tr.verdict.status, "n_impacts": tr.n_impacts}))
            log(f"  {family:20s} rtol={rtol:.0e}  theta-grid err={err:.2e}  t={wall * 1e3:.1f} ms")

    th = THRESHOLD_CASE
    a_ref, n_ref = bisect_threshold(
        lambda A: runs.simulate("analytic", SCENE, Pulse(A, th["omega"]),
                               AccSettings(rtol=REF_RTOL, atol=REF_ATOL, sample_dt=None)).overturned,
        th["lo"], th["hi"], th["rel_tol"])
    log(f"  reference threshold A = {a_ref:.10g} m/s^2 at Omega = {th['omega']} rad/s "
        f"({n_ref} runs)")
    for family, verdict, default_rtol in (
            ("analytic rtol",
             lambda A, r: simulate_acc(SCENE, Pulse(A, th["omega"]),
                                       _acc(r, sample_dt=None)).overturned, ACC_DEFAULT_RTOL),
            ("analytic-fast rtol",
             lambda A, r: fast.verdict_for(SCENE, Pulse(A, th["omega"]), _fast(r)).overturned,
             FAST_DEFAULT_RTOL)):
        # quick: a loose tolerance and the default (one accurate bisection costs ~5 s)
        thr_rtols = [1e-4, default_rtol] if quick else rtols
        for rtol in thr_rtols:
            # The work is one whole bisection (~30 runs, itself an average); median of 3
            # for the cheap fast path, one for the accurate path.
            (a_thr, n_runs), wall = timed(
                lambda: bisect_threshold(lambda A: verdict(A, rtol), th["lo"], th["hi"],
                                         th["rel_tol"]),
                repeats=3 if family.startswith("analytic-fast") else 1,
                warmup=1 if family.startswith("analytic-fast") else 0)
            err = abs(a_thr - a_ref) / a_ref
            points.append(Point(family, "threshold", err, wall, {"rtol": rtol, "atol": rtol * 1e-2},
                                default=math.isclose(rtol, default_rtol),
                                extra={"A_thr": a_thr, "A_ref": a_ref, "runs": n_runs,
                                       "bracket_rel": th["rel_tol"]}))
            log(f"  {family:20s} rtol={rtol:.0e}  threshold err={err:.2e}  t={wall:.2f} s "
                f"({n_runs} runs)")
    return points
