"""``trilith restitution``: free rocking from a tilt, measured vs Eq. 19/20 per impact."""
from __future__ import annotations

import argparse
import math

from trilith_xval.engines import engine_names

from trilith_xval.compare.cli.options import (add_scene_args, add_settings_arg, add_store_args, detail,
                                 envelope, info, print_json, run_spec, scene_from_args,
                                 settings_from_args, settings_line, sig, use_store)
from trilith_xval.compare.cli.model_options import add_restitution_arg, restitution_factor
from trilith_xval.compare.run.jsonable import plain

from trilith_xval.compare.measure.restitution import DEFAULT_THETA0_FRACTION


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "restitution",
        help="free-rocking restitution: measured velocity ratio per impact vs Eq. 19/20",
        description="Release the trilith at rest from a tilt theta0 with no base motion and "
                    "compare each impact's velocity ratio with Eq. 20 (no pendulum) or Eq. 19 "
                    "at the measured pendulum angle.")
    add_scene_args(parser)
    parser.add_argument("--engine", default="pymunk", metavar="NAME",
                        help="backend with free-rocking settings (theta0): "
                             + ", ".join(("analytic",) + engine_names())
                             + "; on drums or a block on a block two or more, E1,E2 "
                               "(no model: engine against engine)")
    add_settings_arg(parser)
    parser.add_argument("--theta0", type=float, default=None, metavar="RAD",
                        help="initial tilt [rad], 0 < |theta0| < alpha; sign = side "
                             f"(default: {DEFAULT_THETA0_FRACTION:g} alpha)")
    parser.add_argument("--psi0", type=float, default=0.0, metavar="RAD",
                        help="initial pendulum angle [rad], in [-pi, pi]")
    parser.add_argument("--n-impacts", type=int, default=None, metavar="N",
                        help="impacts to measure, in [1, 50] (default: 4)")
    add_restitution_arg(parser)
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    add_store_args(parser)
    return parser


def run(args: argparse.Namespace) -> int:
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.measure.restitution import (DEFAULT_N_IMPACTS, MAX_N_IMPACTS,
                                                          free_rocking)

    scene = scene_from_args(args)
    if getattr(scene, "kind", "trilith") != "trilith":  # no model: engines against each other
        from trilith_xval.compare.cli.restitution_kinds import kind_restitution
        return kind_restitution(args, scene)
    theta0 = args.theta0 if args.theta0 is not None else DEFAULT_THETA0_FRACTION * scene.alpha
    n = args.n_impacts if args.n_impacts is not None else DEFAULT_N_IMPACTS
    if not 1 <= n <= MAX_N_IMPACTS:
        raise ValueError(f"--n-impacts must be in [1, {MAX_N_IMPACTS}], got {n}")
    rf = restitution_factor(args)
    loaded = settings_from_args(args, (args.engine,))
    run = run_spec(args.engine, scene, Still(), loaded)
    use_store(args)
    result = free_rocking(run, theta0, n_impacts=n, psi0=args.psi0, restitution_factor=rf)
    if args.json:
        body = result.to_dict()
        diagnostics = dict(body.get("diagnostics") or {})
        timings = {"wall_time": body.pop("wall_time")}
        if "wall_time" in diagnostics:
            timings["engine_wall_time"] = diagnostics.pop("wall_time")
        body["diagnostics"] = diagnostics
        inputs = {"scene": scene.to_dict(), "excitation": {"type": "still"},
                  "engine": args.engine, "theta0": theta0, "psi0": args.psi0, "n_impacts": n,
                  "settings_file": None if loaded is None else loaded.describe()}
        if rf != 1.0:
            inputs["restitution_factor"] = rf
        body = {"engine": body.pop("engine"), "engine_version": body.pop("version"), **body}
        print_json(plain(envelope("restitution", inputs, body, timings)))
        return 0
    eq_name = "Eq. 19 at measured psi" if scene.has_pendulum else "Eq. 20"
    eq_name = eq_name if rf == 1.0 else f"{rf:g} x {eq_name}"
    print(f"{result.engine} ({result.version}), scene {scene.name}: lam = {sig(scene.lam)}, "
          f"mu = {sig(scene.mu)}, gamma = {sig(scene.gamma)}, theta0 = {sig(theta0)} rad")
    print(f"{'#':>3} {'t [s]':>8} {'side':>4} {'psi [rad]':>10} {'measured [-]':>12} "
          f"{'predicted [-]':>13} {'rel.err [%]':>11}   ({eq_name})")
    for k, imp in enumerate(result.impacts):
        print(f"{k + 1:>3} {imp.t:8.4f} {imp.side:+4d} {imp.psi:10.4f} "
              f"{imp.measured:12.4f} {imp.predicted:13.4f} {100 * imp.rel_error:+11.3g}")
    worst = result.max_rel_error
    print(f"max |rel. error| = {100 * worst:.3g} %" if math.isfinite(worst) else
          "no impacts measured")
    detail(f"wall time {result.wall_time:.3f} s")
    if loaded is not None:
        info(settings_line(loaded, args.engine))
    if not result.complete:
        info(f"warning: only {result.n_impacts} of {result.n_requested} impacts measured")
    return 0
