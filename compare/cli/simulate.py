"""``trilith simulate``: one run of one backend under a pulse or a recorded ground motion."""
from __future__ import annotations

import argparse
import math

from trilith_xval.analytic.contact_forces import violations

from trilith_xval.compare.cli.units import acceleration_text, frequency_text, velocity_text
from trilith_xval.compare.cli.excitation_args import (add_pulse_args, add_record_arg, check_run_budget,
                                         excitation_from_args)
from trilith_xval.compare.cli.options import (PLOT_SUFFIXES, add_engine_arg, add_scene_args, add_settings_arg,
                                 check_output_path, detail, envelope, info, print_json,
                                 run_spec, scene_from_args, settings_from_args, settings_line,
                                 sig)
from trilith_xval.compare.cli.model_options import (add_restitution_arg, restitution_factor,
                                                    restitution_text)
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.engines.geometry import STRUCTURE_ENGINES


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "simulate",
        help="simulate one pulse (or record) in one backend; verdict, events, optional CSV/plot",
        description="Run the trilith under a one-sine (Eq. 22) or one-cosine (Eq. 23) pulse, "
                    "or a recorded ground motion (--record), in one backend and report the "
                    "verdict (overturned or not, mode, time), the events and the backend's "
                    "diagnostics.  The model runs a record in its compiled kernels "
                    "(analytic-fast: the accurate path's events and verdict).")
    add_scene_args(parser)
    add_pulse_args(parser, required=False)
    add_record_arg(parser)
    add_engine_arg(parser)
    add_settings_arg(parser)
    parser.add_argument("--criterion", choices=("topple", "alpha"), default=None,
                        help="overturned at |theta| = 1.5 rad (topple) or at alpha "
                             "(default: the backend's, topple)")
    add_restitution_arg(parser)
    parser.add_argument("--t-max", type=float, default=None, metavar="S",
                        help="fixed run length [s], > 0 (default: until the verdict is "
                             "decided exactly, docs/overturning.md)")
    parser.add_argument("--json", action="store_true",
                        help="print the inputs and the trajectory summary as strict JSON")
    parser.add_argument("--csv", metavar="FILE", default=None,
                        help="write t, theta, theta_dot, psi, psi_dot samples")
    parser.add_argument("--plot", metavar="FILE.png", default=None,
                        help="write theta(t)/alpha and psi(t) with the events marked (PNG, "
                             "PDF or SVG); an engine's run is drawn over the model's")
    return parser


def _overrides(name: str, criterion: str | None, t_max: float | None,
               restitution: float = 1.0) -> dict:
    """The command line's layer of backend ``name``'s run: ``--criterion``,
    ``--t-max`` (it fixes the run's window: no early stop, in every backend) and
    ``--restitution-factor`` (the model's, set on the analytic backends only; at 1
    their settings stay the defaults)."""
    if t_max is not None and not (math.isfinite(t_max) and 0.0 < t_max <= 1e5):
        raise ValueError(f"--t-max must be a time in (0, 1e5] s, got {t_max!r}")
    options = {}
    if criterion is not None:  # configure keeps the backend's topple angle
        options["criterion"] = criterion
    if t_max is not None:  # the same fixed window in every backend: no early stop
        options["t_max"] = t_max
        if name != "analytic-fast":  # the compiled model stops only when its verdict is exact
            options["early_stop"] = False
    if restitution != 1.0 and name.startswith("analytic"):
        options["restitution_factor"] = restitution
    return options


def model_backend(engine: str, excitation) -> str:
    """The backend that runs ``engine``: a sampled record under the model
    (``analytic``) runs in its compiled kernels (``analytic-fast``: the same
    function integrated, the same events and verdict,
    ``tests/analytic/test_fast_records.py``; a long record in a fraction of the
    CPU; the accurate path stays :func:`analytic.simulate.simulate` in Python);
    anything else runs where asked."""
    if (engine == "analytic" and excitation.describe()["type"] == "record"
            and excitation.compiled_form() is not None):
        return "analytic-fast"
    return engine


