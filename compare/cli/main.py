"""``trilith``: the command-line front door.

Bad input ends with a one-line ``error: ...`` on stderr naming the option and
its allowed range, exit code 2 (argparse's convention), never a traceback; so
does an output that cannot be written (a full disk, a read-only filesystem, a
full or closed stdout).  A pipe whose reader went away
(``trilith ... --json | head``) ends quietly with exit code 1.

Called as the ``trilith`` program (``argv`` None), :func:`main` ends by freezing
the garbage collector (:func:`gc.freeze`): the interpreter's shutdown then
skips scanning the objects numba, scipy and matplotlib created, which took
0.3 CPU s after a spectrum (docs/benchmarks.md, "Fixed costs").  Every output is
written and closed before; the operating system frees the memory.
"""
from __future__ import annotations

import argparse
import errno
import gc
import importlib
import os
import re
import sys

from trilith_xval.compare.cli import COMMANDS
from trilith_xval.engines import engine_names


# Errors of a write that found no room or no device.
_WRITE_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO, errno.EBADF}


def _version() -> str:
    """The package version and, run from a git checkout, its commit (``+dirty``
    when tracked files differ from it): a bug report then names the code.  Never
    fails: without git, or outside a checkout, the version alone."""
    from pathlib import Path

    from trilith_xval.compare.run.provenance import git_commit
    try:
        from importlib.metadata import PackageNotFoundError, version
        text = version("trilith-xval")
    except PackageNotFoundError:  # a source checkout that was never installed
        text = "unknown (not installed)"
    root = Path(__file__).resolve().parents[2]
    # Only this package's own checkout: an installed copy inside another
    # repository (a .venv in a clone) must not report that repository's commit.
    if (root / ".git").exists():
        commit = git_commit(root)
        if commit != "unknown":
            head, _, dirty = commit.partition("+")
            text += f" (commit {head[:12]}{', with uncommitted changes' if dirty else ''})"
    return text


class _VersionAction(argparse.Action):
    """``--version``, computed when asked for (git is not run for other commands)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="show the version (and the git commit of a checkout) and exit"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"{parser.prog} {_version()}")  # on stdout, as argparse's own action
        parser.exit()


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
        return super()._format_text(_plain(text))

    def _fill_text(self, text, width, indent):
        # The raw formatter differs from the default in _fill_text only.
        if "\n" in text.strip():  # a docstring or a table: laid out by hand
            return argparse.RawDescriptionHelpFormatter._fill_text(self, text, width, indent)
        return super()._fill_text(text, width, indent)

    def _expand_help(self, action):
        return _plain(super()._expand_help(action))


def _plain(text: str) -> str:
    return re.sub(r"``([^`]+)``", r"'\1'", text) if text else text


class _OneLineErrors:
    """argparse's errors as one ``error:`` line (not the usage block), exit code 2."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (see '{self.prog} --help')\n")


class _Parser(_OneLineErrors, argparse.ArgumentParser):
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
        # The provenance block writes the run's command with this parser's flags.
        self.set_defaults(_parser=self)


class _TopParser(_OneLineErrors, argparse.ArgumentParser):
    """The ``trilith`` parser itself."""


def build_parser() -> tuple[argparse.ArgumentParser, dict]:
    parser = _TopParser(
        prog="trilith", formatter_class=HelpFormatter,
        description=f"Cross-validate physics engines ({', '.join(engine_names())}) "
                    "against the analytic rocking model of a trilith with a pendulum mass "
                    "absorber.")
    parser.add_argument("--version", action=_VersionAction)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    modules = {}
    for name in COMMANDS:
        module = importlib.import_module(f"trilith_xval.compare.cli.{name}")
        module.add_parser(sub)
        modules[name.replace("_", "-")] = module  # the command's name on the line
    return parser, modules


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot fail again."""
    try:
        fd = sys.stdout.fileno()
    except (OSError, ValueError):  # an in-memory stream: nothing to flush at exit
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


def _stdout_open() -> bool:
    """stdout is an open descriptor (``trilith ... >&-`` closes it: then a file the
    command opens could take descriptor 1 and receive its printout)."""
    if sys.stdout is None:
        return False
    try:
        fd = sys.stdout.fileno()
    except (OSError, ValueError):  # an in-memory stream (tests, notebooks)
        return True
    try:
        os.fstat(fd)
    except OSError:
        return False
    return True


def main(argv: list[str] | None = None) -> int:
    """Run the ``trilith`` command line ``argv`` (default ``sys.argv[1:]``);
    returns the exit code."""
    try:
        code = _main(argv)
    finally:
        if argv is None:  # the program itself: nothing runs after this but the exit
            gc.freeze()
    if argv is None and code == 130:
        # Interrupted: the run store is closed and the workers killed.  The exit
        # handlers of a process pool whose workers were killed can still write to
        # its closed wake-up pipe and print a traceback after the one-line message,
        # so the program leaves without running them.
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError, AttributeError):
                pass
        os._exit(130)
    return code


def _main(argv: list[str] | None) -> int:
    if not _stdout_open():
        print("error: standard output is closed; redirect it to a file or /dev/null",
              file=sys.stderr)
        return 2
    try:
        parser, modules = build_parser()
    except ValueError as exc:  # the engine registry itself is broken (a name clash)
        print(f"error: {exc}", file=sys.stderr)
        return 2
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_help()
        return 2
    from trilith_xval.compare.cli import options as _common
    _common.VERBOSITY = args.verbosity
    from trilith_xval.compare.run import progress
    progress.PIPED_LINES = args.verbosity >= 0  # a pipe or a log gets progress lines
    try:
        code = int(modules[args.command].run(args) or 0)
        sys.stdout.flush()  # a closed pipe fails here, inside the handler below
        return code
    except ValueError as exc:  # validation at the boundary
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (| head): stop quietly, as cat and grep do.
        _quiet_stdout()
        return 1  # what Python itself does on EPIPE
    except OSError as exc:  # an output that cannot be written: full disk, read-only
        where = f"{exc.filename}: " if exc.filename else ""
        if exc.filename is None and exc.errno in _WRITE_ERRORS:
            # Every file output names itself (compare.run.atomic): a nameless write
            # failure is stdout's (e.g. > /dev/full).
            where = "standard output: "
            _quiet_stdout()
        print(f"error: {where}{exc.strerror or exc}; nothing was left half-written",
              file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        runs = sys.modules.get("trilith_xval.compare.run.runs")
        kept = "; finished runs are kept in the run store" if runs and runs.active() else ""
        print(f"interrupted: cancelled{kept}", file=sys.stderr)
        return 130
    finally:
        # A command's run store and scheduler end with it (main() is also called
        # in-process, by tests and scripts), and so do its progress lines.
        progress.PIPED_LINES = False
        if "trilith_xval.compare.run.runs" in sys.modules:
            store = sys.modules["trilith_xval.compare.run.runs"].activate(None)
            if store is not None:
                store.close()
            sys.modules["trilith_xval.compare.run.runs"].set_scheduler(None)


if __name__ == "__main__":
    sys.exit(main())
