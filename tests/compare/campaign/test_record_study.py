"""A record suite as a campaign axis: ``[campaign.records]`` checked at the door,
and the campaign's record rows equal to ``trilith fragility``'s results."""
from __future__ import annotations

import json

import numpy as np
import pytest

from trilith_xval.compare.campaign.study import load_study
from trilith_xval.compare.cli.main import main


def write_suite(folder):
    folder.mkdir()
    t = np.arange(0.0, 1.5, 0.01)
    for w in (9.0, 11.0):  # two records: a fragility curve needs at least two
        a = np.where(t <= 2 * np.pi / w, np.sin(w * t), 0.0)
        np.savetxt(folder / f"r{w:02.0f}.csv", np.column_stack([t, a]), delimiter=",",
                   header="t,a", comments="")
    return folder


def write(tmp_path, records: str, head: str = ""):
    path = tmp_path / "c.toml"
    path.write_text('[campaign]\nname = "rec"\nscenes = ["fig5"]\nengines = ["pymunk"]\n'
                    f'cases = ["no_pendulum"]\n{head}\n[campaign.records]\n{records}\n')
    return path


@pytest.mark.parametrize("records, needle", [
    ('suite = "/nonexistent/x"', "campaign.records.suite"),
    ('suite = "sample"\nim = "pgd"', "campaign.records.im must be one of pga, pgv, scale"),
    ('suite = "sample"\nim_range = "2"', "campaign.records.im_range must be 'LO:HI'"),
    ('suite = "sample"\nim_range = "5:2"', "im_lo (5) must be below im_hi (2)"),
    ('suite = "sample"\ntail = "long"', "campaign.records.tail must be a number"),
    ('suite = "sample"\nwindow = 3', "unknown key(s) window")])
def test_bad_records_table_is_named(tmp_path, records, needle):
    with pytest.raises(ValueError, match=None) as info:
        load_study(write(tmp_path, records))
    assert needle in str(info.value) and "c.toml" in str(info.value)


def test_records_only_campaign_needs_no_omega(tmp_path):
    study = load_study(write(tmp_path, 'suite = "sample"'))
    assert study.omegas == () and study.records.labels == ("sample.csv",)


@pytest.mark.slow
def test_campaign_rows_equal_the_fragility_results(tmp_path, capsys):
    """Two records, Pymunk: each campaign row is the fragility's robust bracket
    (the same stored job), and its reference the model's IDA."""
    suite = write_suite(tmp_path / "suite")
    ida = 'im_range = "2:40"\nrel_step = 0.5\nrtol = 0.05\ntail = 1.0'
    cache = str(tmp_path / "cache")
    assert main(["campaign", str(write(tmp_path, f'suite = "{suite}"\n{ida}')), "--out",
                 str(tmp_path / "camp"), "--workers", "1", "--cache", cache]) == 0
    rows = json.loads((tmp_path / "camp" / "campaign.json").read_text())["rows"]
    assert main(["fragility", "--records", str(suite), "--engine", "pymunk", "--no-pendulum",
                 "--im-range", "2:40", "--rel-step", "0.5", "--rtol", "0.05", "--tail", "1",
                 "--workers", "1", "--out", str(tmp_path / "frag"), "--cache", cache,
                 "-q"]) == 0
    capsys.readouterr()
    frag = json.loads((tmp_path / "frag" / "fragility.json").read_text())["backends"]
    engine, model = frag["pymunk"]["records"], frag["analytic"]["records"]
    assert len(rows) == len(engine) == len(model) == 2
    for row, eng, mod in zip(rows, engine, model):  # both in the suite's (file name) order
        assert row["a_engine"] == eng["im_overturn"] and row["a_reference"] == mod["im_overturn"]
        assert row["bracketed"] and row["a_reference_safe"] <= row["a_engine"] * 1.02
