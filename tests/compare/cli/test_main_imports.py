"""The front door stays light: building the ``trilith`` parser (``--help``, and
every command before it runs) imports no numerical engine, no compiler and no
plotting library; each command imports what it uses when it runs."""
from __future__ import annotations

import os
import subprocess
import sys

from tests.support.paths import ROOT

# What costs 0.2-1 s to import and is needed only by some commands.
HEAVY = ("numba", "scipy", "matplotlib", "pybullet", "pymunk", "mujoco", "dartpy", "pydrake",
         "distributed")


def test_the_parser_imports_nothing_heavy():
    code = ("import sys; from trilith_xval.compare.cli.main import build_parser; build_parser(); "
            f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}, check=True, timeout=120)
    assert out.stdout.split() == []


def test_no_command_draws_a_figure_itself():
    """compare/cli parses, resolves, calls and prints: every figure a command writes
    is drawn in compare/report or compare/show, where the API reaches it too."""
    import ast
    drawing = []
    for path in sorted((ROOT / "compare" / "cli").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split(".")[0] == "matplotlib" for n in names):
                drawing.append(path.name)
    assert drawing == [], f"figures drawn in compare/cli: {drawing}"
