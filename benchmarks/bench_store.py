"""The run store's cost and payoff.

* ``trilith report --quick`` three times, one process each, one after the other:
  ``--no-cache``, cold into an empty store, warm from that store.  Targets, each
  a ratio of two measurements of this one run:

  - the warm rerun computes nothing (its ``-v`` store line: ``0 computed``);
  - warm CPU seconds <= ``TARGET_WARM_RATIO`` x cold CPU seconds.  CPU, not
    wall: the store saves computation, and CPU time does not count the other
    processes of a shared machine.  A warm run reads every run and every
    figure from the store (:mod:`compare.report.figure_cache`); what is left
    is the interpreter, the imports and the tables;
  - the three summary.json agree on every result (what they cost and when they
    were made aside: ``timings``, ``wall_time``, ``provenance``, the trust
    table's ``cost`` and the sentence of its conclusion that quotes it).
* Per run: the store's overhead on a miss (key + encode + insert) and the cost
  of a hit, against the run itself, for a Pymunk run and an analytic-fast one
  (the reason analytic-fast runs are not stored: a hit costs more than the run).
"""
from __future__ import annotations

import dataclasses
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import machine, median_time, write

ROOT = Path(__file__).resolve().parents[1]
TARGET_WARM_RATIO = 0.05  # warm / cold CPU seconds of report --quick (see the module doc)


# What differs between two correct reports: what they cost, and when and how
# they were run (the provenance holds the date and the command line).
_NOT_RESULTS = ("timings", "wall_time", "provenance", "cost", "from_store", "cpu_s_spent")
_COST_SENTENCE = re.compile(r" One run costs .*? \(wall time on the measuring machine\)\."
                            r"|; \d+ of \d+ points were served by the run store")


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in _NOT_RESULTS}
    if isinstance(obj, str):
        return _COST_SENTENCE.sub("", obj)
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _report(out: Path, *store_args: str) -> tuple[float, float, dict, int | None]:
    """Wall time, CPU time (the command and its waited-for workers), summary and
    the number of results computed (None without a store)."""
    import resource
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", "report", "--quick", "-v",
                           "--out", str(out), *store_args], cwd=ROOT, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)
    if proc.returncode != 0:
        raise RuntimeError(f"report failed: {proc.stderr[-2000:]}")
    found = re.search(r"(\d+) reused, (\d+) computed", proc.stdout)
    computed = int(found.group(2)) if found else None
    return wall, cpu, _strip(json.loads((out / "summary.json").read_text())), computed


def per_run_overhead() -> dict:
    """The store's work per run [ms], each part timed on its own over many calls
    (a difference of two noisy run times would drown a sub-millisecond cost):
    key (canonical JSON + SHA-256), a missed lookup, the insert (encode + commit)
    on a miss; the lookup (select + decode) on a hit; against the run itself."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.run.codec import decode, encode
    from trilith_xval.compare.run.keys import run_key
    from trilith_xval.compare.run.store import RunStore
    from trilith_xval.engines import get_backend
    from trilith_xval.scenes import load_scene

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
        c0 = time.process_time()  # the value format alone, in CPU time
        for _ in range(n):
            blob = encode(traj)
        c1 = time.process_time()
        for _ in range(n):
            decode(blob)
        c2 = time.process_time()
        overhead = t_key + t_miss + t_put
        out[name] = {"run_ms": 1e3 * run, "miss_overhead_ms": 1e3 * overhead,
                     "miss_overhead_rel": overhead / run, "hit_ms": 1e3 * t_hit,
                     "blob_kB": size / 1e3, "encode_cpu_ms": 1e3 * (c1 - c0) / n,
                     "decode_cpu_ms": 1e3 * (c2 - c1) / n}
    return out


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t_plain, c_plain, s_plain, _ = _report(tmp / "r0", "--no-cache")
        t_cold, c_cold, s_cold, n_cold = _report(tmp / "r1", "--cache", str(tmp / "cache"))
        t_warm, c_warm, s_warm, n_warm = _report(tmp / "r2", "--cache", str(tmp / "cache"))
    same = s_plain == s_cold == s_warm
    ratio, overhead = c_warm / c_cold, c_cold / c_plain
    runs_ = per_run_overhead()
    print(f"report --quick CPU time: no store {c_plain:.1f} s, cold with store {c_cold:.1f} s "
          f"({n_cold} computed), warm {c_warm:.1f} s ({n_warm} computed, target 0): warm / "
          f"cold {ratio:.3f} (target <= {TARGET_WARM_RATIO:g}), cold-with-store / "
          f"no-store {overhead:.3f}; summaries {'identical' if same else 'DIFFER'}")
    print(f"  wall time: no store {t_plain:.1f} s, cold {t_cold:.1f} s, warm {t_warm:.1f} s "
          f"({t_cold / t_warm:.1f}x); load average {os.getloadavg()[0]:.1f}")
    for name, r in runs_.items():
        print(f"  {name}: run {r['run_ms']:.2f} ms; store work on a miss "
              f"{r['miss_overhead_ms']:.3f} ms ({100 * r['miss_overhead_rel']:.1f} % of the run),"
              f" a hit {r['hit_ms']:.3f} ms; {r['blob_kB']:.0f} kB stored; encode "
              f"{r['encode_cpu_ms']:.3f} ms, decode {r['decode_cpu_ms']:.3f} ms CPU")
    write("store", {"machine": machine(), "report_quick_s": {
        "no_cache": t_plain, "cold": t_cold, "warm": t_warm}, "report_quick_cpu_s": {
        "no_cache": c_plain, "cold": c_cold, "warm": c_warm}, "warm_cold_cpu_ratio": ratio,
        "cold_overhead_ratio": overhead, "summaries_identical": same,
        "warm_computed": n_warm, "per_run": runs_})
    return 0 if same and n_warm == 0 and ratio <= TARGET_WARM_RATIO else 1


if __name__ == "__main__":
    sys.exit(main())
