"""Pymunk's drums restitution against its solver iterations and its step, MuJoCo
beside it: the velocity ratio of each of the first four impacts of the shipped
drums (two columns of two drums under the lintel, `scenes/data/drums.toml`)
released from half its release limit, free rocking, no base motion
(:func:`compare.measure.restitution_kinds.kind_free_rocking`, as ``trilith
restitution --scene drums --engine pymunk,mujoco``).

Run: ``python -m benchmarks.pymunk_drum_iterations`` (no run store; about 1 CPU
min).  Prints one line per setting: the four ratios of each engine and the worst
difference between them.  docs/geometry.md states the result.
"""
from __future__ import annotations

import sys
import time

# (Pymunk's step [s], its solver iterations): its calibrated 30 at three steps,
# then more iterations at its reference step and at half of it.
SETTINGS = ((1e-4, 30), (5e-5, 30), (2.5e-5, 30), (1e-4, 100), (1e-4, 200), (1e-4, 300),
            (1e-4, 1000), (5e-5, 300))
N_IMPACTS = 4


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.measure.restitution import DEFAULT_THETA0_FRACTION
    from trilith_xval.compare.measure.restitution_kinds import kind_free_rocking
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.engines.geometry import release_limit
    from trilith_xval.scenes import load_scene

    runs.activate(None)
    scene = load_scene("drums")
    theta0 = DEFAULT_THETA0_FRACTION * release_limit(scene)
    mujoco = kind_free_rocking(RunSpec.resolve("mujoco", scene, Still()), theta0, N_IMPACTS)
    ref = [r["ratio"] for r in mujoco["impacts"]]
    print(f"drums from theta0 = {theta0:.4g} rad; MuJoCo at {mujoco['dt']:g} s: "
          + " ".join(f"{r:.4f}" for r in ref), flush=True)
    for dt, iterations in SETTINGS:
        t0 = time.process_time()
        run = RunSpec.resolve("pymunk", scene, Still(),
                              overrides={"dt": dt, "iterations": iterations})
        got = [r["ratio"] for r in kind_free_rocking(run, theta0, N_IMPACTS)["impacts"]]
        worst = max(abs(a - b) / b for a, b in zip(got, ref))
        print(f"pymunk dt {dt:g} s, iterations {iterations}: "
              + " ".join(f"{r:.4f}" for r in got)
              + f"; worst |pymunk / mujoco - 1| {100 * worst:.2f} %, "
                f"{time.process_time() - t0:.1f} CPU s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
