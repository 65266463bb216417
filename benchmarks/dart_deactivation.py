"""DART's body deactivation against a threshold: the same atlas point searched
with dartpy's default deactivation (bodies slower than 0.01 m/s and 0.05 rad/s
for 0.5 s have every velocity set to 0) and with it switched off.

Run: ``python -m benchmarks.dart_deactivation`` (no run store; about 4 CPU min).
Prints one line per point and setting: the atlas's cause, the relative error
against the model, the engine's threshold [m/s^2] and the CPU seconds.  The points
are DART's atlas points that stay ``window`` at its calibrated step (2e-4 s) and
at its reference step (docs/atlas.md); docs/dart.md states the result.
"""
from __future__ import annotations

import sys
import time

# (scene, case, pulse, Omega [rad/s], model threshold [m/s^2], model mode): the
# stored atlas's points (docs/validation/atlas.json).
POINTS = (("fig8_lam7_gamma0.2", "pendulum", "sine", 8.0, 3.574894238831695, "after-impact"),
          ("fig9_lam7_b0.8", "pendulum", "sine", 6.0, 2.9307142857142865, "after-impact"))


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.compare.campaign.study import ThresholdJob, run_threshold
    from trilith_xval.compare.run import runs
    from trilith_xval.engines.dart_ import world

    runs.activate(None)
    built = world.DartWorld.__init__

    def awake(self, *args, **kwargs):
        built(self, *args, **kwargs)
        options = self.world.getDeactivationOptions()
        options.mEnabled = False
        self.world.setDeactivationOptions(options)
    try:
        for label, init in (("deactivation on (dartpy default)", built),
                            ("deactivation off", awake)):
            world.DartWorld.__init__ = init
            for point in POINTS:
                t0 = time.process_time()
                row = run_threshold(ThresholdJob(*point, "dart", 2e-4, 0.03, 4e-3, ()))
                print(f"{label}: {point[0]} {point[1]} Omega {point[3]:g}: {row['cause']}, "
                      f"{100 * row['rel_error']:+.2f} %, A_dart {row['a_engine']:.5g} m/s^2 "
                      f"(model {point[4]:.5g}), {time.process_time() - t0:.0f} CPU s",
                      flush=True)
    finally:
        world.DartWorld.__init__ = built
    return 0


if __name__ == "__main__":
    sys.exit(main())
