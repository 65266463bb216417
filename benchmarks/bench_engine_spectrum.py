"""A whole Fig. 5 engine spectrum per engine (issue 15): Omega = 3..30 step 1, both
curves, each engine bisected around the model to 0.5 % of A, 2 workers, no run store.

Ratios against the path before issue 15 measured in the same run: threshold probes
then ran every run to the topple angle (no ``verdict_only`` early exit) inside a 3 %
bracket (two runs, then ~5 bisections); today's probes stop as soon as the overturn
is certain and an agreeing point costs three runs (a guard 3 % below, a 0.45 %
bracket).  Targets (issue 15, 2 cores):
PyBullet <= 45 s, Pymunk <= 15 s.  ``BENCH_QUICK=1``
uses every fourth frequency (`BENCH_QUICK=1 make bench`).

Wall times depend on the machine's load; the JSON records the load average.  A
benchmark fails only when its results are wrong: here when the two paths give
engine thresholds beyond the two brackets' resolution (the early exit must not
change a verdict).
"""
from __future__ import annotations

import math
import os
import time

import numpy as np

from analytic.spectrum import overturning_spectrum
from compare.measure import engine_spectrum as es
from compare.measure import thresholds
from scenes import load_scene

from . import machine, write

TARGETS = {"pybullet": 45.0, "pymunk": 15.0, "mujoco": None}


def _old_overturns(backend, scene, omega, amplitude, settings=None, kind="sine"):
    """The probe before issue 15: the run goes on until the columns topple."""
    from analytic.excitation import Pulse
    from engines import get_backend
    traj = get_backend(backend).simulate(scene, Pulse(amplitude, omega, kind), settings)
    return traj.overturned, traj.verdict.status, traj.verdict.mode


def _old_threshold(engine, scene, omega, a_ref, mode_ref, settings, kind, rel_tol):
    """The bracket before issue 15 (compare/campaign's): 3 % either side."""
    return thresholds.engine_threshold(engine, scene, omega, a_ref, settings, kind=kind,
                                       mode_reference=mode_ref, rel_bracket=0.03,
                                       rel_tol=rel_tol)


def _spectrum(engine, scene, ref, old: bool):
    saved = thresholds.overturns, es._threshold
    if old:  # forked workers inherit the patches
        thresholds.overturns, es._threshold = _old_overturns, _old_threshold
    try:
        t0 = time.perf_counter()
        out = es.engine_spectrum(engine, scene, ref, workers=2, convergence=False)
        return out, time.perf_counter() - t0
    finally:
        thresholds.overturns, es._threshold = saved


def main(argv: list[str] | None = None) -> int:
    quick = os.environ.get("BENCH_QUICK") == "1"
    omegas = np.arange(3.0, 31.0, 4.0 if quick else 1.0)
    scene = load_scene("fig5")
    ref = overturning_spectrum(scene, omegas)
    rows, failed = [], False
    for engine in TARGETS:
        new, t_new = _spectrum(engine, scene, ref, old=False)
        old, t_old = _spectrum(engine, scene, ref, old=True)
        # Same transition within both brackets (0.5 % of A each); a point where
        # either search found an engine window the other missed counts as a note.
        pairs = [(a, b) for ca, cb in zip(new.curves.values(), old.curves.values())
                 for a, b in zip(ca, cb)]
        differ = [a.omega for a, b in pairs
                  if not (math.isnan(a.a_engine) and math.isnan(b.a_engine))
                  and not abs(a.a_engine - b.a_engine) <= 0.0101 * a.a_analytic]
        # Where both agree with the model the two searches must find the same
        # transition; elsewhere (collapse, engine windows) they may find another one.
        bad = [a.omega for a, b in pairs if a.cause == b.cause == "agrees"
               and not abs(a.a_engine - b.a_engine) <= 0.0101 * a.a_analytic]
        same = not bad
        runs = sum(p.runs for c in new.curves.values() for p in c)
        target = TARGETS[engine]
        print(f"{engine}: {len(omegas)} freqs x 2 curves, {runs} runs: {t_new:.1f} s "
              f"(before: {t_old:.1f} s, ratio {t_new / t_old:.2f})"
              + (f"; target {target:g} s" if target and not quick else "")
              + (f"; thresholds differ at Omega {differ}" if differ else "")
              + ("" if same else f"  DIFFER WHERE BOTH AGREE: {bad}"), flush=True)
        failed |= not same
        rows.append({"engine": engine, "frequencies": len(omegas), "runs": runs,
                     "wall_s": t_new, "wall_before_s": t_old, "ratio": t_new / t_old,
                     "target_s": target, "same_thresholds": same, "differ_at": differ})
    write("engine_spectrum", {"machine": machine(), "quick": quick, "rows": rows})
    return 1 if failed else 0
