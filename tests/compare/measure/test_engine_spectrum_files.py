"""The stored engine spectra's summary table reads the JSON the spectrum command writes."""
from __future__ import annotations

import json

from compare.measure.engine_spectrum_files import summary_table


def _point(omega, a_ref, err, cause, iso=0, cpu=1.0):
    a_eng = None if err is None else a_ref * (1 + err)
    return {"omega": omega, "a_reference": a_ref, "a_engine": a_eng, "rel_error": err,
            "cause": cause, "isolated": [{"amplitude": 1.0}] * iso, "search_cpu_s": cpu,
            "cpu_s": 2 * cpu}


def test_summary_row_region_beyond_and_costs(tmp_path):
    curves = {"pendulum": [_point(3, 2.5, 0.002, "agrees", iso=2), _point(4, 3.0, 0.002, "agrees"),
                           _point(5, 9.0, 0.03, "model"), _point(6, 12.0, None, "model")],
              "no_pendulum": [_point(3, 2.4, -0.002, "agrees"), _point(4, 2.9, 0.03, "collapse"),
                              _point(5, 8.0, 0.002, "agrees"), _point(6, 11.0, 0.05, "model")]}
    doc = {"engines": {"toy": {"curves": curves, "cost": {"runs": 70, "cpu_s": 16.0,
                                                          "cpu_per_sim_s": 0.05}}}}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(doc))
    row = summary_table([path]).splitlines()[2]
    # The region ends before the first frequency where any point disagrees (4 here,
    # the collapse), whatever agrees beyond it (Omega 5 without the pendulum).
    assert row.startswith("| toy | 4 of 8 | Omega 3-3 (A <= 2.5 m/s^2), 2 points |")
    assert "Omega 4-6: +0.2 to +5.0 %, no robust bracket at Omega 6 (collapse 1, model 3)" in row
    assert "| 2 | 70 | 8 / 16 | 0.050 |" in row
