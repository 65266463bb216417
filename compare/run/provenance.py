"""Where a report came from: date, commit, command line, versions, machine.

Kept apart from the measurements (``summary.json["provenance"]``) so two runs of
the same campaign compare equal on everything but this block.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import os
import platform
import shlex
import subprocess
import sys
from pathlib import Path

__all__ = ["collect", "git_commit", "command_line"]

_ROOT = Path(__file__).resolve().parents[2]


def git_commit(root: Path = _ROOT) -> str:
    """``git rev-parse HEAD`` of the checkout holding this package (``+dirty``
    when tracked files differ from it); ``'unknown'`` outside a git checkout."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=10,
                               check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("+dirty" if dirty else "") if head else "unknown"


def command_line(args: argparse.Namespace | None, prog: str = "trilith") -> str:
    """The equivalent command line of a parsed ``trilith`` command: every option
    with its value (defaults included), so the line reproduces the run even
    when the defaults change later.  Without ``args``: this process's argv.

    With the subcommand's parser on ``args._parser`` (the CLI puts it there) the
    flags are the parser's own (``-q`` for a quiet run, ``--no-cache``); without
    it each attribute ``name`` is written ``--name``.
    """
    if args is None:
        return shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]])
    parser = getattr(args, "_parser", None)
    words = [prog, getattr(args, "command", None) or ""]
    if parser is None:
        opts = {k: v for k, v in vars(args).items() if k not in ("command", "func")}
        for key, value in opts.items():
            words += _option_words("--" + key.replace("_", "-"), value)
        return shlex.join(w for w in words if w)
    for action in parser._actions:  # the parser's own record of its options
        if isinstance(action, (argparse._HelpAction, argparse._VersionAction)):
            continue
        value = getattr(args, action.dest, None)
        if not action.option_strings:  # a positional argument
            words += [str(v) for v in value] if isinstance(value, list) else \
                [] if value is None else [str(value)]
            continue
        flag = max(action.option_strings, key=len)
        if isinstance(action, argparse._StoreConstAction):  # also store_true/false
            if value == action.const and value != action.default:
                words.append(flag)
            continue
        words += _option_words(flag, value)
    return shlex.join(w for w in words if w)


def _option_words(flag: str, value) -> list[str]:
    if value is None or value is False:
        return []
    if value is True:
        return [flag]
    if isinstance(value, list):  # a repeated option (action="append") or nargs
        return [w for item in value for w in (flag, str(item))]
    return [flag, str(value)]


def _version(module: str) -> str:
    try:
        return str(__import__(module).__version__)
    except (ImportError, AttributeError):
        return "not installed"


def collect(args: argparse.Namespace | None = None, *, quick: bool = False,
            backends: dict | None = None) -> dict:
    """The provenance block of a report.

    Parameters
    ----------
    args : argparse.Namespace, optional
        The parsed command (for :func:`command_line`).
    quick : bool
        Whether the campaign ran with ``--quick`` (smaller grids).
    backends : dict, optional
        Backend name -> its ``version()`` string.
    """
    return {
        "date": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
        "commit": git_commit(),
        "command": command_line(args),
        "quick": bool(quick),
        "versions": {"python": platform.python_version(), "numpy": _version("numpy"),
                     "scipy": _version("scipy"), "matplotlib": _version("matplotlib"),
                     **(backends or {})},
        "machine": {"platform": platform.platform(), "processor": platform.machine(),
                    "cpu_count": os.cpu_count()},
    }
