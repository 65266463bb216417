"""A sampled design of triliths for calibration: a training set and a held-out set.

A calibrated setting holds where it was measured.  So ``trilith calibrate
--design N,M`` does not tune on the paper's Fig. 5 alone: it samples what a user
changes (:data:`engines.calibration.COORDINATES`) by Latin hypercube
(:class:`scipy.stats.qmc.LatinHypercube`, fixed seed) over :data:`RANGES`, picks
the cheapest settings within the tolerance on ``N`` training scenes and reports
the worst error of those settings on ``M`` held-out scenes drawn from the same
ranges with another seed.  The ranges become the settings' domain
(:class:`engines.calibration.Domain`); both curves (with and without the
pendulum) are measured, so the pendulum-free curve is in the domain too.

Frequencies: each scene's threshold spectrum scales with its rocking frequency
parameter ``p = sqrt(3 g / (4 R))`` (Housner 1963; ``R`` the column's half
diagonal), so each scene is measured at ``Omega = p x`` :data:`OMEGA_OVER_P`,
across its band (Fig. 5: 5.5-18.6 rad/s of the paper's 3-30).  Points where the
model itself is invalid are not counted against the engine (the cause search
names them, after the step rule).
"""
from __future__ import annotations

import math

__all__ = ["RANGES", "OMEGA_OVER_P", "design_scenes", "scene_omegas", "domain_table", "SEED"]

# The paper's ranges (Figs. 8, 9, 11: lam 3-7, b 0.2-0.8 m, mu 0.5-4, gamma
# 0.1-0.3) widened a little where a monument plausibly goes (gamma to 0.4), and
# the pendulum length, gap and lintel thickness around the paper's 2h/3, h, b/2.
RANGES = {"lam": (3.0, 7.0), "b": (0.2, 0.8), "mu": (0.5, 4.0), "gamma": (0.1, 0.4),
          "l_over_h": (0.4, 0.9), "gap_over_h": (0.6, 1.4),
          "lintel_height_over_b": (0.3, 0.8)}
OMEGA_OVER_P = (2.5, 4.0, 6.0, 8.5)
SEED = 34  # training set; the held-out set uses SEED + 1


def design_scenes(n: int, seed: int = SEED, ranges: dict | None = None,
                  prefix: str = "design") -> list:
    """``n`` triliths by Latin hypercube over ``ranges`` (default :data:`RANGES`),
    named ``prefix1`` ... ``prefixN``; values rounded to 4 decimals (SI)."""
    from scipy.stats import qmc

    from trilith_xval.analytic.parameters import Scene
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 200:
        raise ValueError(f"n must be an integer in [1, 200], got {n!r}")
    ranges = dict(RANGES if ranges is None else ranges)
    names = list(ranges)
    unit = qmc.LatinHypercube(d=len(names), seed=seed).random(n)
    out = []
    for i, row in enumerate(unit):
        v = {k: ranges[k][0] + u * (ranges[k][1] - ranges[k][0]) for k, u in zip(names, row)}
        h = v["lam"] * v["b"]
        out.append(Scene(b=round(v["b"], 4), lam=round(v["lam"], 4), mu=round(v["mu"], 4),
                         gamma=round(v["gamma"], 4), l=round(v["l_over_h"] * h, 4),
                         gap=round(v["gap_over_h"] * h, 4),
                         lintel_height=round(v["lintel_height_over_b"] * v["b"], 4),
                         name=f"{prefix}{i + 1}"))
    return out


def scene_omegas(scene) -> list[float]:
    """The design's pulse frequencies for ``scene`` [rad/s] (module docstring)."""
    p = math.sqrt(3.0 * scene.g / (4.0 * scene.R))
    return [round(p * f, 3) for f in OMEGA_OVER_P]


def domain_table(ranges: dict | None = None) -> dict:
    """The ``[domain]`` table of a settings file calibrated on these ranges (both
    curves).  The sampled values are rounded to 4 decimals, so a design scene's
    ratios (l/h, gap/h) may sit up to ~1e-4 outside these ranges."""
    ranges = dict(RANGES if ranges is None else ranges)
    return {**{k: [float(lo), float(hi)] for k, (lo, hi) in ranges.items()},
            "no_pendulum": True}
