"""The run store's cost and payoff (issue 12).

* ``trilith report --quick`` three times, one process each, one after the other:
  ``--no-cache``, cold into an empty store, warm from that store.  Reported: the
  warm speed-up (cold / warm, target >= 10) and the store's cost on a cold run
  (cold-with-store / no-cache); the three summary.json must agree (timings aside).
* Per run: the store's overhead on a miss (key + pickle + insert) and the cost of
  a hit, against the run itself, for a Pymunk run and an analytic-fast one (the
  reason analytic-fast runs are not stored: a hit costs more than the run).

Fails when the summaries differ (a wrong result) or the warm speed-up is below
the issue's 10x.
"""
from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import machine, median_time, write

ROOT = Path(__file__).resolve().parents[1]
TARGET_SPEEDUP = 10.0  # issue 12: a warm rerun of report --quick at least 10x faster


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in ("timings", "wall_time")}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _report(out: Path, *store_args: str) -> tuple[float, float, dict]:
    """Wall time, CPU time (the command and its waited-for workers) and summary."""
    import resource
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "compare.cli.main", "report", "--quick", "--out",
                           str(out), *store_args], cwd=ROOT, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)
    if proc.returncode != 0:
        raise RuntimeError(f"report failed: {proc.stderr[-2000:]}")
    return wall, cpu, _strip(json.loads((out / "summary.json").read_text()))


def per_run_overhead() -> dict:
    """The store's work per run [ms], each part timed on its own over many calls
    (a difference of two noisy run times would drown a sub-millisecond cost):
    key (canonical JSON + SHA-256), a missed lookup, the insert (pickle + commit)
    on a miss; the lookup (select + unpickle) on a hit; against the run itself."""
    from analytic.excitation import Pulse
    from compare.run.store import RunStore, run_key
    from engines import get_backend
    from scenes import load_scene

    scene = load_scene("fig5")
    out = {}
    cases = {"pymunk": dataclasses.replace(get_backend("pymunk").Settings(), t_max=1.0),
             "analytic-fast": get_backend("analytic-fast").Settings()}
    for name, settings in cases.items():
        backend = get_backend(name)
        pulse = Pulse(25.0, 11.0)
        traj, run = median_time(lambda: backend.simulate(scene, pulse, settings), 5, True)
        n = 200
        with tempfile.TemporaryDirectory() as d:
            store = RunStore(d)
            t0 = time.perf_counter()
            keys = [run_key(name, scene, Pulse(25.0 + k, 11.0), settings) for k in range(n)]
            t_key = (time.perf_counter() - t0) / n
            t0 = time.perf_counter()
            assert all(store.get(k) is None for k in keys)
            t_miss = (time.perf_counter() - t0) / n
            t0 = time.perf_counter()
            for k in keys:
                store.put(k, traj, kind="run", label=name, cost=0.0)
            t_put = (time.perf_counter() - t0) / n
            t0 = time.perf_counter()
            for k in keys:
                store.get(k)
            t_hit = (time.perf_counter() - t0) / n + t_key
            size = len(store._connect().execute("SELECT value FROM runs LIMIT 1").fetchone()[0])
            store.close()
        overhead = t_key + t_miss + t_put
        out[name] = {"run_ms": 1e3 * run, "miss_overhead_ms": 1e3 * overhead,
                     "miss_overhead_rel": overhead / run, "hit_ms": 1e3 * t_hit,
                     "blob_kB": size / 1e3}
    return out


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t_plain, c_plain, s_plain = _report(tmp / "r0", "--no-cache")
        t_cold, c_cold, s_cold = _report(tmp / "r1", "--cache", str(tmp / "cache"))
        t_warm, c_warm, s_warm = _report(tmp / "r2", "--cache", str(tmp / "cache"))
    same = s_plain == s_cold == s_warm
    speedup, overhead = t_cold / t_warm, t_cold / t_plain
    runs_ = per_run_overhead()
    print(f"report --quick: no store {t_plain:.1f} s, cold with store {t_cold:.1f} s, warm "
          f"{t_warm:.1f} s: warm speed-up {speedup:.1f}x (target >= {TARGET_SPEEDUP:g}), "
          f"cold-with-store / no-store {overhead:.3f}; summaries "
          f"{'identical' if same else 'DIFFER'}")
    # CPU time does not count other processes' load on a shared machine.
    print(f"  CPU time: no store {c_plain:.1f} s, cold {c_cold:.1f} s, warm {c_warm:.1f} s: "
          f"speed-up {c_cold / c_warm:.1f}x, cold-with-store / no-store "
          f"{c_cold / c_plain:.3f}; load average {os.getloadavg()[0]:.1f}")
    for name, r in runs_.items():
        print(f"  {name}: run {r['run_ms']:.2f} ms; store work on a miss "
              f"{r['miss_overhead_ms']:.3f} ms ({100 * r['miss_overhead_rel']:.1f} % of the run),"
              f" a hit {r['hit_ms']:.3f} ms; {r['blob_kB']:.0f} kB stored")
    write("store", {"machine": machine(), "report_quick_s": {
        "no_cache": t_plain, "cold": t_cold, "warm": t_warm}, "report_quick_cpu_s": {
        "no_cache": c_plain, "cold": c_cold, "warm": c_warm}, "warm_speedup": speedup,
        "cold_overhead_ratio": overhead, "summaries_identical": same, "per_run": runs_})
    return 0 if same and speedup >= TARGET_SPEEDUP else 1


if __name__ == "__main__":
    sys.exit(main())
