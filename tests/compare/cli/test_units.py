"""Engineering units at the door (g, Hz, a period, cm/s) and beside SI in outputs."""
from __future__ import annotations

import math

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.cli.units import (acceleration_text, frequency_text, parse_acceleration,
                               parse_frequency, parse_period, parse_velocity)
from trilith_xval.scenes import SCENE_DIR

SAMPLE = SCENE_DIR.parent / "records" / "sample.csv"


@pytest.mark.parametrize("text, value", [("0.5g", 0.5 * 9.80665), ("0.5 g", 0.5 * 9.80665),
                                         ("3", 3.0), ("3 m/s^2", 3.0), ("-1e-1g", -0.980665)])
def test_accelerations(text, value):
    assert parse_acceleration(text, "-A") == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("text, value", [("2Hz", 4 * math.pi), ("2 Hz", 4 * math.pi),
                                         ("11", 11.0), ("11 rad/s", 11.0)])
def test_frequencies(text, value):
    assert parse_frequency(text, "-w") == pytest.approx(value, rel=1e-15)


def test_period_and_velocity():
    assert parse_period("0.5", "--period") == pytest.approx(4 * math.pi, rel=1e-15)
    assert parse_period("0.5s", "--period") == pytest.approx(4 * math.pi, rel=1e-15)
    assert parse_velocity("25cm/s", "--pgv") == pytest.approx(0.25, rel=1e-15)


@pytest.mark.parametrize("call, match", [
    (lambda: parse_acceleration("0.5kg", "-A"), "-A: '0.5kg' is not an acceleration"),
    (lambda: parse_acceleration("nan", "-A"), "-A"),
    (lambda: parse_frequency("2 kHz", "-w"), "-w: '2 kHz' is not a frequency"),
    (lambda: parse_period("0", "--period"), "--period: the period must be > 0"),
    (lambda: parse_period("-1", "--period"), "--period")])
def test_bad_units_name_the_option(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_texts_show_g_and_hz_beside_si():
    assert acceleration_text(9.80665 / 2) == "4.903 m/s^2 (0.5 g)"
    assert frequency_text(4 * math.pi) == "12.57 rad/s (2 Hz, T = 0.5 s)"


def test_cli_same_run_in_si_and_engineering_units(capsys):
    assert main(["simulate", "-A", "0.5g", "-w", "2Hz", "--json", "-q"]) == 0
    a = capsys.readouterr().out
    assert main(["simulate", "-A", str(0.5 * 9.80665), "-w", str(4 * math.pi), "--json",
                 "-q"]) == 0
    b = capsys.readouterr().out
    assert main(["simulate", "-A", "0.5g", "--period", "0.5", "--json", "-q"]) == 0
    c = capsys.readouterr().out
    strip = lambda s: [ln for ln in s.splitlines() if "wall" not in ln and "cpu" not in ln]  # noqa: E731
    assert strip(a) == strip(b) == strip(c)


@pytest.mark.parametrize("argv, message", [
    (["simulate", "-A", "0.5kg", "-w", "2"], "error: -A/--amplitude: '0.5kg' is not"),
    (["simulate", "-A", "1", "-w", "2Hz", "--period", "1"], "error: give -w/--omega or --period"),
    (["simulate", "--record", str(SAMPLE), "--scale", "0"], "error: scale factor must be"),
    (["simulate", "--record", str(SAMPLE), "--pgv", "fast"], "error: --pgv: 'fast' is not"),
    (["simulate", "-A", "1", "-w", "2", "--pga", "1"], "error: --pga scales a --record")])
def test_cli_refuses_bad_units_in_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1


def test_record_scaled_to_a_pga_in_g(capsys):
    assert main(["simulate", "--record", str(SAMPLE), "--pga", "0.3g", "-q"]) == 0
    assert "PGA 2.942 m/s^2 (0.3 g)" in capsys.readouterr().out
