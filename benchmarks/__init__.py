"""Benchmarks (not tests): run times and the accuracy they buy.

``make bench`` runs :mod:`benchmarks.run`, which calls ``main()`` of every
``benchmarks/bench_*.py``.  Results are printed and written as JSON to
``benchmarks/out/`` (git-ignored).  Wall-clock numbers live here, never in tests.
"""
from __future__ import annotations

import json
import os
import platform
import statistics
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import NamedTuple

OUT = Path(__file__).resolve().parent / "out"


def machine() -> dict:
    """What a timing depends on: cores, load, versions, date (UTC)."""
    import numba
    import numpy
    import scipy
    try:
        load = os.getloadavg()
    except OSError:
        load = None
    return {"nproc": os.cpu_count(), "loadavg": load, "python": platform.python_version(),
            "numpy": numpy.__version__, "scipy": scipy.__version__,
            "numba": numba.__version__, "platform": platform.platform(),
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds")}


def write(name: str, payload: dict) -> Path:
    """Write ``benchmarks/out/<name>.json`` (strict JSON) whole, atomically, and
    return its path."""
    from trilith_xval.compare.run.atomic import write_text
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"{name}.json"
    write_text(path, json.dumps(payload, indent=1, allow_nan=False))
    return path


class Timed(NamedTuple):
    """A child command's exit code, output, CPU seconds (user + system of it and
    the workers it reaped), wall seconds, the 1-min load average before and
    after, and the largest resident set [MB] of any process reaped so far (the
    command's or a worker's: peak memory per process, not their sum)."""

    returncode: int
    stdout: str
    stderr: str
    cpu_s: float
    wall_s: float
    load_average: list
    max_rss_mb: float


def timed_trilith(argv: list[str], cwd=None, env=None) -> Timed:
    """Run ``trilith *argv`` as a user does, in a child process (``python -m
    trilith_xval.compare.cli.main``), and time it: CPU from ``RUSAGE_CHILDREN``
    (the command and every worker it waited for), wall beside it."""
    import resource
    import subprocess
    import sys
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load0, t0 = os.getloadavg()[0], time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", *argv],
                          cwd=cwd, env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return Timed(proc.returncode, proc.stdout, proc.stderr, cpu, wall,
                 [load0, os.getloadavg()[0]], after.ru_maxrss / 1024.0)


def median_time(fn, repeats: int, warm_up: bool = False) -> tuple[object, float]:
    """``(last result, median wall time [s])`` of ``repeats`` calls of ``fn``,
    after one untimed call when ``warm_up``."""
    out = fn() if warm_up else None
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)
