"""The pulse family at the door: every command that takes a pulse accepts
``--pulse sine|cosine|ricker|ricker-anti|mp`` with the M-P ``--mp-gamma`` /
``--mp-nu``, and refuses a bad one before any work (exit 2, one ``error:`` line
naming the option)."""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic.pulses import PULSE_FAMILY, MavroeidisPapageorgiou, PulseShape, Ricker, pulse_of
from trilith_xval.compare.cli.main import main

from tests.support.paths import ROOT

SAMPLE_CSV = str(ROOT / "scenes" / "records" / "sample.csv")

DOOR_CASES = [
    (["simulate", "--pulse", "mp", "-A", "15", "-w", "11", "--mp-gamma", "1"],
     "--mp-gamma must be in (1, 20]"),
    (["simulate", "--pulse", "mp", "-A", "15", "-w", "11", "--mp-gamma", "25"],
     "--mp-gamma must be in (1, 20]"),
    (["simulate", "--pulse", "mp", "-A", "15", "-w", "11", "--mp-gamma", "two"],
     "--mp-gamma: 'two' is not a number"),
    (["simulate", "--pulse", "mp", "-A", "15", "-w", "11", "--mp-nu", "7"],
     "--mp-nu must be in [-2 pi, 2 pi]"),
    (["simulate", "--pulse", "mp", "-A", "15", "-w", "11", "--mp-nu", "nan"],
     "--mp-nu must be finite"),
    (["simulate", "--pulse", "ricker", "-A", "15", "-w", "11", "--mp-gamma", "2"],
     "--mp-gamma: only for --pulse mp"),
    (["simulate", "--pulse", "ricker", "-A", "15", "-w", "0.2"], "-w/--omega (or --period)"),
    (["simulate", "--pulse", "ricker", "-A", "2e4", "-w", "11"], "-A/--amplitude"),
    (["simulate", "--pulse", "ricker", "--record", SAMPLE_CSV],
     "--record replaces the pulse: drop --pulse"),
    (["spectrum", "--pulse", "mp", "--mp-nu", "-9"], "--mp-nu must be in"),
    (["spectrum", "--pulse", "ricker", "--record", SAMPLE_CSV], "drop --pulse"),
    (["spectrum", "--pulse", "cosine", "--mp-gamma", "3"], "only for --pulse mp"),
    (["map", "--pulse", "ricker", "--mp-gamma", "2"], "only for --pulse mp"),
    (["map", "--pulse", "mp"], "more than 5000 for a mp"),
    (["record", "--pulse", "mp", "--mp-gamma", "0.5", "--out", "/tmp/x.gif"],
     "--mp-gamma must be in"),
]


@pytest.mark.parametrize("argv, needle", DOOR_CASES, ids=[" ".join(a) for a, _ in DOOR_CASES])
def test_bad_pulse_refused_at_the_door(argv, needle, no_work, capsys):
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("error: ") and needle in lines[0], lines[0]
    assert captured.out == ""


@pytest.mark.parametrize("kind", PULSE_FAMILY)
def test_amplitude_is_the_peak_and_omega_the_frequency(kind):
    """``-A`` is the PGA of every shape (negative mirrors it); ``Omega`` is
    ``2 pi / T_p`` of a Ricker wavelet and ``2 pi f_p`` of the M-P pulse."""
    omega = 9.0
    p, m = pulse_of(kind, 7.5, omega), pulse_of(kind, -7.5, omega)
    assert p.pga == pytest.approx(7.5, rel=1e-9) and m.pga == pytest.approx(7.5, rel=1e-9)
    t = p.peak_times[0]
    assert m.acceleration(t) == pytest.approx(-p.acceleration(t), rel=1e-12)
    if isinstance(p, Ricker):
        assert p.period == pytest.approx(2 * math.pi / omega, rel=1e-15)
    if isinstance(p, MavroeidisPapageorgiou):
        assert p.frequency == pytest.approx(omega / (2 * math.pi), rel=1e-15)


def test_mp_shape_is_carried_and_checked():
    p = PulseShape("mp", gamma=2.6, nu=-1.0).at(4.0, 8.0)
    assert (p.gamma, p.nu) == (2.6, -1.0) and p.pga == pytest.approx(4.0, rel=1e-9)
    with pytest.raises(ValueError, match="gamma must be in"):
        PulseShape("mp", gamma=1.0)
    with pytest.raises(ValueError, match="only"):
        PulseShape("ricker", gamma=3.0)


def test_simulate_runs_every_shape_in_the_model_and_an_engine(capsys):
    """The model and an engine take every shape through the same template rule;
    the JSON echoes the shape's parameters."""
    import json
    assert main(["simulate", "--pulse", "mp", "--mp-gamma", "2.5", "--mp-nu", "0.5",
                 "-A", "0.5g", "-w", "1.5Hz", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    exc = doc["inputs"]["excitation"]
    assert exc["type"] == "mavroeidis-papageorgiou"
    assert (exc["gamma"], exc["nu"], exc["frequency"]) == (2.5, 0.5, 1.5)
    assert main(["simulate", "--pulse", "ricker-anti", "-A", "3", "--period", "0.5",
                 "--engine", "pymunk", "--t-max", "1.6", "--no-pendulum"]) == 0
    out = capsys.readouterr().out
    assert "antisymmetric Ricker wavelet, T_p = 0.5 s, PGA 3 m/s^2" in out
