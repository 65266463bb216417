"""Process start-up of ``trilith spectrum``: wall time of a whole
one-frequency call, and where it goes (``python -X importtime`` top-level
modules, then the compiled-cache load measured by ``fast.warm_up``)."""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from . import machine, write

ROOT = Path(__file__).resolve().parent.parent
CMD = [sys.executable, "-m", "trilith_xval.compare.cli.main", "spectrum", "--omega", "10"]


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}


def main(argv: list[str] | None = None) -> int:
    subprocess.run(CMD, env=_env(), capture_output=True, check=True)  # fill the caches
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run(CMD, env=_env(), capture_output=True, check=True)
        walls.append(time.perf_counter() - t0)
    walls.sort()
    imp = subprocess.run([sys.executable, "-X", "importtime", *CMD[1:]], env=_env(),
                         capture_output=True, text=True, check=True).stderr
    top = []
    for line in imp.splitlines():
        parts = line.split("|")
        if len(parts) == 3 and parts[1].strip().isdigit() and not parts[2].startswith("   "):
            top.append((int(parts[1]) / 1e6, parts[2].strip()))
    top.sort(reverse=True)
    probe = subprocess.run([sys.executable, "-c", (
        "import time; t=time.perf_counter(); from trilith_xval.analytic import fast; t1=time.perf_counter();"
        "fast.warm_up(record=False); print(t1-t, time.perf_counter()-t1)")],
        env=_env(), capture_output=True, text=True, check=True).stdout.split()
    print(f"trilith spectrum --omega 10: median {walls[1]:.3f} s of 3 (min {walls[0]:.3f})")
    print(f"  import analytic.fast {float(probe[0]):.3f} s, compiled-cache load "
          f"{float(probe[1]):.3f} s")
    print("  top-level imports: " + ", ".join(f"{n} {t:.3f} s" for t, n in top[:6]))
    write("bench_startup", {"machine": machine(), "wall_s": walls,
                            "import_fast_s": float(probe[0]), "cache_load_s": float(probe[1]),
                            "top_imports": top[:15]})
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
