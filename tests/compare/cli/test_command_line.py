"""The command a stored result records is one a person can run: its flags are the
parser's own and parsing it again gives the same options."""
from __future__ import annotations

import shlex

import pytest

from trilith_xval.compare.cli.main import build_parser
from trilith_xval.compare.run.provenance import command_line

LINES = [
    "atlas -q --engine dart --omega 4:28:2 --time-budget 14 --workers 1 --cache /tmp/s",
    "atlas --from a.json --from 'b c.json' --json out.json",
    "spectrum -v --omega 3:30:1 --no-cache",
    "calibrate --engine pymunk --step-only --tolerance 0.02",
    "report --quick --out 'x y'",
]


def _options(ns) -> dict:
    return {k: v for k, v in vars(ns).items() if k != "_parser"}


@pytest.mark.parametrize("line", LINES)
def test_the_recorded_command_parses_back_to_the_same_run(line):
    parser, _ = build_parser()
    args = parser.parse_args(shlex.split(line))
    recorded = command_line(args)
    words = shlex.split(recorded)
    assert words[:2] == ["trilith", line.split()[0]]
    again = parser.parse_args(words[1:])
    assert _options(again) == _options(args)
    # No option the parser does not know (a bare attribute name such as
    # --verbosity or --from_ was once written here).
    assert "--verbosity" not in words


def test_quiet_and_verbose_are_written_as_their_switches():
    parser, _ = build_parser()
    quiet = command_line(parser.parse_args(["spectrum", "-q"]))
    plain = command_line(parser.parse_args(["spectrum"]))
    assert "--quiet" in shlex.split(quiet) and "--quiet" not in shlex.split(plain)
