"""DART's body deactivation against a threshold: the same atlas point searched
with dartpy's default deactivation (bodies slower than 0.01 m/s and 0.05 rad/s
for 0.5 s have every velocity set to 0) and with it switched off
(``Settings.deactivation``, ``engines/dart_/__init__.py``).

Run: ``python -m benchmarks.dart_deactivation [SCENE ...]`` (no run store; about 13
CPU min for the first five points; scene names select points).
Prints one line per point and setting: the atlas's cause, the relative error
against the model, the engine's threshold [m/s^2] and the CPU seconds.  The first
two points are DART's atlas points that stay ``window`` at its calibrated step
(2e-4 s) and at its reference step (docs/atlas.md); the next three try to break the
finding at fig9_lam7_b0.8: the neighbouring frequencies 5.8 and 6.2 rad/s, and the
reference step 1e-4 s at 6 rad/s; the last two are DART's other ``window`` points of
the stored atlas at its calibrated step.  docs/dart.md states the result.
"""
from __future__ import annotations

import sys
import time

# (scene, case, pulse, Omega [rad/s], step [s]): the model's threshold and mode come
# from the analytic spectrum at its defaults (the atlas's reference).
POINTS = (("fig8_lam7_gamma0.2", "pendulum", "sine", 8.0, 2e-4),
          ("fig9_lam7_b0.8", "pendulum", "sine", 6.0, 2e-4),
          ("fig9_lam7_b0.8", "pendulum", "sine", 5.8, 2e-4),
          ("fig9_lam7_b0.8", "pendulum", "sine", 6.2, 2e-4),
          ("fig9_lam7_b0.8", "pendulum", "sine", 6.0, 1e-4),
          ("fig8_lam7_gamma0.3", "pendulum", "sine", 10.0, 2e-4),
          ("fig9_lam7_b0.6", "pendulum", "sine", 10.0, 2e-4))


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.analytic.spectrum import overturning_spectrum
    from trilith_xval.compare.campaign.study import ThresholdJob, run_threshold
    from trilith_xval.compare.run import runs
    from trilith_xval.scenes import load_scene

    runs.activate(None)
    chosen = set(sys.argv[1:] if argv is None else argv)
    unknown = chosen - {p[0] for p in POINTS}
    if unknown:
        print(f"error: scene: {', '.join(sorted(unknown))} is not a probed point "
              f"({', '.join(sorted({p[0] for p in POINTS}))})", file=sys.stderr)
        return 2
    for scene, case, pulse, omega, dt in POINTS:
        if chosen and scene not in chosen:
            continue
        ref = overturning_spectrum(load_scene(scene), [omega])
        a_ref = float((ref.a_pendulum if case == "pendulum" else ref.a_no_pendulum)[0])
        mode = (ref.mode_pendulum if case == "pendulum" else ref.mode_no_pendulum)[0]
        for label, awake in (("deactivation on (dartpy default)", False),
                             ("deactivation off", True)):
            options = (("deactivation", False),) if awake else ()
            t0 = time.process_time()
            row = run_threshold(ThresholdJob(scene, case, pulse, omega, a_ref, mode, "dart",
                                             dt, 0.03, 4e-3, options))
            print(f"{label}: {scene} {case} Omega {omega:g} dt {dt:g} s: {row['cause']}, "
                  f"{100 * row['rel_error']:+.2f} %, A_dart {row['a_engine']:.5g} m/s^2 "
                  f"(model {a_ref:.5g}), {time.process_time() - t0:.0f} CPU s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
