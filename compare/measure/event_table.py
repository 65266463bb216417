"""The shared event rule on every backend: the paper's points A-D and the sample record.

``python -m trilith_xval.compare.measure.event_table [BACKEND ...]`` prints a Markdown table: for
each case and backend the uplift, the number of impacts and the overturn read by
:mod:`analytic.sampled_events` (each time +- its resolution), the verdict's own time,
and the run's CPU seconds; the model's exact lift-off and impact count are in the
last column.  docs/engine-trust.md quotes its output.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

__all__ = ["rows", "main"]

RECORD = "scenes/records/sample.csv"


def _cases():
    from trilith_xval.scenes import load_scene
    from trilith_xval.scenes.ground_motion import load_record
    from trilith_xval.scenes.points import POINTS, point_pulse

    scene = load_scene("fig5")
    for point in POINTS:
        for pendulum in (True, False):
            yield (f"{point}, {'pendulum' if pendulum else 'no pendulum'}",
                   scene if pendulum else scene.without_pendulum(), point_pulse(point))
    root = Path(__file__).resolve().parents[2]
    yield "sample record, pendulum", scene, load_record(root / RECORD)


def rows(backends) -> list[dict]:
    """One row per case and backend (calibrated settings, each backend's own stop rule)."""
    from trilith_xval import engines

    out = []
    for case, scene, excitation in _cases():
        for name in backends:
            cpu0 = time.process_time()
            traj = engines.simulate(name, scene, excitation)
            cpu = traj.diagnostics.get("cpu_time", time.process_time() - cpu0)
            read = traj.sampled_events()
            exact = (f"{traj.uplift_time:.4f} s, {traj.n_impacts}"
                     if name.startswith("analytic") and traj.uplift_time is not None else "")
            out.append({"case": case, "backend": name, "status": traj.verdict.status,
                        "uplift": read.uplift.text() if read.uplift else "none",
                        "impacts": read.n_impacts,
                        "exceeds_alpha": (read.exceeds_alpha.text() if read.exceeds_alpha
                                          else "-"),
                        "verdict_time": ("-" if traj.verdict.time is None
                                         else f"{traj.verdict.time:.4f} s"),
                        "cpu_s": float(cpu), "exact": exact})
    return out


def main(argv=None) -> int:
    from trilith_xval.engines import engine_names
    backends = (argv if argv is not None else sys.argv[1:]) or ["analytic", *engine_names()]
    load0 = os.getloadavg()
    table = rows(backends)
    print("| case | backend | verdict | uplift | impacts | past alpha for good | verdict time "
          "| CPU s | model's exact lift-off, impacts |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r['case']} | {r['backend']} | {r['status']} | {r['uplift']} | {r['impacts']} "
              f"| {r['exceeds_alpha']} | {r['verdict_time']} | {r['cpu_s']:.2f} | {r['exact']} |")
    print(f"\nload average {load0[0]:.1f} -> {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
