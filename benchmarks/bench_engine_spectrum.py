"""A whole Fig. 5 engine spectrum per engine with the one threshold search: Omega =
3..30 step 1, both curves, robust brackets of 0.5 % of A (each end checked against
the perturbation set of compare/measure/thresholds.py), 2 workers, no run store,
no convergence reruns.  ``BENCH_QUICK=1`` uses every fourth frequency
(`BENCH_QUICK=1 make bench`).

Costs are CPU seconds measured inside each engine run (``diagnostics['cpu_time']``)
and summed over the points, CPU seconds per simulated second, and the wall time
with the 1-minute load average before and after: on a shared machine only the CPU
seconds compare between runs.  A benchmark fails only when its results are wrong:
here when a point's robust bracket is wider than the search's resolution.
"""
from __future__ import annotations

import os
import time

import numpy as np

from trilith_xval.analytic.spectrum import overturning_spectrum
from trilith_xval.compare.measure import engine_spectrum as es
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.scenes import load_scene

from . import machine, write

ENGINES = ("pybullet", "pymunk", "mujoco")


def main(argv: list[str] | None = None) -> int:
    quick = os.environ.get("BENCH_QUICK") == "1"
    omegas = np.arange(3.0, 31.0, 4.0 if quick else 1.0)
    scene = load_scene("fig5")
    ref = overturning_spectrum(scene, omegas)
    rows, failed = [], False
    for engine in ENGINES:
        load0, t0, c0 = os.getloadavg()[0], time.perf_counter(), time.process_time()
        out = es.engine_spectrum(RunSpec.resolve(engine, scene), ref, workers=2,
                                 convergence=False)
        wall, parent_cpu = time.perf_counter() - t0, time.process_time() - c0
        cost = out.cost()
        pts = [p for c in out.curves.values() for p in c]
        wide = [p.omega for p in pts if p.bracketed
                and not p.rel_resolution <= es.DEFAULT_REL_TOL * (1 + 1e-9)]
        failed |= bool(wide)
        agree = sum(p.cause == "agrees" for p in pts)
        print(f"{engine}: {len(pts)} points, {cost['runs']} runs, {cost['cpu_s']:.1f} CPU s in "
              f"the runs ({cost['cpu_per_sim_s']:.3g} CPU s per simulated s), {wall:.1f} s wall "
              f"with 2 workers, load {load0:.1f} -> {os.getloadavg()[0]:.1f}; {agree} agree; "
              f"{sum(bool(p.isolated) for p in pts)} points with isolated overturns"
              + (f"  BRACKET WIDER THAN 0.5 % AT {wide}" if wide else ""), flush=True)
        rows.append({"engine": engine, "points": len(pts), "runs": cost["runs"],
                     "cpu_s": cost["cpu_s"], "cpu_per_sim_s": cost["cpu_per_sim_s"],
                     "wall_s": wall, "parent_cpu_s": parent_cpu, "workers": 2,
                     "load_average": [load0, os.getloadavg()[0]], "agree": agree,
                     "with_isolated": sum(bool(p.isolated) for p in pts),
                     "too_wide_at": wide})
    write("engine_spectrum", {"machine": machine(), "quick": quick, "rows": rows})
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
