"""Measured rocking impacts of a square block against Housner and the engines:
writes ``docs/validation/impact_measurement.json``.

    nice -n 5 python -m benchmarks.impact_measurement --data DIR [--out PATH]
    python -m benchmarks.impact_measurement --table      # the docs table from --out

``DIR`` is the user's own copy of the drop files (``traj_<n>.csv``, e.g. the
folder ``IRB Bound/IRB Square`` of a clone of ``DAIRLab/ImpactModeling``);
nothing of them is stored, only derived numbers
(:mod:`compare.peers.impact_measure`).  Records the command, the commit, the
digest of the files read, the CPU seconds (``time.process_time``) and the load
average.  About 10 CPU s.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

SCHEMA = "trilith-xval/impact-measurement/1"
ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "validation" / "impact_measurement.json"


def _commit() -> str:
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], check=True,
                              capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def rate_noise(angle_noise: float, frame_rate: float, window: int) -> float:
    """The estimator's rate noise [rad/s] at ``angle_noise`` [rad]: the standard
    deviation of the slope at frame 0 of a least-squares parabola through frames
    ``1 .. window`` with independent noise (2.54 angle_noise x frame_rate at 4)."""
    import numpy as np
    k = np.arange(1, window + 1, dtype=float)
    x = np.stack([np.ones_like(k), k, k * k], axis=1)
    return float(np.sqrt(np.linalg.inv(x.T @ x)[1, 1]) * angle_noise * frame_rate)


def table(doc: dict) -> str:
    """The Markdown table of ``docs/measured-impacts.md`` from a stored document."""
    s = doc["summary"]
    m = s["measured"]
    lines = ["| ratio theta_dot+/theta_dot- | mean | median | std | p25 | p75 "
             "| RMS error vs measured | median abs. error |",
             "|---|---|---|---|---|---|---|---|",
             f"| measured ({s['impacts']} impacts, {s['files_with_impacts']} drops) | "
             f"{m['mean']:+.3f} | {m['median']:+.3f} | {m['std']:.3f} | {m['p25']:+.3f} | "
             f"{m['p75']:+.3f} | | |",
             f"| Housner (Eq. 20, mu = gamma = 0) | {s['housner']:+.3f} | | | | | "
             f"{s['housner_rms_error']:.3f} | {s['housner_median_abs_error']:.3f} |",
             f"| best single value (the measured mean / median) | | | | | | "
             f"{s['floor_any_single_value']:.3f} | {s['floor_any_single_value_mad']:.3f} |"]
    for key, e in s["engines"].items():
        lines.append(f"| {key} replaying each impact | {e['mean']:+.3f} | {e['median']:+.3f} | "
                     f"{e['std']:.3f} | {e['p25']:+.3f} | {e['p75']:+.3f} | "
                     f"{e['rms_error']:.3f} | {e['median_abs_error']:.3f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, help="folder of the user's traj_<n>.csv files")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--table", action="store_true", help="print the docs table from --out")
    args = ap.parse_args(argv)
    if args.table:
        print(table(json.loads(args.out.read_text())))
        return 0
    if args.data is None:
        ap.error("--data DIR is needed (a folder of traj_<n>.csv files)")
    from trilith_xval.compare.peers import impact_data, impact_measure, impact_replay

    load0, cpu0 = os.getloadavg(), time.process_time()
    res = impact_measure.measure(args.data)
    noise = rate_noise(res["angle_noise"], impact_data.FRAME_RATE, res["filter"]["window"])
    doc = {"schema": SCHEMA,
           "command": "nice -n 5 python -m benchmarks.impact_measurement --data DIR",
           "commit": _commit(), "python": platform.python_version(),
           "engines": impact_replay.engine_versions(),
           "units": "SI: m, s, rad; ratios are theta_dot+/theta_dot- (signed)",
           "data": {**impact_measure.DATA_SOURCE, "files_read": res["files"],
                    "sha256": impact_measure.files_digest(args.data)},
           "filter": res["filter"], "theta_offset": res["theta_offset"],
           "angle_noise": res["angle_noise"], "rate_noise": noise,
           "frictions": list(impact_measure.FRICTIONS), "rejected": res["rejected"],
           "summary": impact_measure.summarise(res["rows"], res["housner"], noise),
           "estimator_sensitivity": impact_measure.estimator_sensitivity(args.data),
           "rows": res["rows"], "load_average_start": list(load0)}
    doc["cpu_s"] = time.process_time() - cpu0
    doc["load_average_end"] = list(os.getloadavg())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc, indent=1) + "\n")
    print(table(doc))
    print(f"wrote {args.out} ({doc['cpu_s']:.1f} CPU s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
