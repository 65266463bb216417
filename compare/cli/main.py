"""``trilith``: the command-line front door.

Bad input ends with a one-line ``error: ...`` on stderr naming the option and
its allowed range, exit code 2 (argparse's convention), never a traceback.
A closed pipe (``trilith ... --json | head``) ends quietly.
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import sys

from compare.cli import COMMANDS
from engines import engine_names


class UsageError(ValueError):
    """Raised for bad command-line values; reported with exit code 2."""


def _version() -> str:
    try:
        from importlib.metadata import PackageNotFoundError, version
        return version("trilith-xval")
    except PackageNotFoundError:  # a source checkout that was never installed
        return "unknown (not installed)"


class HelpFormatter(argparse.HelpFormatter):
    """Shows every default that is a value (not None/False) as ``(default: X)``,
    turns reST ``literal`` markup into plain text, and keeps the line breaks of
    multi-line descriptions (module docstrings) while wrapping one-liners."""

    def _get_help_string(self, action):
        text = action.help or ""
        if ("%(default)" not in text and action.option_strings
                and action.default not in (None, False, argparse.SUPPRESS, [])
                and action.nargs != 0):
            text += " (default: %(default)s)"
        return text

    def _format_text(self, text):
        text = _plain(text)
        if "\n" in text.strip():  # a docstring: laid out by hand
            return argparse.RawDescriptionHelpFormatter._format_text(self, text)
        return super()._format_text(text)

    def _expand_help(self, action):
        return _plain(super()._expand_help(action))


def _plain(text: str) -> str:
    return re.sub(r"``([^`]+)``", r"'\1'", text) if text else text


class _Parser(argparse.ArgumentParser):
    """Subcommand parser: the help formatter above and the -q/-v switches."""

    def __init__(self, *args, **kwargs):
        kwargs["formatter_class"] = HelpFormatter
        if kwargs.get("description"):
            kwargs["description"] = _plain(kwargs["description"])
        super().__init__(*args, **kwargs)
        group = self.add_mutually_exclusive_group()
        group.add_argument("-q", "--quiet", dest="verbosity", action="store_const", const=-1,
                           default=0, help="print only results and errors")
        group.add_argument("-v", "--verbose", dest="verbosity", action="store_const", const=1,
                           help="also print timings, engine versions and settings")


def build_parser() -> tuple[argparse.ArgumentParser, dict]:
    parser = argparse.ArgumentParser(
        prog="trilith", formatter_class=HelpFormatter,
        description=f"Cross-validate physics engines ({', '.join(engine_names())}) "
                    "against the analytic rocking model of a trilith with a pendulum mass "
                    "absorber.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    modules = {}
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"compare.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"compare.cli.{name}":
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
    from compare.cli import options as _common
    _common.VERBOSITY = args.verbosity
    try:
        code = int(modules[args.command].run(args) or 0)
        sys.stdout.flush()  # a closed pipe fails here, inside the handler below
        for note in getattr(args, "deprecation_notes", None) or ():
            print(note, file=sys.stderr)
        return code
    except ValueError as exc:  # includes UsageError: validation at the boundary
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (| head): stop quietly, as cat and grep do.  Point
        # stdout at /dev/null so the interpreter's final flush cannot fail again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
        return 1  # what Python itself does on EPIPE
    except KeyboardInterrupt:
        runs = sys.modules.get("compare.run.runs")
        kept = "; finished runs are kept in the run store" if runs and runs.active() else ""
        print(f"interrupted: cancelled{kept}", file=sys.stderr)
        return 130
    finally:
        # A command's run store and scheduler end with it (main() is also called
        # in-process, by tests and scripts).
        if "compare.run.runs" in sys.modules:
            sys.modules["compare.run.runs"].activate(None)
            sys.modules["compare.run.runs"].set_scheduler(None)


if __name__ == "__main__":
    sys.exit(main())
