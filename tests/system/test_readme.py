"""The README runs as written: its Python example, and every `.venv/bin/trilith ...`
line of its code blocks (with this interpreter's bin directory in place of
`.venv/bin/`, in a scratch directory that sees the repository's `scenes/`)."""
from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.paths import ROOT
README = ROOT / "README.md"
PREFIX = ".venv/bin/"
# Lines that run for a minute or more (campaigns, the benchmarks, the fragility
# of the twelve-motion suite).
SLOW = ("trilith report", "trilith bench", "trilith fragility")


def readme_cli_lines() -> list[str]:
    blocks = re.findall(r"```[a-z]*\n(.*?)```", README.read_text(), re.S)
    lines = []
    for block in blocks:
        for line in block.splitlines():
            line = line.strip()
            if line.startswith("trilith ") or line.startswith(PREFIX + "trilith "):
                lines.append(line)
    return lines


def test_every_cli_line_uses_the_venv_prefix():
    lines = readme_cli_lines()
    assert len(lines) >= 15
    bare = [line for line in lines if not line.startswith(PREFIX)]
    assert not bare, f"README lines without {PREFIX}: {bare}"


def _params():
    out = []
    for line in readme_cli_lines():
        marks = [pytest.mark.slow] if any(s in line for s in SLOW) else []
        out.append(pytest.param(line, marks=marks, id=line.split("#")[0].strip()[len(PREFIX):]))
    return out


@pytest.mark.parametrize("line", _params())
def test_readme_cli_line_runs_as_written(line, tmp_path):
    argv = shlex.split(line, comments=True)
    exe = Path(sys.executable).parent / argv[0].removeprefix(PREFIX)
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "trilith_xval.compare.cli.main"]
    for folder in ("scenes", "campaigns", "docs"):  # paths the lines name, from the repo root
        (tmp_path / folder).symlink_to(ROOT / folder)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    env["MPLBACKEND"] = "Agg"
    proc = subprocess.run(cmd + argv[1:], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=1800)
    assert "Traceback" not in proc.stderr, proc.stderr
    if argv[1] == "view":  # no display in tests: the documented exit 2 and hint
        assert proc.returncode == 2 and "trilith record" in proc.stderr
        return
    assert proc.returncode == 0, proc.stderr
    if "--json" in argv:
        json.loads(proc.stdout)
    if "--out" in argv or "--plot" in argv:
        target = argv[argv.index("--out" if "--out" in argv else "--plot") + 1]
        assert (tmp_path / target).exists()


def test_python_example_runs(capsys):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert blocks, "README has no Python example"
    exec(compile(blocks[0], "README.md", "exec"), {})
    out = capsys.readouterr().out
    # Point D overturns without impact in every backend (paper Fig. 7b).
    names = re.search(r"for name in \((.*?)\):", blocks[0]).group(1).split(",")
    assert len(names) >= 4 and out.count("overturned no-impact") == len(names)


def test_readme_opens_with_make_report_and_make_test():
    head = README.read_text().splitlines()[:10]
    assert any(line.startswith("make report") for line in head)
    assert any(line.startswith("make test") for line in head)


def test_simulate_example_json():
    bin_dir = Path(sys.executable).parent
    cmd = [str(bin_dir / "trilith"), "simulate", "-A", "25", "-w", "11", "--json"]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    assert '"overturned": true' in out and '"mode": "no-impact"' in out
