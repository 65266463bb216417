"""Write the synthetic sample ground motion ``sample.csv`` and ``sample.AT2``.

Not a real earthquake: white noise (fixed seed) through a Kanai-Tajimi filter
(ground frequency 15 rad/s, damping 0.6, the values Kanai and Tajimi proposed for
firm soil) under a Saragoni-Hart envelope ``(t/t_peak)^2 exp(2 (1 - t/t_peak))``
peaking at 2 s, 10 s long at 100 samples per second, scaled to a peak ground
acceleration of 4 m/s^2 (enough to rock the Fig. 5 trilith, whose uplift needs
g/lam = 1.96 m/s^2).  The same samples are written as CSV (t [s], a [m/s^2]) and
as a PEER NGA ``.AT2`` file (accelerations in g), so both readers of
``scenes.ground_motion`` have a file to read.

Run ``python scenes/records/make_sample.py`` to rewrite both files; the output is
committed, and deterministic for a given numpy (PCG64 stream, fixed seed).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DT = 0.01  # s
DURATION = 10.0  # s
PGA = 4.0  # m/s^2
OMEGA_G, ZETA_G = 15.0, 0.6  # Kanai-Tajimi firm soil
T_PEAK = 2.0  # s
G = 9.80665  # m/s^2, the g of PEER files
SEED = 20260101


def synthetic_record() -> tuple[np.ndarray, np.ndarray]:
    """``(t, a)``: times [s] from 0 and accelerations [m/s^2]."""
    n = int(round(DURATION / DT)) + 1
    t = DT * np.arange(n)
    w = np.random.default_rng(SEED).standard_normal(n)
    # Kanai-Tajimi: x'' + 2 z wg x' + wg^2 x = -w; ground acceleration
    # a = 2 z wg x' + wg^2 x (absolute acceleration of the filter mass), by
    # semi-implicit Euler at a tenth of the output step.
    x = v = 0.0
    a = np.empty(n)
    sub = 10
    h = DT / sub
    for k in range(n):
        for _ in range(sub):
            v += h * (-w[k] - 2 * ZETA_G * OMEGA_G * v - OMEGA_G ** 2 * x)
            x += h * v
        a[k] = 2 * ZETA_G * OMEGA_G * v + OMEGA_G ** 2 * x
    envelope = (t / T_PEAK) ** 2 * np.exp(2.0 * (1.0 - t / T_PEAK))
    a = a * envelope
    a[0] = 0.0
    return t, a * (PGA / np.max(np.abs(a)))


def write_csv(path: Path, t: np.ndarray, a: np.ndarray) -> None:
    with open(path, "w") as fh:
        fh.write("# synthetic ground motion, scenes/records/make_sample.py (not a real record)\n")
        fh.write("t,a\n")
        for ti, ai in zip(t, a):
            fh.write(f"{ti:.2f},{ai:.6f}\n")


def write_at2(path: Path, a: np.ndarray) -> None:
    g = a / G
    with open(path, "w") as fh:
        fh.write("PEER NGA STRONG MOTION DATABASE RECORD\n")
        fh.write("Synthetic sample, scenes/records/make_sample.py (not a real record)\n")
        fh.write("ACCELERATION TIME SERIES IN UNITS OF G\n")
        fh.write(f"NPTS= {len(g):6d}, DT= {DT:.4f} SEC\n")
        for i in range(0, len(g), 5):
            fh.write("".join(f"{x:15.7E}" for x in g[i:i + 5]) + "\n")


def main() -> None:
    t, a = synthetic_record()
    write_csv(HERE / "sample.csv", t, a)
    write_at2(HERE / "sample.AT2", a)
    print(f"wrote {HERE / 'sample.csv'} and sample.AT2: {len(t)} samples, {t[-1]:g} s, "
          f"PGA {np.max(np.abs(a)):.3g} m/s^2")


if __name__ == "__main__":
    main()
