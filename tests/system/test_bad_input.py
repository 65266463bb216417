"""Bad input is refused at the API boundary with a ValueError naming the parameter
(and its allowed range); the CLI turns it into one ``error:`` line and exit code 2."""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.simulate import Settings, simulate
from trilith_xval.analytic.trajectory import OverturnCriterion
from trilith_xval.compare.cli.main import main

from tests.support.paths import ROOT


# --- Scene ----------------------------------------------------------------------------------
@pytest.mark.parametrize("field,value", [
    ("b", 0.0), ("b", -0.6), ("lam", 0.5), ("lam", 101.0), ("gamma", -0.1), ("mu", -1.0),
    ("b", math.nan), ("lam", math.inf), ("gamma", math.nan), ("l", 0.0), ("g", -9.81),
    ("column_mass", 0.0), ("column_mass", -5.0), ("J_G", math.inf), ("gap", -0.1)])
def test_scene_rejects(field, value):
    with pytest.raises(ValueError, match=field):
        Scene(**{field: value})


def test_scene_rejects_non_numbers():
    # A wrong type is a TypeError (numpy's convention), still naming the parameter.
    with pytest.raises(TypeError, match="b must be a real number"):
        Scene(b="wide")


# --- Pulse, criterion, settings ----------------------------------------------------------------
@pytest.mark.parametrize("kwargs,name", [
    ({"amplitude": 5.0, "omega": 0.0}, "omega"), ({"amplitude": 5.0, "omega": -3.0}, "omega"),
    ({"amplitude": math.nan, "omega": 3.0}, "amplitude"),
    ({"amplitude": 5.0, "omega": math.inf}, "omega"),
    ({"amplitude": 5.0, "omega": 3.0, "kind": "square"}, "kind")])
def test_pulse_rejects(kwargs, name):
    with pytest.raises(ValueError, match=name):
        Pulse(**kwargs)


@pytest.mark.parametrize("field,value", [
    ("t_max", 0.0), ("t_max", math.nan), ("t_cap", -1.0), ("rtol", 0.0), ("rtol", 0.5),
    ("atol", 0.0), ("method", "Euler"), ("sample_dt", 0.0), ("rest_velocity", 0.0),
    ("rest_step_fraction", 0.5), ("max_events", 0), ("theta0", math.inf), ("psi_dot0", math.nan),
    ("criterion", "topple")])
def test_settings_reject(field, value):
    with pytest.raises((ValueError, TypeError), match=field):  # TypeError: a wrong type
        Settings(**{field: value})


def test_criterion_rejects():
    with pytest.raises(ValueError, match="criterion"):
        OverturnCriterion("sideways")
    with pytest.raises(ValueError, match="topple_angle"):
        OverturnCriterion("topple", 2.0)


def test_simulate_rejects_bad_initial_state(fig5, fig5_bare):
    with pytest.raises(ValueError, match="theta0"):
        simulate(fig5, Pulse(1.0, 5.0), Settings(theta0=1.6))
    with pytest.raises(ValueError, match="psi0"):
        simulate(fig5_bare, Pulse(1.0, 5.0), Settings(psi0=0.1))
    with pytest.raises(ValueError, match="scene"):
        simulate("fig5", Pulse(1.0, 5.0))
    with pytest.raises(ValueError, match="settings"):
        simulate(fig5, Pulse(1.0, 5.0), {"t_max": 1.0})


# --- CLI -------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv,needle", [
    (["--scene", "atlantis"], "unknown scene"),
    (["--set", "height=3"], "unknown name 'height'"),
    (["--set", "lam=0.2"], "lam"),
    (["--omega", "0"], "omega"),
    (["--amplitude", "nan"], "amplitude"),
    (["--engine", "bullet3"], "unknown engine"),
    (["--t-max", "-2"], "--t-max"),
])
def test_cli_bad_values_exit_2_with_one_line(capsys, argv, needle):
    base = {"--amplitude": "5", "--omega": "9"}
    args = ["simulate"] + argv
    for flag, value in base.items():
        if flag not in argv:
            args += [flag, value]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and needle in err
    assert "\n" not in err and "Traceback" not in err


def test_cli_argparse_errors_exit_2(capsys):
    # -A is optional since --record can replace the pulse: a missing one is our error.
    assert main(["simulate", "--omega", "9"]) == 2
    assert capsys.readouterr().err.startswith("error: give -A/--amplitude")
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "-A", "5", "-w", "9", "--criterion", "wobble"])
    assert exc.value.code == 2
    assert "Traceback" not in capsys.readouterr().err


def test_cli_subprocess_one_line_error():
    exe = shutil.which("trilith", path=str(Path(sys.executable).parent))
    cmd = [exe] if exe else [sys.executable, "-m", "trilith_xval.compare.cli.main"]
    proc = subprocess.run(cmd + ["simulate", "-A", "5", "-w", "0"], capture_output=True,
                          text=True, cwd=ROOT, timeout=120)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: omega")
    assert proc.stdout == ""


@pytest.mark.parametrize("omega", [float("nan"), -5.0, 0, 0.0, 1e6])
def test_first_overturn_amplitude_refuses_a_frequency_outside_the_pulse_range(omega):
    from trilith_xval.analytic.first_overturn import SpectrumSettings, first_overturn_amplitude
    from trilith_xval.scenes import load_scene
    with pytest.raises(ValueError, match=r"omega must be in \[0.1, 10000\] rad/s"):
        first_overturn_amplitude(load_scene("fig5"), omega, SpectrumSettings())


def test_a_size_beyond_the_float_range_is_a_value_error():
    from trilith_xval.analytic import Scene
    with pytest.raises(ValueError, match="b must be finite, got an integer of 401 digits"):
        Scene(b=10 ** 400)
