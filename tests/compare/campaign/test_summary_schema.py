"""The typed summary schema reads the stored summary and new fields."""
import math
from pathlib import Path

from tests.support.paths import ROOT

from trilith_xval.compare.campaign.summary import Probe, Summary, ThresholdResult, load

SUMMARY = ROOT / "docs" / "validation" / "summary.json"


def test_stored_summary_reads_with_every_engine_point():
    doc = load(SUMMARY)
    assert doc.engines
    for engine in doc.engines:
        pts = doc.points(engine)
        assert pts, engine
        for p in pts:
            assert p.case in ("pendulum", "no_pendulum")
            assert p.a_reference and p.a_reference > 0
            assert p.probes and all(isinstance(q, Probe) for q in p.probes)


def test_resolution_derived_and_nan_is_none():
    p = ThresholdResult.from_dict({"omega": 12.0, "a_reference": 10.0, "a_engine": 10.1,
                                   "a_survives": 10.05, "rel_error": float("nan")}, "no_pendulum")
    assert math.isclose(p.rel_resolution, 0.005)
    assert p.rel_error is None and p.bracketed and p.isolated == ()


def test_schema2_cpu_by_job_is_read_as_wall_time():
    s = Summary.from_dict({"schema_version": 2, "timings": {"cpu_by_job": {"threshold:x": 3.0}}})
    assert s.timings.cpu_by_job == {} and s.timings.wall_by_job == {"threshold:x": 3.0}
    s3 = Summary.from_dict({"schema_version": 3, "timings": {"cpu_by_job": {"threshold:x": 3.0},
                                                             "load_average": [0.5, 1.0]}})
    assert s3.timings.cpu_by_job == {"threshold:x": 3.0} and s3.timings.load_average == (0.5, 1.0)
