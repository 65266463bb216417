"""``trilith simulate``: one run of one backend under a one-sine/one-cosine pulse."""
from __future__ import annotations

import argparse
import dataclasses
import math

from ._common import (add_engine_arg, add_pulse_args, add_scene_args, clean_nan, print_json,
                      pulse_from_args, scene_from_args)


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "simulate",
        help="simulate one pulse in one backend; verdict, events, optional CSV/plot",
        description="Run the trilith under a one-sine (Eq. 22) or one-cosine (Eq. 23) pulse "
                    "in one backend and report the verdict (overturned or not, mode, time), "
                    "the events and the backend's diagnostics.")
    add_scene_args(parser)
    add_pulse_args(parser, required=True)
    add_engine_arg(parser)
    parser.add_argument("--criterion", choices=("topple", "alpha"), default=None,
                        help="overturned at |theta| = 1.5 rad (topple) or at alpha "
                             "[the backend's default: topple]")
    parser.add_argument("--t-max", type=float, default=None,
                        help="fixed run length [s], > 0; default: until the verdict is "
                             "decided exactly (docs/overturning.md)")
    parser.add_argument("--json", action="store_true",
                        help="print the trajectory summary as strict JSON")
    parser.add_argument("--csv", metavar="FILE", default=None,
                        help="write t, theta, theta_dot, psi, psi_dot samples")
    parser.add_argument("--plot", metavar="FILE.png", default=None,
                        help="write theta(t)/alpha and psi(t) (PNG)")
    return parser


def _settings(backend, criterion: str | None, t_max: float | None):
    """The backend's default settings with ``criterion`` and ``t_max`` replaced
    (every backend's Settings has both fields)."""
    from analytic.trajectory import OverturnCriterion
    if t_max is not None and not (math.isfinite(t_max) and t_max > 0.0):
        raise ValueError(f"--t-max must be a finite time > 0 s, got {t_max!r}")
    settings = backend.Settings()
    changes = {}
    if criterion is not None:  # keep the backend's topple angle
        changes["criterion"] = OverturnCriterion(criterion, settings.criterion.topple_angle)
    if t_max is not None:
        changes["t_max"] = t_max
    return dataclasses.replace(settings, **changes) if changes else settings


def _plot(traj, scene, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 2 if scene.has_pendulum else 1
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(7, 2.6 * rows), squeeze=False)
    ax = axes[0, 0]
    ax.plot(traj.t, traj.theta / scene.alpha, lw=1.0)
    ax.axhline(1.0, color="0.6", lw=0.6, ls="--")
    ax.axhline(-1.0, color="0.6", lw=0.6, ls="--")
    ax.set_ylabel(r"$\theta/\alpha$")
    for e in traj.impacts:
        ax.axvline(e.t, color="0.85", lw=0.5, zorder=0)
    v = traj.verdict
    ax.set_title(f"{traj.backend}: {v.status}" + (f" ({v.mode}, t = {v.time:.3f} s)"
                                                    if v.overturned else ""), fontsize=9)
    if scene.has_pendulum:
        axes[1, 0].plot(traj.t, traj.psi, lw=1.0, color="C1")
        axes[1, 0].set_ylabel(r"$\psi$ [rad]")
    axes[-1, 0].set_xlabel("t [s]")
    fig.tight_layout()
    from compare.atomic import savefig
    savefig(fig, path, dpi=120)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from engines import get_backend

    scene = scene_from_args(args)
    pulse = pulse_from_args(args)
    backend = get_backend(args.engine)
    settings = _settings(backend, args.criterion, args.t_max)
    traj = backend.simulate(scene, pulse, settings)
    if args.csv:
        from compare.atomic import atomic_path
        with atomic_path(args.csv) as tmp:
            traj.to_csv(tmp)
    if args.plot:
        _plot(traj, scene, args.plot)
    if args.json:
        print_json(clean_nan(traj.summary()))
        return 0
    v = traj.verdict
    print(f"{traj.backend}: scene {scene.name} (lam={scene.lam:g}, b={scene.b:g} m, "
          f"mu={scene.mu:g}, gamma={scene.gamma:g}), {pulse.kind} pulse "
          f"A={pulse.amplitude:g} m/s^2, Omega={pulse.omega:g} rad/s")
    line = f"verdict: {v.status}"
    if v.overturned:
        line += f" ({v.mode}) at t = {v.time:.4f} s"
    print(line + (f" -- {v.reason}" if v.reason else ""))
    up = traj.uplift_time
    print(f"uplift: {'none' if up is None else f'{up:.4f} s'}, impacts: {traj.n_impacts}, "
          f"max |theta| = {traj.max_abs_theta:.4g} rad (alpha = {scene.alpha:.4g}), "
          f"t_end = {traj.t[-1]:.3f} s, wall {traj.wall_time:.3f} s")
    if traj.diagnostics.get("model_valid") is False:  # analytic backend: docs/model.md
        d = traj.diagnostics
        print(f"warning: the analytic model is not valid along this run: the ground would have "
              f"to pull (min vertical reaction {d['min_vertical_reaction']:.3g} x weight), "
              f"the columns would hop; engines may disagree for that reason")
    if args.csv:
        print(f"wrote {args.csv}")
    if args.plot:
        print(f"wrote {args.plot}")
    return 0
