"""``trilith restitution``: free rocking from a tilt, measured vs Eq. 19/20 per impact."""
from __future__ import annotations

import argparse
import math

from ._common import (add_scene_args, add_store_args, clean_nan, print_json, scene_from_args,
                      use_store)

# Half the static overturning angle: large, clean impacts far from toppling.
DEFAULT_THETA0_FRACTION = 0.5


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "restitution",
        help="free-rocking restitution: measured velocity ratio per impact vs Eq. 19/20",
        description="Release the trilith at rest from a tilt theta0 with no base motion and "
                    "compare each impact's velocity ratio with Eq. 20 (no pendulum) or Eq. 19 "
                    "at the measured pendulum angle.")
    add_scene_args(parser)
    parser.add_argument("--engine", default="pymunk",
                        help="backend with free-rocking settings (theta0): pymunk, pybullet "
                             "[pymunk]")
    parser.add_argument("--theta0", type=float, default=None,
                        help="initial tilt [rad], 0 < |theta0| < alpha; sign = side "
                             f"[{DEFAULT_THETA0_FRACTION:g} alpha]")
    parser.add_argument("--psi0", type=float, default=0.0,
                        help="initial pendulum angle [rad], in [-pi, pi] [0]")
    parser.add_argument("--n-impacts", type=int, default=None,
                        help="impacts to measure, in [1, 50] [4]")
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    add_store_args(parser)
    return parser


def run(args: argparse.Namespace) -> int:
    from engines.restitution import DEFAULT_N_IMPACTS, measure_restitution

    scene = scene_from_args(args)
    theta0 = args.theta0 if args.theta0 is not None else DEFAULT_THETA0_FRACTION * scene.alpha
    n = args.n_impacts if args.n_impacts is not None else DEFAULT_N_IMPACTS
    use_store(args)
    result = measure_restitution(args.engine, scene, theta0, n_impacts=n, psi0=args.psi0)
    if args.json:
        print_json(clean_nan(result.to_dict()))
        return 0
    eq_name = "Eq. 19 at measured psi" if scene.has_pendulum else "Eq. 20"
    print(f"{result.engine} ({result.version}), scene {scene.name}: lam={scene.lam:g} "
          f"mu={scene.mu:g} gamma={scene.gamma:g}, theta0={theta0:.4g} rad")
    print(f"{'#':>3} {'t [s]':>8} {'side':>4} {'psi [rad]':>10} {'measured':>10} "
          f"{'predicted':>10} {'rel.err':>9}   ({eq_name})")
    for k in range(result.n_impacts):
        print(f"{k + 1:>3} {result.times[k]:8.4f} {result.sides[k]:+4d} {result.psi[k]:10.4f} "
              f"{result.measured[k]:10.6f} {result.predicted[k]:10.6f} "
              f"{100 * result.rel_errors[k]:+8.3f}%")
    worst = result.max_rel_error
    print(f"max |rel. error| = {100 * worst:.3f} %" if math.isfinite(worst) else
          "no impacts measured")
    if not result.complete:
        print(f"warning: only {result.n_impacts} of {result.n_requested} impacts measured")
    return 0
