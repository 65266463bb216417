"""Options of the analytic model itself (not of a scene, not of an engine):
``--restitution-factor``, shared by the commands that run the model.

Checked at the door like every option (:mod:`compare.cli.options`): a
``ValueError`` naming the option and its range, before any work.
"""
from __future__ import annotations

import argparse
import math

__all__ = ["add_restitution_arg", "restitution_factor", "restitution_text"]


def add_restitution_arg(parser: argparse.ArgumentParser) -> None:
    """``--restitution-factor R``; read with :func:`restitution_factor`."""
    parser.add_argument(
        "--restitution-factor", default=None, metavar="R",
        help="measured restitution: the model's impact ratio (Eq. 20 without pendulum, "
             "Eq. 19 with it) times R, in (0, 1] (default 1: the exact impact); engines "
             "run beside the model are compared with this scaled model (docs/model.md)")


def restitution_factor(args: argparse.Namespace) -> float:
    """The ``--restitution-factor`` given (1.0 when absent), refused outside (0, 1].

    0 would stop every rocking at its first impact and above 1 an impact would
    create energy: neither is a restitution a block can have.
    """
    text = getattr(args, "restitution_factor", None)
    if text is None:
        return 1.0
    try:  # read here, not by argparse: its error would not be the door's one line
        value = float(text)
    except (TypeError, ValueError):
        raise ValueError(f"--restitution-factor must be a number in (0, 1], "
                         f"got {text!r}") from None
    if not (math.isfinite(value) and 0.0 < value <= 1.0):
        raise ValueError(f"--restitution-factor must be in (0, 1], got {value!r}")
    return value


def restitution_text(r: float, pendulum: bool) -> str:
    """``''`` at 1, else a clause saying what the model's impacts are."""
    if r == 1.0:
        return ""
    return f"restitution factor {r:g} (impact ratio {r:g} x Eq. {19 if pendulum else 20})"
