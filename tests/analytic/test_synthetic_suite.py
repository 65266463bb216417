"""The shipped synthetic suite: its script rewrites it bit for bit, and the suite
reads as twelve 12 s motions at 100 Hz with the documented peak accelerations
and soils (scenes/records/make_synthetic.py)."""
from __future__ import annotations

import numpy as np
import pytest

import trilith_xval.scenes.records.make_synthetic as ms
from trilith_xval.scenes.ground_motion import load_suite


def test_the_script_rewrites_the_shipped_files_bit_for_bit(tmp_path):
    written = ms.main(tmp_path)
    shipped = sorted(ms.FOLDER.glob("*.csv"))
    assert [p.name for p in written] == [p.name for p in shipped]
    for new, old in zip(written, shipped):
        assert new.read_bytes() == old.read_bytes(), new.name


def test_the_suite_as_documented():
    suite = load_suite("synthetic")
    assert len(suite) == 12
    g = ms.G
    pgas = [r.pga for r in suite]
    # Geometric from 0.15 g to 0.45 g, to the 6 decimals of the files.
    assert pgas == pytest.approx(list(np.geomspace(0.15 * g, 0.45 * g, 12)), abs=1e-6)
    for r in suite:
        assert len(r.times) == 1201 and r.end_time == pytest.approx(12.0)
        assert r.accelerations[0] == 0.0
    soils = [r.label.split("-")[-1].removesuffix(".csv") for r in suite]
    assert soils == ["firm", "medium", "soft"] * 4


def test_the_soil_sets_the_frequency_content():
    """Zero crossings per second grow with the site frequency: soft (5 rad/s)
    below medium (10) below firm (15), on every seed."""
    suite = load_suite("synthetic")
    rate = {}
    for r in suite:
        a = np.asarray(r.accelerations)
        rate.setdefault(r.label.split("-")[-1], []).append(
            np.sum(np.signbit(a[1:]) != np.signbit(a[:-1])) / r.end_time)
    assert max(rate["soft.csv"]) < min(rate["medium.csv"])
    assert max(rate["medium.csv"]) < min(rate["firm.csv"])


def test_one_record_file_is_a_suite_of_one():
    one = load_suite(str(ms.FOLDER / "cp-01-firm.csv"))
    assert len(one) == 1 and one[0].label == "cp-01-firm.csv"
