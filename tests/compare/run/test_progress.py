"""Long work is never silent on a pipe: one stderr line per tenth of the work, with
done/total and the elapsed seconds; none with -q; none from the Python API."""
from __future__ import annotations

import os
import re
import subprocess
import sys

from tests.support.paths import ROOT
from trilith_xval.compare.run import progress

LINE = re.compile(r"^spectrum pymunk: (\d+)/(\d+) points, \d+ s$")


def _spectrum(*extra: str) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", "spectrum",
                           "--engine", "pymunk", "--omega", "9,12", "--no-cache", *extra],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return [ln for ln in proc.stderr.splitlines() if ln.strip()]


def test_a_piped_engine_spectrum_prints_its_progress():
    lines = [LINE.match(ln) for ln in _spectrum() if ln.startswith("spectrum pymunk:")]
    assert lines and all(lines), lines
    counts = [(int(m[1]), int(m[2])) for m in lines]
    assert counts[-1][0] == counts[-1][1] == 4  # two frequencies, both curves
    assert [d for d, _ in counts] == sorted(d for d, _ in counts)


def test_quiet_prints_no_progress():
    assert not any(ln.startswith("spectrum pymunk:") for ln in _spectrum("-q"))


def test_the_api_prints_nothing_unasked(capsys):
    assert progress.PIPED_LINES is False
    b = progress.bar(3, "x", "items")
    for _ in range(3):
        b.update()
    b.close()
    assert capsys.readouterr().err == ""
