"""A whole overturning spectrum (Fig. 5), then one engine on part of its grid.

Run: .venv/bin/python docs/examples/whole_spectrum.py [OMEGA_START OMEGA_STOP]
"""
import sys

import numpy as np

from trilith_xval.analytic.spectrum import overturning_spectrum
from trilith_xval.compare.measure.engine_spectrum import engine_spectrum
from trilith_xval.compare.run.spec import RunSpec
from trilith_xval.scenes import load_scene

lo, hi = (float(sys.argv[1]), float(sys.argv[2])) if len(sys.argv) > 2 else (3.0, 30.0)
scene = load_scene("fig5")
spec = overturning_spectrum(scene, np.arange(lo, hi + 1e-9, 1.0))
for w, a_np, a_yp, gain in zip(spec.omega, spec.a_no_pendulum, spec.a_pendulum,
                               spec.gain_percent):
    print(f"Omega {w:5.1f} rad/s: A without {a_np:6.2f}, with pendulum {a_yp:6.2f} m/s^2 "
          f"(gain {gain:+5.1f} %)")
# Pymunk bisected around the model at the first two frequencies only (each ~10 s).
first = overturning_spectrum(scene, spec.omega[:2])
# The run is a value: Pymunk at its calibrated threshold step where the scene is in
# the calibration's domain (else its reference step), resolved once.
pymunk = RunSpec.resolve("pymunk", scene, calibrated=True)
for curve, points in engine_spectrum(pymunk, first).curves.items():
    for p in points:
        print(f"pymunk {curve}: Omega {p.omega:g}, A {p.a_engine:.3f} vs model "
              f"{p.a_reference:.3f} ({100 * p.rel_error:+.2f} %, {p.cause})")