def _describe_excitation(excitation) -> str:
    d = excitation.describe()
    if d["type"] == "pulse":
        return (f"{d['kind']} pulse A = {acceleration_text(d['amplitude'])}, "
                f"Omega = {frequency_text(d['omega'])}")
    if d["type"] in ("ricker", "mavroeidis-papageorgiou"):
        shape = (f"{d['kind']} Ricker wavelet, T_p = {sig(d['period'])} s" if d["type"] == "ricker"
                 else f"Mavroeidis-Papageorgiou pulse, f_p = {sig(d['frequency'])} Hz, gamma = "
                      f"{sig(d['gamma'])}, nu = {sig(d['nu'])} rad")
        return (f"{shape}, PGA {acceleration_text(excitation.pga)}, "
                f"PGV {velocity_text(excitation.pgv)}, {sig(excitation.end_time)} s")
    return (f"record {d['label']} ({d['n_samples']} samples, {sig(d['end_time'])} s, "
            f"PGA {acceleration_text(d['peak'])}, PGV {velocity_text(d['pgv'])})")


def run(args: argparse.Namespace) -> int:
    from trilith_xval.engines import get_backend

    # Every check before the run: scene, excitation, engine, settings, budget, outputs.
    scene = scene_from_args(args)
    excitation = excitation_from_args(args)
    r = restitution_factor(args)
    kind = getattr(scene, "kind", "trilith")
    if kind != "trilith":  # analytic.kinds: the engines alone, no model
        if args.engine.startswith("analytic"):
            raise ValueError(f"trilith simulate: there is no model of the {kind} kind "
                             f"(scene {scene.name!r}); run an engine: "
                             f"{', '.join(STRUCTURE_ENGINES)} (docs/geometry.md)")
        if r != 1.0:
            raise ValueError(f"--restitution-factor scales the model's impacts; there is no "
                             f"model of the {kind} kind")
    model_run = args.engine.startswith("analytic") or args.plot is not None
    if r != 1.0 and not model_run:
        raise ValueError(f"--restitution-factor scales the model's impacts, and --engine "
                         f"{args.engine} alone runs no model (add --plot to draw the model "
                         f"beside it)")
    loaded = settings_from_args(args, (args.engine,))
    name = model_backend(args.engine, excitation)
    backend = get_backend(name)
    # The run, resolved once: defaults, the --settings table, the command line.
    spec = run_spec(name, scene, excitation, loaded,
                    overrides=_overrides(name, args.criterion, args.t_max, r))
    settings = spec.settings
    check_run_budget(name, settings, excitation)
    # An engine's plot shows the model's run beside it (same scene, excitation,
    # criterion and window): what a cross-validation is read from.
    overlay = (args.plot is not None and not args.engine.startswith("analytic")
               and kind == "trilith")
    if overlay:
        model_name = model_backend("analytic", excitation)
        model_settings = run_spec(model_name, scene, excitation, overrides=_overrides(
            model_name, args.criterion, args.t_max, r)).settings
        check_run_budget(model_name, model_settings, excitation)
    if args.csv is not None:
        check_output_path(args.csv, "--csv")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", suffixes=PLOT_SUFFIXES)
    traj = backend.simulate(spec.scene, spec.excitation, settings)
    if args.csv is not None:
        from trilith_xval.compare.run.atomic import atomic_path
        with atomic_path(args.csv) as tmp:
            traj.to_csv(tmp)
    if args.plot is not None:
        model = [get_backend(model_name).simulate(scene, excitation, model_settings)
                 ] if overlay else []
        from trilith_xval.compare.show.history import plot_runs  # matplotlib: only when asked
        plot_runs(model + [traj], scene, args.plot)
    if args.json:
        summary = traj.summary()
        timings = summary.pop("timings")
        inputs = {"scene": scene.to_dict(), "excitation": excitation.describe(),
                  "engine": args.engine, "criterion": args.criterion, "t_max": args.t_max,
                  "settings_file": None if loaded is None else loaded.describe()}
        if r != 1.0:  # absent at 1: the documents of exact-impact runs stay as they were
            inputs["restitution_factor"] = r
        body = {"engine": summary.pop("engine"), "engine_version": backend.version(), **summary}
        if kind != "trilith":  # said, not left to be guessed: there is no model
            body.update(kind=kind, model=None)
        print_json(plain(envelope("simulate", inputs, body, timings)))
        return 0
    v = traj.verdict
    if kind != "trilith":
        return _print_kind(traj, scene, excitation, backend, args, loaded)
    print(f"{traj.backend}: scene {scene.name} (lam = {sig(scene.lam)}, b = {sig(scene.b)} m, "
          f"mu = {sig(scene.mu)}, gamma = {sig(scene.gamma)}), {_describe_excitation(excitation)}"
          + (f"; model {restitution_text(r, scene.has_pendulum)}" if r != 1.0 else ""))
    line = f"verdict: {v.status}"
    if v.overturned:  # the name of the time in --json and in Python's Trajectory
        line += f" ({v.mode}), overturn_time = {v.time:.4f} s"
    print(line + (f" -- {v.reason}" if v.reason else ""))
    read = traj.sampled_events()
    rule = read.rule
    up = "none" if read.uplift is None else read.uplift.text()
    over = ("" if read.exceeds_alpha is None else
            f", past alpha for good (exceeds_alpha_time) at {read.exceeds_alpha.text()}")
    print(f"uplift (|theta| = {rule.uplift_angle:g} rad): {up}, impacts (theta = 0 crossed "
          f"faster than {rule.impact_speed:g} rad/s): {read.n_impacts}{over}")
    print(f"max |theta| = {sig(traj.max_abs_theta)} rad (alpha = {sig(scene.alpha)} rad), "
          f"t_end = {traj.t[-1]:.3f} s")
    if traj.backend.startswith("analytic"):  # the model's own, exact events
        exact = traj.uplift_time
        print(f"model's exact events: lift-off {'none' if exact is None else f'{exact:.4f} s'}, "
              f"{traj.n_impacts} impacts (down to its rest speed)")
    detail(f"engine {backend.version()}, wall time {traj.wall_time:.3f} s")
    if loaded is not None:
        info(settings_line(loaded, args.engine))
    if traj.diagnostics.get("model_valid") is False:  # analytic backend: docs/model.md
        info(f"warning: the analytic model is not valid along this run: "
             f"{'; '.join(violations(traj.diagnostics))}; engines may disagree for that reason")
    if args.csv is not None:
        info(f"wrote {args.csv}")
    if args.plot is not None:
        info(f"wrote {args.plot}")
    return 0


