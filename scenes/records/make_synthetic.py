"""Write the shipped synthetic suite ``synthetic/*.csv``: twelve ground motions
from a published stochastic model, so that a fragility curve needs no download.

Not real earthquakes.  Each motion is stationary white noise (numpy PCG64, seed
``SEED + k`` for motion ``k``) filtered by the **Clough-Penzien** filter (a
Kanai-Tajimi ground filter followed by a high-pass that removes the white
noise's unbounded low-frequency displacement; Clough & Penzien, *Dynamics of
Structures*, McGraw-Hill 1975, section 25; Kanai 1957, Tajimi 1960), with the
firm, medium and soft soil parameters of Der Kiureghian & Neuenhofer (1992,
"Response spectrum method for multi-support seismic excitations", *Earthquake
Engng Struct. Dyn.* 21, 713-740):

======  ===============  ======  ===============  ======
soil    omega_g [rad/s]  zeta_g  omega_f [rad/s]  zeta_f
======  ===============  ======  ===============  ======
firm    15.0             0.6     1.5              0.6
medium  10.0             0.4     1.0              0.6
soft     5.0             0.2     0.5              0.6
======  ===============  ======  ===============  ======

four motions per soil, times a **Saragoni-Hart** envelope (Saragoni & Hart
1974, "Simulation of artificial earthquakes", *Earthquake Engng Struct. Dyn.*
2, 249-267) ``e(t) = (t / t_p)^2 exp(2 (1 - t / t_p))`` (shape ``t^b e^{-ct}``
with ``b = 2``, normalised to 1 at its peak ``t_p = 2.5 s``; 1 % of the peak at
the end), 12 s long at 100 samples per second (1201 samples), then scaled to a
peak ground acceleration between 0.15 g and 0.45 g (geometric steps over the
twelve, firm, medium and soft interleaved; incremental dynamic analysis rescales
every motion anyway: the PGA only makes the files look like records).

The filters are integrated by semi-implicit Euler at a tenth of the output step,
the white noise held over each output step (the filtered process is the model;
its discretisation is part of this generator).  Output: CSV ``t [s], a [m/s^2]``
(6 decimals), like ``sample.csv``.  Generated here, under the project's licence
(MIT).  ``python scenes/records/make_synthetic.py [DIR]`` rewrites the files
(into ``DIR``, default ``synthetic/`` beside this script) bit for bit: pure
Python arithmetic on numpy's PCG64 stream, which numpy keeps stable.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FOLDER = HERE / "synthetic"
SEED = 20260301
DT = 0.01  # s
DURATION = 12.0  # s
T_PEAK = 2.5  # s, the envelope's peak
G = 9.80665  # m/s^2
PGA_RANGE_G = (0.15, 0.45)
# (name, omega_g [rad/s], zeta_g, omega_f [rad/s], zeta_f): Der Kiureghian &
# Neuenhofer 1992.
SOILS = (("firm", 15.0, 0.6, 1.5, 0.6), ("medium", 10.0, 0.4, 1.0, 0.6),
         ("soft", 5.0, 0.2, 0.5, 0.6))
N_PER_SOIL = 4
SUBSTEPS = 10


def motion_plan() -> list[tuple[str, int, tuple, float]]:
    """``(file name, seed, soil row, PGA [m/s^2])`` of each motion, in order."""
    n = N_PER_SOIL * len(SOILS)
    pgas = np.geomspace(PGA_RANGE_G[0], PGA_RANGE_G[1], n) * G
    plan = []
    for k in range(n):
        soil = SOILS[k % len(SOILS)]  # interleaved: every soil spans the PGA range
        plan.append((f"cp-{k + 1:02d}-{soil[0]}.csv", SEED + k, soil, float(pgas[k])))
    return plan


def clough_penzien(seed: int, soil: tuple, pga: float) -> tuple[np.ndarray, np.ndarray]:
    """``(t, a)``: one motion, times [s] from 0 and accelerations [m/s^2].

    Kanai-Tajimi: ``x'' + 2 zg wg x' + wg^2 x = -w``, its absolute acceleration
    ``f = 2 zg wg x' + wg^2 x``; Clough-Penzien high-pass:
    ``y'' + 2 zf wf y' + wf^2 y = f``, the ground acceleration ``a = y''
    = f - 2 zf wf y' - wf^2 y`` (transfer ``-w^2 / (wf^2 - w^2 + 2 i zf wf w)``).
    """
    _name, wg, zg, wf, zf = soil
    n = int(round(DURATION / DT)) + 1
    t = DT * np.arange(n)
    noise = np.random.default_rng(seed).standard_normal(n).tolist()
    h = DT / SUBSTEPS
    x = v = y = u = 0.0
    a = [0.0] * n
    for k in range(n):
        w = noise[k]
        for _ in range(SUBSTEPS):
            v += h * (-w - 2.0 * zg * wg * v - wg * wg * x)
            x += h * v
            f = 2.0 * zg * wg * v + wg * wg * x
            u += h * (f - 2.0 * zf * wf * u - wf * wf * y)
            y += h * u
        a[k] = f - 2.0 * zf * wf * u - wf * wf * y
    env = [(tk / T_PEAK) ** 2 * math.exp(2.0 * (1.0 - tk / T_PEAK)) for tk in t.tolist()]
    acc = np.array([ak * ek for ak, ek in zip(a, env)])
    acc[0] = 0.0  # the ground starts at rest
    return t, acc * (pga / float(np.max(np.abs(acc))))


def write_csv(path: Path, t: np.ndarray, a: np.ndarray, soil: tuple, seed: int) -> None:
    name, wg, zg, wf, zf = soil
    with open(path, "w", newline="\n") as fh:
        fh.write("# synthetic ground motion (not a real record), "
                 "scenes/records/make_synthetic.py\n")
        fh.write(f"# Clough-Penzien {name} soil: omega_g {wg:g} rad/s, zeta_g {zg:g}, "
                 f"omega_f {wf:g} rad/s, zeta_f {zf:g}; Saragoni-Hart envelope, peak "
                 f"{T_PEAK:g} s; seed {seed}; PGA {np.max(np.abs(a)):.6f} m/s^2\n")
        fh.write("t,a\n")
        for ti, ai in zip(t.tolist(), a.tolist()):
            fh.write(f"{ti:.2f},{ai:.6f}\n")


def main(folder: Path = FOLDER) -> list[Path]:
    """Write every motion of :func:`motion_plan` into ``folder``; the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name, seed, soil, pga in motion_plan():
        t, a = clough_penzien(seed, soil, pga)
        write_csv(folder / name, t, a, soil, seed)
        out.append(folder / name)
    return out


if __name__ == "__main__":
    written = main(Path(sys.argv[1]) if len(sys.argv) > 1 else FOLDER)
    print(f"wrote {len(written)} motions into {written[0].parent}")
