"""The README's Python example and its simulate command run as written."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_python_example_runs(capsys):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert blocks, "README has no Python example"
    exec(compile(blocks[0], "README.md", "exec"), {})
    out = capsys.readouterr().out
    # Point D overturns without impact in every backend (paper Fig. 7b).
    assert out.count("overturned no-impact") == 3


def test_readme_opens_with_make_report_and_make_test():
    head = README.read_text().splitlines()[:10]
    assert any(line.startswith("make report") for line in head)
    assert any(line.startswith("make test") for line in head)


def test_simulate_example_json():
    bin_dir = Path(sys.executable).parent
    cmd = [str(bin_dir / "trilith"), "simulate", "-A", "25", "-w", "11", "--json"]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    assert '"overturned": true' in out and '"mode": "no-impact"' in out
