"""``trilith simulate --record`` runs the model's record in the compiled kernels
(``analytic-fast``), with the verdict and exact events of the accurate path
(compared in depth in tests/analytic/test_fast_records.py)."""
from __future__ import annotations

import json
from pathlib import Path

from trilith_xval.analytic import simulate as accurate
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_record, load_scene

SAMPLE = Path(__file__).resolve().parents[3] / "scenes" / "records" / "sample.csv"


def test_the_model_runs_a_record_compiled(capsys):
    assert main(["simulate", "--record", str(SAMPLE), "--t-max", "12", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    ref = accurate.simulate(load_scene("fig5"), load_record(SAMPLE),
                            accurate.Settings(t_max=12.0))
    assert doc["engine"] == "analytic-fast"
    assert doc["status"] == ref.verdict.status
    assert doc["n_impacts"] == ref.sampled_events().n_impacts  # read from the samples
    assert [e["kind"] for e in doc["events"]] == [e.kind for e in ref.events]  # exact


def test_record_hint_names_a_record_by_its_file_though_it_compiles():
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.show.view import record_hint
    rec = load_record(SAMPLE)
    assert rec.compiled_form() is not None
    assert "--record sample.csv" in record_hint("fig5", "pymunk", rec)
    assert "--amplitude 3 --omega 6" in record_hint("fig5", "pymunk", Pulse(3.0, 6.0))
