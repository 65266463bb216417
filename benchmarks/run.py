"""Entry point of ``make bench``: run ``main()`` of every ``benchmarks/bench_*.py``.

Modules are run in name order, each isolated from the others' failures; the exit
code is 1 when any benchmark failed (a benchmark fails when its results are
wrong, e.g. verdicts that disagree, not when it is slow).
"""
from __future__ import annotations

import importlib
import sys
import time
import traceback
from pathlib import Path


def discover() -> list[str]:
    here = Path(__file__).resolve().parent
    return sorted(p.stem for p in here.glob("bench_*.py"))


def main(argv: list[str] | None = None) -> int:
    names = discover() if not argv else [n for n in discover() if n in argv]
    failed = []
    for name in names:
        module = importlib.import_module(f"benchmarks.{name}")
        entry = getattr(module, "main", None)
        if entry is None:
            continue
        print(f"=== {name} ===", flush=True)
        start = time.perf_counter()
        try:
            code = entry()
        except Exception:  # keep going: one broken benchmark must not hide the others
            traceback.print_exc()
            code = 1
        print(f"=== {name}: {'ok' if not code else 'FAILED'} "
              f"({time.perf_counter() - start:.1f} s) ===", flush=True)
        if code:
            failed.append(name)
    if failed:
        print(f"failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
