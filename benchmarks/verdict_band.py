"""The verdict of an engine at evenly spaced amplitudes across a threshold: where a
search finds no robust bracket, this shows whether the engine's outcome flickers
(survives and overturns alternately) and over how wide a band.

``python -m benchmarks.verdict_band ENGINE SCENE OMEGA DT LO HI N OUT.json``
runs N one-sine pulses of amplitude LO..HI [m/s^2] at OMEGA [rad/s] with the step DT
[s] (the rest of the engine's threshold settings as every search uses them:
:func:`compare.measure.engine_spectrum.pulse_settings`) and writes each verdict
with its CPU seconds and the load average.
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

from trilith_xval import engines
from trilith_xval.analytic import Pulse
from trilith_xval.compare.measure.engine_spectrum import pulse_settings
from trilith_xval.scenes import load_scene


def band(engine: str, scene, omega: float, dt: float, lo: float, hi: float, n: int) -> list:
    settings = pulse_settings(engine, scene, 2.0 * hi, omega, options={"dt": dt})
    rows = []
    for a in np.round(np.linspace(lo, hi, n), 6):
        t0 = time.process_time()
        verdict = engines.simulate(engine, scene, Pulse(float(a), omega), settings).verdict
        rows.append({"amplitude": float(a), "status": verdict.status,
                     "mode": verdict.mode if verdict.overturned else None,
                     "cpu_s": time.process_time() - t0})
    return rows


def main(argv: list[str]) -> None:
    engine, scene_name, omega, dt, lo, hi, n, out = argv
    scene = load_scene(scene_name)
    load = os.getloadavg()
    rows = band(engine, scene, float(omega), float(dt), float(lo), float(hi), int(n))
    doc = {"command": "python -m benchmarks.verdict_band " + " ".join(argv),
           "engine": engine, "version": engines.get_backend(engine).version(),
           "scene": scene_name, "omega": float(omega), "dt": float(dt), "rows": rows,
           "cpu_s": sum(r["cpu_s"] for r in rows), "load_average": [load, os.getloadavg()]}
    with open(out, "w") as fh:
        json.dump(doc, fh, indent=1)


if __name__ == "__main__":
    main(sys.argv[1:])
