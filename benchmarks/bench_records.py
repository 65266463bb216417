"""Cost of a recorded ground motion against its length: CPU seconds per sample of
the model (with and without the pendulum) and of Pymunk, on the synthetic sample
record (``scenes/records/make_sample.py``) resampled at 0.5 ms and tiled to
1e4 and 1e5 samples (``python -m benchmarks.bench_records 1000000`` adds 1e6:
500 s of record).  Scaled by 0.5 (PGA 2 m/s^2, near uplift): the trilith rests
most of the time and rocks now and then.  Each run covers the whole record
(``t_max`` = its end).  The cost must grow linearly: the printed us/sample stays
flat.  Fails if a run ends undecided or unstable.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

DT = 5e-4  # s


def tiled_record(n: int):
    from trilith_xval.analytic.excitation import SampledRecord
    from trilith_xval.scenes.records.make_sample import synthetic_record
    t0, a0 = synthetic_record()
    tf = np.arange(0.0, 10.0, DT)
    af = 0.5 * np.interp(tf, t0, a0)
    a = np.tile(af, n // af.size + 1)[:n]
    return SampledRecord(tuple(DT * np.arange(n)), tuple(a), f"tiled-{n}")


def main(argv: list[str] | None = None) -> int:
    from trilith_xval import engines
    from trilith_xval.scenes import load_scene
    sizes = [10_000, 100_000] + [int(x) for x in (argv or [])]
    fig5 = load_scene("fig5")
    bad = 0
    for n in sizes:
        rec = tiled_record(n)
        for backend, scene in (("analytic", fig5.without_pendulum()), ("analytic", fig5),
                               ("pymunk", fig5)):
            settings = engines.configure(backend, t_max=rec.end_time)
            c0 = time.process_time()
            tr = engines.simulate(backend, scene, rec, settings)
            cpu = time.process_time() - c0
            bad += tr.verdict.status in ("undecided", "unstable")
            print(f"{backend:8s} {'pendulum' if scene.has_pendulum else 'bare':8s} n={n:>8d} "
                  f"({rec.end_time:6.1f} s): {cpu:7.2f} CPU s, {1e6 * cpu / n:6.1f} us/sample, "
                  f"{tr.verdict.status}, {tr.verdict.n_impacts} impacts, "
                  f"load {os.getloadavg()[0]:.1f}", flush=True)
    return int(bad > 0)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
