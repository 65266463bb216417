"""The benchmarks' one way of timing a command as a user runs it."""
from __future__ import annotations

from benchmarks import timed_trilith


def test_a_timed_command_reports_its_exit_output_and_costs():
    ok = timed_trilith(["--version"])
    assert ok.returncode == 0 and "trilith" in ok.stdout.lower()
    assert ok.cpu_s > 0.0 and ok.wall_s > 0.0 and ok.max_rss_mb > 0.0
    assert len(ok.load_average) == 2
    bad = timed_trilith(["spectrum", "--omega", "-3"])
    assert bad.returncode == 2 and bad.stderr.strip()
