"""Fixed costs of the analytic CLI: ``trilith spectrum --omega 3:30:1 --no-cache``
(the Fig. 5 coarse grid) against the same command at the reference commit, and
what one forked worker costs.

* Side by side: the reference commit's sources (``spectrum_cli_reference.json``:
  the code before the kernels were loaded once before forking and the workers
  decided by the work) are unpacked once with ``git archive`` into
  ``benchmarks/out/``, run once to fill their numba cache, then both commands
  run in turn, three pairs.  CPU time of the whole process and its waited-for
  children (``RUSAGE_CHILDREN``), not wall time: the machine is shared.  Target:
  median CPU now <= ``TARGET_RATIO`` x median CPU then; both print the same
  thresholds as the reference file, bit for bit.  Without git (or the commit),
  the ratio is taken against the CPU time stored in the reference file, and
  says so.
* ``pool_start_cpu_s``: a parent that has loaded the kernels forks a pool of two
  workers that run trivial tasks; the CPU both sides spend, per worker (the
  constant :data:`analytic._workers.POOL_START_CPU_S` is set from it).
* ``help_cpu_s``: ``trilith --help``, and the heavy modules it imports (none).
"""
from __future__ import annotations

import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from . import OUT, machine, write

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).with_name("spectrum_cli_reference.json")
ARGS = ["spectrum", "--omega", "3:30:1", "--no-cache", "--json"]
TARGET_RATIO = 0.5  # CPU now / CPU at the reference commit
HEAVY = ("numba", "scipy", "matplotlib", "pybullet", "pymunk", "mujoco", "dartpy", "pydrake")


def _cpu_of(argv: list[str], root: Path) -> tuple[float, float, str]:
    """CPU seconds (user + system, the process and its children), wall seconds
    and stdout of ``python -m trilith_xval.compare.cli.main *argv`` run from ``root``
    (``compare.cli.main`` in a reference tree: older commits predate the one
    import name and run from their own folders)."""
    import time
    module = "trilith_xval.compare.cli.main" if root == ROOT else "compare.cli.main"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", module, *argv], cwd=root,
                          env={**os.environ, "PYTHONPATH": str(root)}, capture_output=True,
                          text=True, check=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, proc.stdout


def _reference_tree(commit: str) -> Path | None:
    """The sources of ``commit`` under ``benchmarks/out/`` (unpacked once), or None."""
    where = OUT / f"reference-{commit[:12]}"
    if (where / "compare" / "cli" / "main.py").is_file():
        return where
    OUT.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=OUT, prefix=".reference-"))
    try:
        archive = staging / "src.tar"
        subprocess.run(["git", "archive", "--format=tar", "-o", str(archive), commit],
                       cwd=ROOT, check=True, capture_output=True)
        with tarfile.open(archive) as tar:
            tar.extractall(staging / "src", filter="data")
        (staging / "src").rename(where)  # whole or absent
    except (OSError, subprocess.CalledProcessError):
        return None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return where


def _thresholds(stdout: str) -> dict:
    body = json.loads(stdout)
    return {k: body[k] for k in json.loads(REFERENCE.read_text())["thresholds"]}


def _pool_start_cpu() -> float:
    """CPU seconds per worker of a two-worker pool forked by a loaded parent."""
    code = (
        "import resource\n"
        "from trilith_xval.analytic import fast\n"
        "from trilith_xval.analytic._workers import fork_pool\n"
        "import trilith_xval.analytic.simulate\n"
        "fast.warm_up(record=False)\n"
        "def cpu(who):\n"
        "    r = resource.getrusage(who); return r.ru_utime + r.ru_stime\n"
        "s0, c0 = cpu(resource.RUSAGE_SELF), cpu(resource.RUSAGE_CHILDREN)\n"
        "for _ in range(5):\n"
        "    with fork_pool(2) as ex:\n"
        "        list(ex.map(abs, range(-20, 0)))\n"
        "print((cpu(resource.RUSAGE_SELF) - s0 + cpu(resource.RUSAGE_CHILDREN) - c0) / 10)\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True)
    return float(out.stdout.split()[-1])


def _help() -> tuple[float, list[str]]:
    cpu, _, _ = _cpu_of(["--help"], ROOT)
    code = ("import sys; from trilith_xval.compare.cli.main import build_parser; build_parser(); "
            f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True)
    return cpu, [m for m in out.stdout.strip().split(",") if m]


def main(argv: list[str] | None = None) -> int:
    ref = json.loads(REFERENCE.read_text())
    old_root = _reference_tree(ref["commit"])
    _cpu_of(ARGS, ROOT)  # fill this checkout's numba cache
    if old_root is not None:
        _cpu_of(ARGS, old_root)  # and the reference's
    rows = []
    same = True
    for _ in range(3):
        row = {"load_before": os.getloadavg()[0]}
        if old_root is not None:
            row["old_cpu_s"], row["old_wall_s"], out = _cpu_of(ARGS, old_root)
            same &= _thresholds(out) == ref["thresholds"]
        row["new_cpu_s"], row["new_wall_s"], out = _cpu_of(ARGS, ROOT)
        same &= _thresholds(out) == ref["thresholds"]
        row["load_after"] = os.getloadavg()[0]
        rows.append(row)
    new = statistics.median(r["new_cpu_s"] for r in rows)
    if old_root is not None:
        old, against = statistics.median(r["old_cpu_s"] for r in rows), "measured now"
    else:
        old, against = ref["measured"]["median_cpu_s"], f"stored ({ref['measured']['date']})"
    ratio = new / old
    pool = _pool_start_cpu()
    help_cpu, help_heavy = _help()
    loads = [r["load_before"] for r in rows] + [rows[-1]["load_after"]]
    print(f"trilith {' '.join(ARGS)}: median CPU {new:.2f} s now, {old:.2f} s at "
          f"{ref['commit'][:7]} ({against}): {ratio:.2f}x (target <= {TARGET_RATIO:g}); "
          f"thresholds {'identical to' if same else 'DIFFER from'} the reference; "
          f"load average {min(loads):.1f}-{max(loads):.1f}")
    for r in rows:
        old_part = (f"then {r['old_cpu_s']:.2f} s CPU ({r['old_wall_s']:.1f} s wall), "
                    if "old_cpu_s" in r else "")
        print(f"  {old_part}now {r['new_cpu_s']:.2f} s CPU ({r['new_wall_s']:.1f} s wall); "
              f"load {r['load_before']:.1f}")
    print(f"  a forked worker from a loaded parent: {1e3 * pool:.0f} ms CPU "
          f"(POOL_START_CPU_S assumes {1e3 * _pool_constant():.0f} ms)")
    print(f"  trilith --help: {help_cpu:.2f} s CPU; heavy modules imported by the parser: "
          f"{', '.join(help_heavy) or 'none'}")
    write("cli_cost", {"machine": machine(), "command": ARGS, "reference_commit": ref["commit"],
                       "against": against, "runs": rows, "median_cpu_s_now": new,
                       "median_cpu_s_then": old, "ratio": ratio, "target_ratio": TARGET_RATIO,
                       "thresholds_identical": same, "pool_start_cpu_s": pool,
                       "help_cpu_s": help_cpu, "help_heavy_imports": help_heavy})
    return 0 if same and ratio <= TARGET_RATIO and not help_heavy else 1


def _pool_constant() -> float:
    from trilith_xval.analytic._workers import POOL_START_CPU_S
    return POOL_START_CPU_S


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
