"""One fast-path run of the Fig. 5 case at point A (A_s = 19 m/s^2, Omega = 15 rad/s,
with the pendulum), against the accurate path in the same process.

Median over many runs after a warm-up (compilation or cache load excluded: a
spectrum pays it once per process).  Target: median <= 0.1 ms for the verdict.
Timed: the verdict-only kernel (what spectra call), ``fast.simulate`` (with a
sampled Trajectory) and ``analytic.simulate``; the verdicts must be identical.
"""
from __future__ import annotations

import sys

from trilith_xval.analytic import fast
from trilith_xval.analytic import simulate as accurate
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.trajectory import OverturnCriterion
from trilith_xval.scenes import load_scene

from . import machine, median_time, write

POINT_A = (19.0, 15.0)
TARGET_S = 1e-4


def main(argv: list[str] | None = None) -> int:
    scene = load_scene("fig5")
    warm = fast.warm_up()
    rows = {}
    ok = True
    for label, sc in (("pendulum", scene), ("no pendulum", scene.without_pendulum())):
        pulse = Pulse(*POINT_A)
        args = sc.model_args()
        thr = OverturnCriterion().threshold(sc.alpha)
        (st, _r, _t, n_imp), t_verdict = median_time(
            lambda: fast.overturn_verdict(*args, POINT_A[0], POINT_A[1], 0, thr), 2000,
            warm_up=True)
        tr_fast, t_sim = median_time(lambda: fast.simulate(sc, pulse), 300, warm_up=True)
        tr_acc, t_acc = median_time(lambda: accurate.simulate(sc, pulse), 15, warm_up=True)
        same = ((fast.STATUS_NAMES[st], n_imp) == (tr_acc.verdict.status, tr_acc.n_impacts)
                and (tr_fast.verdict.status, tr_fast.verdict.mode, tr_fast.n_impacts)
                == (tr_acc.verdict.status, tr_acc.verdict.mode, tr_acc.n_impacts))
        ok &= same
        rows[label] = {"verdict": tr_acc.verdict.status, "mode": tr_acc.verdict.mode,
                       "n_impacts": tr_acc.n_impacts, "verdicts_identical": same,
                       "fast_verdict_median_s": t_verdict, "fast_simulate_median_s": t_sim,
                       "accurate_median_s": t_acc, "speedup_verdict": t_acc / t_verdict,
                       "speedup_simulate": t_acc / t_sim,
                       "fast_steps": tr_fast.diagnostics["steps"]}
        print(f"point A {POINT_A}, {label}: {tr_acc.verdict.status} "
              f"({tr_acc.n_impacts} impacts); verdicts identical: {same}")
        print(f"  fast verdict   {t_verdict * 1e3:8.4f} ms  (target <= {TARGET_S * 1e3:g} ms: "
              f"{'met' if t_verdict <= TARGET_S else 'MISSED'})")
        print(f"  fast simulate  {t_sim * 1e3:8.4f} ms")
        print(f"  accurate       {t_acc * 1e3:8.4f} ms  -> speedup x{t_acc / t_verdict:.0f} "
              f"(verdict), x{t_acc / t_sim:.0f} (simulate)")
    path = write("bench_fast", {"machine": machine(), "warm_up_s": warm, "point": POINT_A,
                                "target_s": TARGET_S, "results": rows})
    print(f"warm-up (compile or cache load) {warm:.2f} s; wrote {path}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
