"""``trilith spectrum``: overturning spectra with and without the pendulum (Fig. 5)."""
from __future__ import annotations

import argparse
import math
import sys

from ._common import (add_scene_args, add_store_args, clean_nan, print_json, scene_from_args,
                      use_store)

DEFAULT_OMEGA = "3:30:1"  # the range of the paper's Fig. 5


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "spectrum",
        help="overturning spectrum: first overturning amplitude per frequency, with and "
             "without pendulum, and the gain Delta (Fig. 5)",
        description="For each pulse frequency, raise the amplitude from the uplift "
                    "acceleration until the first overturning, then bisect to --tol. Both "
                    "curves (with and without the pendulum), the gain "
                    "Delta = 100 (A_yp - A_np)/A_np and the overturning modes.")
    add_scene_args(parser)
    parser.add_argument("--pulse", choices=("sine", "cosine"), default="sine",
                        help="one-sine (Eq. 22) or one-cosine (Eq. 23) pulse [sine]")
    parser.add_argument("--omega", default=DEFAULT_OMEGA, metavar="START:STOP:STEP",
                        help=f"frequencies [rad/s], STOP included, or a comma list "
                             f"[{DEFAULT_OMEGA}]")
    parser.add_argument("--tol", type=float, default=None,
                        help="bisection resolution of the amplitude [m/s^2] [0.01]")
    parser.add_argument("--scan-step", type=float, default=None,
                        help="scan step floor [m/s^2] (windows narrower than the step can "
                             "be missed) [0.1]")
    parser.add_argument("--workers", type=int, default=1, help="processes, in [1, 256] [1]")
    parser.add_argument("--criterion", choices=("topple", "alpha"), default="topple",
                        help="overturned at |theta| = 1.5 rad (topple) or at alpha [topple]")
    parser.add_argument("--t-max", type=float, default=None,
                        help="fixed run length [s]; default: exact survival rules")
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    parser.add_argument("--csv", metavar="FILE", help="write the spectrum as CSV")
    parser.add_argument("--plot", metavar="FILE.png", help="write a Fig. 5-style plot")
    add_store_args(parser, scheduler=True)
    return parser


def _cached_frequency(payload):
    """One frequency (both curves) through the run store: the key is the scene,
    the search settings (pulse kind included) and Omega."""
    from compare import runs
    fn, description, omega = payload
    return runs.memo("spectrum-point", {**description, "omega": omega}, lambda: fn(omega))


def _map_fn(scene, settings, workers: int):
    """``map_fn`` for :func:`analytic.spectrum.overturning_spectrum`: each frequency
    through the store, on local processes or the ``--scheduler`` cluster."""
    from compare import runs
    from compare.store import scene_dict

    description = {"scene": scene_dict(scene), "settings": settings.describe()}

    def map_fn(fn, omegas):
        return runs.run_many(_cached_frequency, [(fn, description, w) for w in omegas],
                             workers=workers)
    return map_fn


def _settings(args: argparse.Namespace):
    from analytic.fast import Settings
    from analytic.spectrum import SpectrumSettings
    from analytic.trajectory import OverturnCriterion

    if args.t_max is not None and not (math.isfinite(args.t_max) and args.t_max > 0):
        raise ValueError(f"--t-max must be a finite time > 0 s, got {args.t_max!r}")
    if args.tol is not None and not (math.isfinite(args.tol) and 1e-6 < args.tol <= 10):
        raise ValueError(f"--tol must be in (1e-06, 10] m/s^2, got {args.tol!r}")
    if args.scan_step is not None and not (math.isfinite(args.scan_step)
                                           and 1e-4 < args.scan_step <= 100):
        raise ValueError(f"--scan-step must be in (0.0001, 100] m/s^2, got {args.scan_step!r}")
    fast = Settings(criterion=OverturnCriterion(args.criterion), t_max=args.t_max)
    kw = {"pulse": args.pulse, "fast": fast}
    if args.tol is not None:
        kw["tol"] = args.tol
    if args.scan_step is not None:
        kw["scan_step"] = args.scan_step
    if kw.get("tol", 0.01) > kw.get("scan_step", SpectrumSettings.scan_step):
        raise ValueError("--tol must not exceed --scan-step")
    return SpectrumSettings(**kw)


