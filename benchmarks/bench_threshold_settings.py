"""Pymunk's whole Fig. 5 engine spectrum at its calibrated threshold settings
(``docs/validation/settings/pymunk-thresholds.toml``, what every threshold search
now starts from) against the engine's defaults (dt 1e-4 s): the CPU ratio and
which points stay within the 2 % tolerance.

Omega = 3..30 rad/s step 1, both curves, the one robust search, no run store, no
convergence reruns, one worker.  ``BENCH_QUICK=1`` uses every fourth frequency.
Targets: <= 0.25x the CPU, and every point that agrees at the defaults still
agrees; a miss is printed, not hidden.  Costs are the engine runs' own CPU
seconds (``diagnostics['cpu_time']``) with the load average before and after.
Fails only when a result is wrong: a bracket wider than the search's resolution.
"""
from __future__ import annotations

import os
import time

import numpy as np

from analytic.spectrum import overturning_spectrum
from compare.campaign.settings_file import threshold_options
from compare.measure import engine_spectrum as es
from compare.run import runs
from compare.run.jsonable import plain
from engines import configure
from scenes import load_scene

from . import machine, write

ENGINE = "pymunk"  # the cheapest engine


def _spectrum(scene, ref, options: dict) -> tuple[dict, list, float]:
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    out = es.engine_spectrum(ENGINE, scene, ref, workers=1, convergence=False, **options)
    cost = out.cost()
    cost.update(wall_s=time.perf_counter() - t0, load_average=[load0, os.getloadavg()[0]],
                dt=out.settings["dt"])
    points = [p for curve in out.curves.values() for p in curve]
    return cost, points, load0


def main(argv: list[str] | None = None) -> int:
    quick = os.environ.get("BENCH_QUICK") == "1"
    runs.activate(None)  # every run computed now: its CPU is measured here
    omegas = np.arange(3.0, 31.0, 4.0 if quick else 1.0)
    scene = load_scene("fig5")
    ref = overturning_spectrum(scene, omegas)
    calibrated = threshold_options(ENGINE)
    if not calibrated:
        print(f"{ENGINE}: no calibrated threshold settings stored; nothing to compare")
        return 1
    default_cost, default_pts, _ = _spectrum(scene, ref, {"dt": configure(ENGINE).dt})
    cal_cost, cal_pts, _ = _spectrum(scene, ref, calibrated)
    ratio = cal_cost["cpu_s"] / default_cost["cpu_s"]
    key = [(p.case, p.omega) for p in default_pts]
    agree_default = {k for k, p in zip(key, default_pts) if p.cause == "agrees"}
    agree_cal = {(p.case, p.omega) for p in cal_pts if p.cause == "agrees"}
    lost = sorted(agree_default - agree_cal)
    gained = sorted(agree_cal - agree_default)
    wide = [(p.case, p.omega) for p in (*default_pts, *cal_pts) if p.bracketed
            and not p.rel_resolution <= es.DEFAULT_REL_TOL * (1 + 1e-9)]
    for name, cost, pts in (("defaults", default_cost, default_pts),
                            ("calibrated", cal_cost, cal_pts)):
        print(f"{ENGINE} {name} (dt {cost['dt']:g} s): {len(pts)} points, {cost['runs']} runs, "
              f"{cost['cpu_s']:.1f} CPU s ({cost['cpu_per_sim_s']:.3g} CPU s per simulated s), "
              f"{sum(p.cause == 'agrees' for p in pts)} within 2 %, load "
              f"{cost['load_average'][0]:.1f} -> {cost['load_average'][1]:.1f}", flush=True)
    print(f"CPU ratio {ratio:.3f}x (target <= 0.25x: {'met' if ratio <= 0.25 else 'MISSED'}); "
          f"agree at the defaults but not calibrated: {lost or 'none'} (target none: "
          f"{'met' if not lost else 'MISSED'}); agree only calibrated: {gained or 'none'}")
    write("threshold_settings", plain({
        "machine": machine(), "quick": quick, "engine": ENGINE, "calibrated": calibrated,
        "defaults": default_cost, "calibrated_cost": cal_cost, "cpu_ratio": ratio,
        "points": len(default_pts), "agree_defaults": len(agree_default),
        "agree_calibrated": len(agree_cal), "lost": lost, "gained": gained,
        "rel_error": {"defaults": [p.rel_error for p in default_pts],
                      "calibrated": [p.rel_error for p in cal_pts]},
        "too_wide_at": wide}))
    return 1 if wide else 0


if __name__ == "__main__":
    raise SystemExit(main())
