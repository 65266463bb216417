"""The first answer for a user's own trilith: ``trilith trust --scene fig5 --engine
pymunk,mujoco`` cold (an empty run store), as a user runs it: a child process,
its CPU seconds and those of the workers it reaped (``RUSAGE_CHILDREN``), with
the load average before and after; wall time beside.

Target: at most 120 CPU s, the consensus where the model is invalid included
(two engines: up to three frequencies per curve).  A miss is printed, not hidden; the benchmark fails
only when the command fails or its result is incomplete (an engine without its
12 threshold points).
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from . import machine, timed_trilith, write

TARGET_CPU_S = 120.0
ENGINES = os.environ.get("BENCH_TRUST_ENGINES", "pymunk,mujoco")


def main(argv: list[str] | None = None) -> int:
    with tempfile.TemporaryDirectory(prefix="bench-trust-") as tmp:
        out = Path(tmp) / "trust"
        run = timed_trilith(["trust", "--scene", "fig5", "--engine", ENGINES, "--out", str(out),
                             "--cache", str(Path(tmp) / "store"), "-q"])
        cpu, wall = run.cpu_s, run.wall_s
        if run.returncode != 0:
            print(run.stderr, file=sys.stderr)
            return 1
        doc = json.loads((out / "trust.json").read_text())
    points = {e: len(v["thresholds"]) for e, v in doc["engines"].items()}
    payload = {"command": f"trilith trust --scene fig5 --engine {ENGINES} --no-cache",
               "cpu_s": cpu, "wall_s": wall, "load_average": run.load_average,
               "target_cpu_s": TARGET_CPU_S, "met": cpu <= TARGET_CPU_S,
               "threshold_points": points,
               # Where the model is invalid, the engines against each other (two engines).
               "consensus_points": len(doc.get("consensus") or []),
               "per_engine": {e: v["cost"] for e, v in doc["engines"].items()},
               "machine": machine()}
    path = write("trust", payload)
    print(f"trust cold: {cpu:.1f} CPU s (target <= {TARGET_CPU_S:g}: "
          f"{'met' if cpu <= TARGET_CPU_S else 'MISSED'}), {wall:.1f} s wall, load "
          f"{run.load_average[0]:.2f} -> {run.load_average[1]:.2f}; {path}")
    return 0 if all(n == 12 for n in points.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
