"""An engine's whole Fig. 5 engine spectrum at its calibrated threshold settings
(``engines/NAME_/thresholds.toml``, what every threshold search on a scene in
its domain starts from) against the engine's defaults (dt 1e-4 s): the CPU ratio and which
points stay within the 2 % tolerance.

``BENCH_ENGINES=pymunk,mujoco`` (default ``pymunk``, the cheapest; ``calibrated``:
every engine with a threshold file) names the engines; each result is written
as ``threshold_settings_ENGINE`` (Pymunk's also as ``threshold_settings``).

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

from trilith_xval.analytic.spectrum import overturning_spectrum
from trilith_xval.compare.campaign.settings_file import threshold_options
from trilith_xval.compare.measure import engine_spectrum as es
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.engines import configure
from trilith_xval.scenes import load_scene

from . import machine, write

DEFAULT_ENGINE = "pymunk"  # the cheapest engine


def _engines() -> list[str]:
    from trilith_xval.engines import engine_names
    text = os.environ.get("BENCH_ENGINES", DEFAULT_ENGINE)
    if text.strip() == "calibrated":
        return [e for e in engine_names() if threshold_options(e, load_scene("fig5"))]
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in engine_names()]
    if unknown or not names:
        raise ValueError(f"BENCH_ENGINES must name engines from {', '.join(engine_names())} "
                         f"or be 'calibrated', got {text!r}")
    return names


def _spectrum(engine: str, scene, ref, options: dict) -> tuple[dict, list, float]:
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    out = es.engine_spectrum(RunSpec.resolve(engine, scene, overrides=options,
                                             overrides_from="the benchmark"),
                             ref, workers=1, convergence=False)
    cost = out.cost()
    cost.update(wall_s=time.perf_counter() - t0, load_average=[load0, os.getloadavg()[0]],
                dt=out.settings["dt"])
    points = [p for curve in out.curves.values() for p in curve]
    return cost, points, load0


def main(argv: list[str] | None = None) -> int:
    quick = os.environ.get("BENCH_QUICK") == "1"
    engines = _engines()  # a bad name: refused before any run
    runs.activate(None)  # every run computed now: its CPU is measured here
    omegas = np.arange(3.0, 31.0, 4.0 if quick else 1.0)
    scene = load_scene("fig5")
    ref = overturning_spectrum(scene, omegas)
    wrong = False
    for engine in engines:
        calibrated = threshold_options(engine, scene)
        if not calibrated:
            print(f"{engine}: no calibrated threshold settings stored; nothing to compare")
            continue
        wrong |= _compare(engine, scene, ref, calibrated, quick)
    return 1 if wrong else 0


def _compare(engine: str, scene, ref, calibrated: dict, quick: bool) -> bool:
    """One engine's two spectra, printed and written; True when a bracket is too wide."""
    default_cost, default_pts, _ = _spectrum(engine, scene, ref, {"dt": configure(engine).dt})
    cal_cost, cal_pts, _ = _spectrum(engine, scene, ref, calibrated)
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
        print(f"{engine} {name} (dt {cost['dt']:g} s): {len(pts)} points, {cost['runs']} runs, "
              f"{cost['cpu_s']:.1f} CPU s ({cost['cpu_per_sim_s']:.3g} CPU s per simulated s), "
              f"{sum(p.cause == 'agrees' for p in pts)} within 2 %, load "
              f"{cost['load_average'][0]:.1f} -> {cost['load_average'][1]:.1f}", flush=True)
    print(f"{engine}: CPU ratio {ratio:.3f}x (target <= 0.25x: "
          f"{'met' if ratio <= 0.25 else 'MISSED'}); agree at the defaults but not "
          f"calibrated: {lost or 'none'} (target none: {'met' if not lost else 'MISSED'}); "
          f"agree only calibrated: {gained or 'none'}")
    payload = plain({
        "machine": machine(), "quick": quick, "engine": engine, "calibrated": calibrated,
        "defaults": default_cost, "calibrated_cost": cal_cost, "cpu_ratio": ratio,
        "points": len(default_pts), "agree_defaults": len(agree_default),
        "agree_calibrated": len(agree_cal), "lost": lost, "gained": gained,
        "rel_error": {"defaults": [p.rel_error for p in default_pts],
                      "calibrated": [p.rel_error for p in cal_pts]},
        "too_wide_at": wide})
    write(f"threshold_settings_{engine}", payload)
    if engine == DEFAULT_ENGINE:
        write("threshold_settings", payload)
    return bool(wide)


if __name__ == "__main__":
    raise SystemExit(main())
