"""A whole Fig. 5 engine spectrum per engine (issue 15): Omega = 3..30 step 1, both
curves, each engine bisected around the model to 0.5 % of A, 2 workers, no run store.

Ratios against the path before issue 15 measured in the same run: threshold probes
then ran every run to the topple angle (no ``verdict_only`` early exit); today's
probes stop as soon as the overturn is certain.  Targets (issue 15, 2 cores):
PyBullet <= 45 s, Pymunk <= 15 s.  ``BENCH_QUICK=1``
uses every fourth frequency (`BENCH_QUICK=1 make bench`).

Wall times depend on the machine's load; the JSON records the load average.  A
benchmark fails only when its results are wrong: here when the two paths give
different engine thresholds (the early exit must not change a verdict).
"""
from __future__ import annotations

import math
import os
import time

import numpy as np

from analytic.spectrum import overturning_spectrum
from compare import engine_spectrum as es
from compare import thresholds
from scenes import load_scene

from . import machine, write

TARGETS = {"pybullet": 45.0, "pymunk": 15.0, "mujoco": None}


def _old_overturns(backend, scene, omega, amplitude, settings=None, kind="sine"):
    """The probe before issue 15: the run goes on until the columns topple."""
    from analytic.excitation import Pulse
    from engines import get_backend
    traj = get_backend(backend).simulate(scene, Pulse(amplitude, omega, kind), settings)
    return traj.overturned, traj.verdict.status, traj.verdict.mode


def _spectrum(engine, scene, ref, old: bool):
    saved = thresholds.overturns
    if old:
        thresholds.overturns = _old_overturns  # forked workers inherit the patch
    try:
        t0 = time.perf_counter()
        out = es.engine_spectrum(engine, scene, ref, workers=2, convergence=False)
        return out, time.perf_counter() - t0
    finally:
        thresholds.overturns = saved


def main(argv: list[str] | None = None) -> int:
    quick = os.environ.get("BENCH_QUICK") == "1"
    omegas = np.arange(3.0, 31.0, 4.0 if quick else 1.0)
    scene = load_scene("fig5")
    ref = overturning_spectrum(scene, omegas)
    rows, failed = [], False
    for engine in TARGETS:
        new, t_new = _spectrum(engine, scene, ref, old=False)
        old, t_old = _spectrum(engine, scene, ref, old=True)
        same = all(math.isclose(a.a_engine, b.a_engine, rel_tol=0, abs_tol=0) or
                   (math.isnan(a.a_engine) and math.isnan(b.a_engine))
                   for ca, cb in zip(new.curves.values(), old.curves.values())
                   for a, b in zip(ca, cb))
        runs = sum(p.runs for c in new.curves.values() for p in c)
        target = TARGETS[engine]
        print(f"{engine}: {len(omegas)} freqs x 2 curves, {runs} runs: {t_new:.1f} s "
              f"(before: {t_old:.1f} s, ratio {t_new / t_old:.2f})"
              + (f"; target {target:g} s" if target and not quick else "")
              + ("" if same else "  THRESHOLDS DIFFER"), flush=True)
        failed |= not same
        rows.append({"engine": engine, "frequencies": len(omegas), "runs": runs,
                     "wall_s": t_new, "wall_before_s": t_old, "ratio": t_new / t_old,
                     "target_s": target, "same_thresholds": same})
    write("engine_spectrum", {"machine": machine(), "quick": quick, "rows": rows})
    return 1 if failed else 0
