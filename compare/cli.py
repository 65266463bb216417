"""``trilith``: the command-line front door.

Bad input ends with a one-line ``error: ...`` on stderr naming the parameter and
its allowed range, exit code 2 (argparse's convention), never a traceback.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from .commands import COMMANDS


class UsageError(ValueError):
    """Raised for bad command-line values; reported with exit code 2."""


def build_parser() -> tuple[argparse.ArgumentParser, dict]:
    parser = argparse.ArgumentParser(
        prog="trilith",
        description="Cross-validate PyBullet and Pymunk against the analytic rocking "
                    "model of a trilith with a pendulum mass absorber.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    modules = {}
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"compare.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"compare.commands.{name}":
                continue
            raise
        module.add_parser(sub)
        modules[name] = module
    return parser, modules


def main(argv: list[str] | None = None) -> int:
    parser, modules = build_parser()
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_help()
        return 2
    try:
        return int(modules[args.command].run(args) or 0)
    except ValueError as exc:  # includes UsageError: validation at the boundary
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pending work was cancelled (compare.runs.run_many)
        print("interrupted: cancelled; finished runs are kept in the run store",
              file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
