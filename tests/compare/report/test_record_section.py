"""The report's record section: each engine's robust intensity against the
model's IDA, with its cause by the stated rule."""
from __future__ import annotations

import pytest

from trilith_xval.analytic.ida import IDASettings
from trilith_xval.compare.cli.main import main
from trilith_xval.compare.report.record_section import _row, record_section, record_section_html
from trilith_xval.scenes import load_scene
from tests.compare.measure.test_record_threshold import half_sine_record

ST = IDASettings(im="pga", im_lo=2.0, im_hi=40.0, rel_step=0.5, rtol=0.01, tail=1.0)


@pytest.mark.slow
def test_pymunk_agrees_on_a_one_sine_record(tmp_path):
    """The case of compare/measure/test_record_threshold.py (Pymunk within 2 %
    of the model): the section calls it 'agrees', and the page shows the row."""
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.store import RunStore
    with runs.using(RunStore(tmp_path / "store")):
        sec = record_section(load_scene("fig5").without_pendulum(), [half_sine_record()],
                             ("pymunk",), ST)
    (row,) = sec["rows"]
    assert row["cause"] == "agrees" and abs(row["rel_error"]) <= 0.02 + ST.rtol
    assert row["pivot_sliding_max"] is not None and row["residual_tilt"] is not None
    page = "".join(record_section_html(sec))
    assert "half-sine" in page and "agrees" in page


@pytest.mark.parametrize("engine, model_valid, isolated, bracketed, cause", [
    ((9.0, 9.1), True, 0, True, "engine"),
    ((9.0, 9.1), False, 0, True, "model"),
    ((9.0, 9.1), True, 1, True, "sensitivity"),
    ((None, None), True, 0, False, "no-bracket"),
    ((10.0, 10.05), True, 0, True, "agrees")])
def test_cause_rule(engine, model_valid, isolated, bracketed, cause):
    """The rule's order: agreement first, then the model, the search's
    sensitivity, a missing bracket, and only then the engine."""
    m = {"im_overturn": 10.1, "im_safe": 10.0, "censored": False}
    res = {"im_overturn": engine[1], "im_safe": engine[0], "censored": False,
           "bracketed": bracketed, "isolated": [{}] * isolated, "flips": [], "n_runs": 9,
           "cpu_s": 1.0, "long_run": None}
    valid = {"valid": model_valid, "reason": "" if model_valid else "the lintel lifts"}
    assert _row("pymunk", "r", m, res, valid, ST)["cause"] == cause


def test_report_refuses_a_bad_record_at_the_door(tmp_path, no_work, capsys):
    assert main(["report", "--quick", "--record", str(tmp_path / "none.csv"), "--out",
                 str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("error: --record") and "does not exist" in err[0]
