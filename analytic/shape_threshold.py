"""The first overturning peak acceleration of a pulse shape the compiled kernels
do not cover (Ricker wavelets, the Mavroeidis-Papageorgiou pulse), with the
accurate model.

:func:`analytic.first_overturn.first_overturn_amplitude` hands these shapes
here; the result has the same form, so spectra, engine spectra and reports
treat every shape alike.  The amplitude is the pulse's peak ground acceleration
(:meth:`analytic.pulses.PulseShape.at`).

The search
----------
1. Scan upwards from the uplift bound (``g/lam`` without the pendulum, Eq. 11;
   ``start_fraction g/lam`` with it, as the compiled search) on a geometric grid
   of ratio ``1 + SCAN_REL_STEP`` until the first overturn.
2. Bisect the last safe / first overturning pair down to ``tol`` [m/s^2].

Every run is :func:`analytic.simulate.simulate` with the spectrum's criterion
and window (``t_max`` None: the exact survival rules) and ``verdict_only``.

Guarantee and limit: the result is the lowest overturning amplitude of the grid
refined to ``tol``; an overturning window narrower than one grid step (5 %)
below it can be missed.  The compiled search of the sine and cosine pulses adds
a window scan (0.3 % steps) that this one does not: a run of the accurate model
costs ~20 ms (Fig. 5 scene, Ricker at Omega 11 rad/s, measured with
``time.process_time``), ~1e3 times a compiled verdict.
"""
from __future__ import annotations

import math

from .parameters import Scene

__all__ = ["SCAN_REL_STEP", "first_overturn_pga"]

# Grid ratio minus one: 60-70 runs from g/lam to 20 g/lam.
SCAN_REL_STEP = 0.05


def first_overturn_pga(scene: Scene, omega: float, ss) -> tuple[float, float, str | None,
                                                                  int, int]:
    """``(a_overturn, a_safe, mode, n_runs, n_undecided)`` of the shape
    ``ss.pulse`` at ``omega`` [rad/s] (module docstring); ``ss`` a
    :class:`analytic.first_overturn.SpectrumSettings`.  ``a_overturn`` is NaN
    (mode None) when nothing overturns up to ``ss.a_max``."""
    from .events import Settings
    from .pulses import pulse_of
    from .simulate import simulate

    settings = Settings(criterion=ss.criterion, t_max=ss.t_max, verdict_only=True,
                        sample_dt=None)
    counts = {"runs": 0, "undecided": 0}

    def verdict(a: float):
        v = simulate(scene, pulse_of(ss.pulse, a, omega), settings).verdict
        counts["runs"] += 1
        counts["undecided"] += v.status not in ("overturned", "survived")
        return v

    a0 = scene.g / scene.lam if scene.gamma == 0.0 else ss.start_fraction * scene.g / scene.lam
    if verdict(a0).overturned:  # nothing is known below the start
        raise ValueError(f"a run overturns at the scan start A={a0:.4g} m/s^2 "
                         f"(Omega={omega:g}); lower start_fraction")
    lo, hi, mode = a0, math.nan, None
    while True:
        a = lo * (1.0 + SCAN_REL_STEP)
        if a > ss.a_max:
            return math.nan, lo, None, counts["runs"], counts["undecided"]
        v = verdict(a)
        if v.overturned:
            hi, mode = a, v.mode
            break
        lo = a
    while hi - lo > ss.tol:
        mid = 0.5 * (lo + hi)
        v = verdict(mid)
        if v.overturned:
            hi, mode = mid, v.mode
        else:
            lo = mid
    return hi, lo, mode, counts["runs"], counts["undecided"]