def plot_spectrum(spec, path) -> None:
    """Fig. 5 layout: both curves on top (dashed = without pendulum), Delta below."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.4),
                                   gridspec_kw={"height_ratios": [2, 1]})
    ax1.plot(spec.omega, spec.a_pendulum, "k-", label="with pendulum")
    ax1.plot(spec.omega, spec.a_no_pendulum, "k--", label="without pendulum")
    for jump in spec.mode_jumps():
        ax1.axvspan(jump["omega_before"], jump["omega_after"], color="0.9", zorder=0)
    ax1.set_ylabel(r"overturning amplitude $A_s$ [m/s$^2$]")
    sc = spec.scene
    ax1.set_title(f"{spec.settings.pulse} pulse, lam={sc.lam:g}, b={sc.b:g} m, "
                  f"gamma={sc.gamma:g}, mu={sc.mu:g}; {spec.criterion.kind}, "
                  f"t_max={spec.t_max}", fontsize=9)
    ax1.legend(fontsize=8)
    ax2.plot(spec.omega, spec.gain_percent, "k-")
    ax2.axhline(0.0, color="0.6", lw=0.8)
    ax2.set_xlabel(r"$\Omega$ [rad/s]")
    ax2.set_ylabel(r"gain $\Delta$ [%]")
    fig.tight_layout()
    from compare.atomic import savefig
    savefig(fig, path, dpi=120)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from analytic.spectrum import overturning_spectrum, parse_omega_range
    from compare import atomic

    scene = scene_from_args(args)
    omegas = parse_omega_range(args.omega, "--omega")
    settings = _settings(args)
    if not (1 <= args.workers <= 256):
        raise ValueError(f"--workers must be in [1, 256], got {args.workers}")
    # A bar only for a person watching (TTY); it shows up after 1 s of work.
    progress = (not args.json) and sys.stdout.isatty()
    use_store(args)
    spec = overturning_spectrum(scene, omegas, settings, progress=progress,
                                map_fn=_map_fn(scene, settings, args.workers))
    if args.csv:
        with atomic.atomic_path(args.csv) as tmp:
            spec.to_csv(tmp)
    if args.plot:
        plot_spectrum(spec, args.plot)
    if args.json:
        print_json(clean_nan(spec.to_dict()))
        return 0
    print(f"scene {scene.name}: lam={scene.lam:g} b={scene.b:g} mu={scene.mu:g} "
          f"gamma={scene.gamma:g}; {settings.pulse} pulse; criterion {settings.criterion.kind}, "
          f"t_max={settings.t_max}, tol={settings.tol:g} m/s^2, scan step "
          f"max({settings.scan_step:g}, {100 * settings.scan_rel_step:g}% A)")
    print(f"{'Omega':>7} {'A_np':>9} {'mode_np':>13} {'A_yp':>9} {'mode_yp':>13} {'Delta%':>8}")
    gain = spec.gain_percent
    for i, w in enumerate(spec.omega):
        print(f"{w:7.3g} {spec.a_no_pendulum[i]:9.3f} {spec.mode_no_pendulum[i] or '-':>13} "
              f"{spec.a_pendulum[i]:9.3f} {spec.mode_pendulum[i] or '-':>13} {gain[i]:8.1f}")
    for jump in spec.mode_jumps():
        print(f"mode jump ({jump['curve']}): {jump['mode_before']} at Omega="
              f"{jump['omega_before']:g} -> {jump['mode_after']} at {jump['omega_after']:g}")
    missing = int(sum(1 for a in list(spec.a_no_pendulum) + list(spec.a_pendulum)
                      if not math.isfinite(a)))
    if missing:
        print(f"warning: {missing} point(s) did not overturn up to a_max="
              f"{settings.a_max:g} m/s^2 (shown as nan)")
    if spec.n_undecided:
        print(f"warning: {spec.n_undecided} run(s) undecided (counted as not overturned)")
    print(f"{spec.n_runs} runs in {spec.wall_time:.2f} s")
    return 0
