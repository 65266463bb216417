"""The engines' replays of a measured impact (compare/peers/impact_replay.py) and
the stored measurement (docs/validation/impact_measurement.json) against its own
generator's summary.

Tolerances:

* replay of a Housner impact (a block pivoting onto its face, no slip, the
  project's no-sliding friction): the engines' own ratio within 0.03 of
  Housner's 0.25.  Their plastic contacts give 0.233 (Pymunk) and 0.224
  (MuJoCo) on the measured states; the 1 ms read-out after the landing loses
  ~120 rad/s^2 x 1 ms = 0.12 rad/s of a ~2 rad/s rate to gravity (0.015 of
  the ratio) and MuJoCo's soft contact a little more.  The data's estimator on
  the engines' 250 Hz samples: within 0.05 (it also sees the gravity
  deceleration over 16 ms through a parabola).
* the stored summary against a recomputation from its rows: 1e-12 relative
  (the same float operations on the same numbers, in another order at most).
"""
from __future__ import annotations

import json
import math

import pytest

from tests.support.paths import ROOT
from trilith_xval.compare.peers import impact_data as d
from trilith_xval.compare.peers import impact_measure as m

STORED = ROOT / "docs" / "validation" / "impact_measurement.json"


def housner_impact(rate: float = -8.0) -> d.Impact:
    """A block on corner 2 one frame before landing flat on corner 3, no slip."""
    th = -rate / d.FRAME_RATE  # one frame ahead of flat
    c, s = math.cos(th), math.sin(th)
    ox, oz = d.CORNERS[2]
    rx, rz = -(c * ox - s * oz), -(s * ox + c * oz)
    state = (0.0, rz, th, -rate * rz, rate * rx, rate)
    return d.Impact("synthetic", 20, 2, 3, 0.0, rate, math.nan, 0.0, 0.0, 0.0, state)


@pytest.mark.parametrize("engine", ["pymunk", "mujoco"])
def test_engines_replay_a_housner_impact(engine):
    pytest.importorskip(engine)
    from trilith_xval.compare.peers import impact_replay as r
    out = r.replay(engine, housner_impact(), r.DEFAULT_FRICTION)
    assert out["ratio_direct"] == pytest.approx(d.housner_ratio(), abs=0.03)
    assert out["ratio"] == pytest.approx(d.housner_ratio(), abs=0.05)
    assert 0.0 < out["t_land"] < 1.0 / d.FRAME_RATE  # it lands within the first frame


def test_replay_refuses_an_unknown_engine():
    from trilith_xval.compare.peers import impact_replay as r
    with pytest.raises(ValueError, match="engine must be one of"):
        r.replay("bullet", housner_impact())


@pytest.fixture(scope="module")
def stored() -> dict:
    return json.loads(STORED.read_text())


def test_stored_summary_is_its_rows_summary(stored):
    from benchmarks.impact_measurement import rate_noise
    noise = rate_noise(stored["angle_noise"], d.FRAME_RATE, stored["filter"]["window"])
    assert stored["rate_noise"] == pytest.approx(noise, rel=1e-12)
    again = m.summarise(stored["rows"], stored["summary"]["housner"], stored["rate_noise"])

    def same(a, b, where):
        if isinstance(a, dict):
            assert a.keys() == b.keys(), where
            for k in a:
                same(a[k], b[k], f"{where}.{k}")
        elif isinstance(a, float):
            assert a == pytest.approx(b, rel=1e-12, abs=1e-15), where
        else:
            assert a == b, where

    same(stored["summary"], again, "summary")


def test_stored_document_is_derived_numbers_with_the_citation(stored):
    assert stored["summary"]["housner"] == d.housner_ratio()
    assert stored["filter"] == d.Filter().to_dict()
    assert "Fazeli" in " ".join(stored["data"]["cite"])
    assert "DAIRLab/ImpactModeling" in stored["data"]["redistributed_in"]
    assert len(stored["data"]["sha256"]) == 64
    assert stored["command"].startswith("nice -n 5 python -m benchmarks.impact_measurement")
    assert stored["cpu_s"] > 0.0 and len(stored["load_average_end"]) == 3
    # one row per impact, no trajectory in it: only the derived per-impact numbers
    keys = {"name", "frame", "pivot", "landing", "phi", "rate_before", "rate_after",
            "residual_before", "residual_after", "slip", "ratio", "outcome", "engines",
            "engines_direct"}
    assert all(set(row) == keys for row in stored["rows"])
    assert stored["summary"]["impacts"] == len(stored["rows"])
    for row in stored["rows"]:
        assert row["ratio"] == pytest.approx(row["rate_after"] / row["rate_before"], rel=1e-12)
        assert set(row["engines"]) == {m.engine_key(e, mu) for e in ("pymunk", "mujoco")
                                       for mu in m.FRICTIONS}


def test_docs_table_is_generated_from_the_stored_json(stored):
    from benchmarks.impact_measurement import table
    text = (ROOT / "docs" / "measured-impacts.md").read_text(encoding="utf-8")
    assert table(stored) in text, (
        "docs/measured-impacts.md's table differs from docs/validation/impact_measurement.json; "
        "print it with: python -m benchmarks.impact_measurement --table")
