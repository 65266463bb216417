"""The full restitution map (``trilith restitution-map``: five engines, six lam and
the fig5 trilith, every variant of each grid) cold (an empty run store), as a
user runs it: a child process with two workers, its CPU seconds and those of the
workers it reaped (``RUSAGE_CHILDREN``), with the load average before and after.

Target: at most 30 CPU-min (1800 CPU s) on 2 cores.  A miss is printed, not
hidden; the benchmark fails only when the command fails or a cell is missing.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from . import machine, timed_trilith, write

TARGET_CPU_S = 1800.0
WORKERS = os.environ.get("BENCH_RMAP_WORKERS", "2")


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.compare.measure.restitution_map import LAMS, TRILITH, grids
    with tempfile.TemporaryDirectory(prefix="bench-rmap-") as tmp:
        out = Path(tmp) / "map.json"
        run = timed_trilith(["restitution-map", "--workers", WORKERS, "--json", str(out),
                             "--cache", str(Path(tmp) / "store"), "-q"])
        cpu, wall = run.cpu_s, run.wall_s
        if run.returncode != 0:
            print(run.stderr, file=sys.stderr)
            return 1
        doc = json.loads(out.read_text())
    expected = sum(len(v) for v in grids().values()) * (len(LAMS) + len(TRILITH))
    payload = {"command": f"trilith restitution-map --workers {WORKERS} --no-cache",
               "cpu_s": cpu, "wall_s": wall, "load_average": run.load_average,
               "target_cpu_s": TARGET_CPU_S, "met": cpu <= TARGET_CPU_S,
               "cells": len(doc["cells"]), "cells_cpu_s": doc["cells_cpu_s"],
               "machine": machine()}
    path = write("restitution_map", payload)
    print(f"restitution map cold: {cpu:.0f} CPU s (target <= {TARGET_CPU_S:g}: "
          f"{'met' if cpu <= TARGET_CPU_S else 'MISSED'}), {wall:.0f} s wall, load "
          f"{run.load_average[0]:.2f} -> {run.load_average[1]:.2f}; {path}")
    return 0 if len(doc["cells"]) == expected else 1


if __name__ == "__main__":
    sys.exit(main())