def _print_kind(traj, scene, excitation, backend, args, loaded) -> int:
    """The text answer for a scene of another kind (:mod:`analytic.kinds`): the
    engine's verdict by the failure rule of :mod:`engines.structure_monitor`, each
    body's largest rotation over its own alpha, and that there is no model."""
    v = traj.verdict
    bodies = len(scene.layout())
    print(f"{traj.backend}: scene {scene.name} ({scene.kind}, {bodies} bodies), "
          f"{_describe_excitation(excitation)}")
    line = f"verdict: {v.status}"
    if v.time is not None:
        line += f" at t = {v.time:.4f} s"
    print(line + (f" -- {v.reason}" if v.reason else ""))
    ratios = {k.split(".", 1)[1]: x for k, x in traj.diagnostics.items()
              if k.startswith("max_angle_over_alpha.")}
    print("max |angle| / own alpha: " + ", ".join(f"{k} {sig(x)}" for k, x in ratios.items()))
    info(f"no model: the analytic model does not cover the {scene.kind} kind; compare engines "
         f"with 'trilith spectrum --scene ... --consensus E1,E2' (docs/geometry.md)")
    detail(f"engine {backend.version()}, wall time {traj.wall_time:.3f} s")
    if loaded is not None:
        info(settings_line(loaded, args.engine))
    if args.csv is not None:
        info(f"wrote {args.csv}")
    if args.plot is not None:
        info(f"wrote {args.plot}")
    return 0
