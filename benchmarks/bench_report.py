"""``make report`` cold: ``trilith report --out DIR`` with an empty run store, all
five engines, as a user runs it: a child process, its CPU seconds and those of
the workers it reaped (``RUSAGE_CHILDREN``), wall time, the load average before
and after.

Target (2 cores, low load): at most 600 CPU s and 5 min wall.  A miss is printed
and stored, not hidden; the benchmark fails only when the command fails (a
re-verified stored value that disagrees is a failure of the command) or a verdict
row is missing.  ``BENCH_STORE=1`` also writes the result to
``docs/validation/benchmarks/report_default.json``, the source of the README's
command-cost block (:mod:`benchmarks.cost_block`).
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from . import machine, timed_trilith, write

TARGET_CPU_S = 600.0
TARGET_WALL_S = 300.0
STORED = Path(__file__).resolve().parents[1] / "docs" / "validation" / "benchmarks"
ENGINES = os.environ.get("BENCH_REPORT_ENGINES", "pybullet,pymunk,mujoco,dart,drake")


def measure(extra: list[str], name: str, label: str) -> tuple[int, dict]:
    """Run ``trilith report *extra --out TMP`` with an empty run store; exit code and
    payload (``label``: the command as the README names it)."""
    with tempfile.TemporaryDirectory(prefix="bench-report-") as tmp:
        out = Path(tmp) / "report"
        argv = ["report", *extra, "--out", str(out), "--cache", str(Path(tmp) / "store")]
        proc = timed_trilith(argv)
        cpu, wall = proc.cpu_s, proc.wall_s
        doc = (json.loads((out / "summary.json").read_text())
               if (out / "summary.json").is_file() else {})
    timings = doc.get("timings") or {}
    payload = {"command": label, "argv": ["trilith", *extra, "(cold: empty run store)"],
               "engines": ENGINES.split(","), "exit_code": proc.returncode,
               "cpu_s": cpu, "wall_s": wall,
               "max_rss_mb": proc.max_rss_mb,
               "load_average": proc.load_average,
               "target_cpu_s": TARGET_CPU_S, "target_wall_s": TARGET_WALL_S,
               "met": cpu <= TARGET_CPU_S and wall <= TARGET_WALL_S,
               "verdicts": [sum(bool(v["passed"]) for v in doc.get("verdicts", [])),
                            len(doc.get("verdicts", []))],
               "cpu_by_job": timings.get("cpu_by_job"),
               # Where the wall goes: the serial model part, the engine jobs' wall,
               # and the jobs' own wall summed (over the jobs' wall: how many
               # workers were busy on average; 2 when both cores worked throughout).
               "reference_spectra_wall_s": timings.get("reference_spectra"),
               "engine_runs_wall_s": timings.get("engine_runs_wall"),
               "jobs_wall_sum_s": (sum((timings.get("spent_by_job") or {}).values())
                                   if timings.get("spent_by_job") else None),
               "reverified": [{k: r.get(k) for k in ("engine", "omega", "rel_difference",
                                                      "passed")}
                              for r in (doc.get("sources") or {}).get("reverified", [])],
               "stderr_tail": proc.stderr[-2000:], "machine": machine()}
    path = write(name, payload)
    if os.environ.get("BENCH_STORE") == "1":
        from trilith_xval.compare.run.atomic import write_text
        STORED.mkdir(parents=True, exist_ok=True)
        write_text(STORED / f"{name}.json", json.dumps(payload, indent=1, allow_nan=False))
    print(f"{payload['command']}: {cpu:.1f} CPU s (target <= {TARGET_CPU_S:g}), {wall:.1f} s "
          f"wall (target <= {TARGET_WALL_S:g}): {'met' if payload['met'] else 'MISSED'}; load "
          f"{proc.load_average[0]:.2f} -> {proc.load_average[1]:.2f}; exit {proc.returncode}; {path}")
    return proc.returncode, payload


def main(argv: list[str] | None = None) -> int:
    code, payload = measure(["--engine", ENGINES], "report_default", "make report")
    if code != 0:
        print(payload["stderr_tail"], file=sys.stderr)
        return 1
    stored = str(STORED.parent / "summary.json")
    code_from, _ = measure(["--from", stored], "report_from",
                           "trilith report --from docs/validation/summary.json")
    return 0 if code_from == 0 and payload["verdicts"][1] == 7 * len(payload["engines"]) else 1


if __name__ == "__main__":
    sys.exit(main())
