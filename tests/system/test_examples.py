"""docs/examples/ scripts run as a user would run them, and the public API's doctests."""
from __future__ import annotations

import doctest
import importlib
import subprocess
import sys
from pathlib import Path

from tests.support.paths import ROOT

import pytest

EXAMPLES = ROOT / "docs" / "examples"

# Public entry points whose numpydoc Examples must run as written.
DOCTEST_MODULES = ("analytic.options", "analytic.parameters", "analytic.excitation",
                   "analytic.bounds", "analytic.contact_forces", "engines",
                   "compare.measure.restitution", "compare.run.jsonable", "compare.run.progress", "scenes.points",
                   "scenes.ground_motion", "engines.mujoco_")


@pytest.mark.parametrize("module", DOCTEST_MODULES)
def test_docstring_examples_run(module):
    result = doctest.testmod(importlib.import_module(f"trilith_xval.{module}"), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0, f"{module} has no Examples"
    assert result.failed == 0


@pytest.mark.parametrize("script, args, expect", [
    ("own_scene.py", [], "A = 15.0 m/s^2"),
    ("engine_vs_model.py", ["pymunk"], "restitution vs Eq. 20"),
    pytest.param("whole_spectrum.py", ["12", "13"], "pymunk pendulum: Omega 12",
                 marks=pytest.mark.slow),
])
def test_example_scripts_run(script, args, expect):
    proc = subprocess.run([sys.executable, str(EXAMPLES / script), *args], capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert expect in proc.stdout
    assert "Traceback" not in proc.stderr
