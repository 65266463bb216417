"""Records in the compiled kernels against the accurate path, in one run: CPU
seconds of both, their ratio, the load average.

1. ``trilith simulate --record`` of a 16,000-sample record: the sample record
   (``scenes/records/sample.AT2``) at 200 Hz repeated 8 times (80 s; the Fig. 5
   trilith, with its pendulum, rocks to the end and survives), run to its
   exact verdict by the model's compiled path (``analytic.fast.simulate``,
   what the command runs for a record) and by the accurate path
   (``analytic.simulate.simulate``, what it ran before).
2. A model-only fragility over the shipped suite (the 12 synthetic
   Clough-Penzien motions, ``scenes/records/synthetic``): the IDA of every
   record with the fragility's default search (:class:`analytic.ida.IDASettings`,
   PGA 0.5 to 20 m/s^2, without the pendulum as in the README's example), by
   :func:`analytic.ida.model_verdict` compiled and accurate, then the lognormal
   fit of both.

CPU seconds are ``time.process_time()`` of this process (no workers: every run
is made here).  The compiled kernels are loaded (or compiled) before the clock
starts; the load time is printed apart.  Fails (exit 1) when the two paths
disagree: another verdict or impact count, event times further apart than
0.01 s, or another s* beyond one IDA bracket (``rtol``).  ``python -m
benchmarks.bench_record_paths 5`` runs the fragility over the first 5 records.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "scenes" / "records" / "sample.AT2"
SUITE = ROOT / "scenes" / "records" / "synthetic"


def long_record(repeats: int = 8, dt: float = 0.005):
    """The sample record resampled every ``dt`` [s] and repeated: ``10 repeats /
    dt`` samples (16,000 by default, 80 s)."""
    from trilith_xval.analytic.excitation import SampledRecord
    from trilith_xval.scenes import load_record
    t = np.arange(0.0, 10.0, dt)
    a = np.tile(load_record(SAMPLE).acceleration_array(t), repeats)
    return SampledRecord(tuple(dt * np.arange(a.size)), tuple(a), f"sample x{repeats}")


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.2f} (1 min) on {os.cpu_count()} CPUs"


def bench_simulate() -> tuple[bool, float]:
    from trilith_xval.analytic import fast
    from trilith_xval.analytic import simulate as accurate
    from trilith_xval.scenes import load_scene
    scene = load_scene("fig5")
    rec = long_record()
    runs = {}
    for name, run in (("compiled", lambda: fast.simulate(scene, rec)),
                      ("accurate", lambda: accurate.simulate(scene, rec))):
        c0 = time.process_time()
        tr = run()
        runs[name] = (time.process_time() - c0, tr)
        print(f"  simulate {len(rec.times)} samples ({rec.end_time:g} s), {name}: "
              f"{runs[name][0]:.3f} CPU s, {tr.verdict.status}, {tr.n_impacts} impacts, "
              f"{len(tr.events)} events; {_load()}", flush=True)
    (cf, tf), (ca, ta) = runs["compiled"], runs["accurate"]
    same = ([(e.kind, e.side) for e in tf.events] == [(e.kind, e.side) for e in ta.events]
            and tf.verdict.status == ta.verdict.status)
    dt = max((abs(a.t - b.t) for a, b in zip(tf.events, ta.events)), default=0.0)
    print(f"  simulate: ratio compiled/accurate = {cf / ca:.5f} ({ca / cf:.0f}x); same events "
          f"and verdict: {same}, largest event time difference {dt:.2e} s", flush=True)
    return same and dt <= 0.01, cf / ca


def bench_fragility(n_records: int | None) -> tuple[bool, float]:
    from trilith_xval.analytic.ida import IDASettings, first_overturn_intensity, model_verdict
    from trilith_xval.compare.measure.fragility import fit_lognormal
    from trilith_xval.scenes import load_record, load_scene
    scene = load_scene("fig5").without_pendulum()
    suite = [load_record(p) for p in sorted(SUITE.glob("*.csv"))][:n_records]
    st = IDASettings()
    out = {}
    for name, compiled in (("compiled", True), ("accurate", False)):
        overturns = model_verdict(scene, st.tail, compiled=compiled)
        c0 = time.process_time()
        res = [first_overturn_intensity(r, overturns, st) for r in suite]
        cpu = time.process_time() - c0
        im = np.array([r.im_overturn for r in res])
        median, beta = fit_lognormal(im, st.im_hi)
        out[name] = (cpu, res)
        print(f"  fragility of {len(suite)} records, {name}: {cpu:.2f} CPU s, "
              f"{sum(len(r.runs) for r in res)} runs, median {median:.4g} m/s^2, "
              f"beta {beta:.4g}; {_load()}", flush=True)
    (cf, rf), (ca, ra) = out["compiled"], out["accurate"]
    ok = True
    for a, b in zip(rf, ra):
        same_runs = [o for _, o in a.runs] == [o for _, o in b.runs]
        close = (a.im_overturn == b.im_overturn or
                 abs(a.im_overturn / b.im_overturn - 1.0) <= st.rtol)
        ok &= close
        if not same_runs or not close:
            print(f"  {a.label}: s* {a.im_overturn:.6g} compiled, {b.im_overturn:.6g} accurate "
                  f"(same verdicts: {same_runs})")
    print(f"  fragility: ratio compiled/accurate = {cf / ca:.5f} ({ca / cf:.0f}x); every "
          f"record's first overturning PGA within one bracket: {ok}", flush=True)
    return ok, cf / ca


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.analytic import fast
    n = int(argv[0]) if argv else None
    print(f"  kernels loaded in {fast.warm_up():.2f} s (not counted); {_load()}", flush=True)
    ok_sim, _ = bench_simulate()
    ok_frag, _ = bench_fragility(n)
    return 0 if ok_sim and ok_frag else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
