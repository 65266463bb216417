"""Threshold searches start from each engine's stored calibrated threshold
settings; restitution and time histories keep the engine's defaults; a settings
file and ``--dt`` go over them, in that order."""
from __future__ import annotations

import pytest

from compare.campaign.settings_file import SETTINGS_DIR, stored_settings, threshold_options
from compare.campaign.study import job_settings
from compare.campaign.validation import CampaignConfig, backend_settings, engine_options
from engines import configure
from scenes import load_scene

STORED = sorted(p.stem.removesuffix("-thresholds")
                for p in SETTINGS_DIR.glob("*-thresholds.toml"))


def test_stored_threshold_settings_are_valid_engine_settings():
    assert "pymunk" in STORED  # the cheapest engine is calibrated
    for engine in STORED:
        stored = stored_settings(engine, "thresholds")
        assert set(stored.tables) == {engine}
        assert stored.path.endswith(f"{engine}-thresholds.toml")
        # The regenerating command is the file's first line.
        first = (SETTINGS_DIR / f"{engine}-thresholds.toml").read_text().splitlines()[0]
        assert first.startswith(f"# trilith calibrate --engine {engine} --metric thresholds")


@pytest.mark.parametrize("engine", STORED)
def test_only_threshold_searches_use_them(engine):
    stored = threshold_options(engine)
    config = CampaignConfig(engines=(engine,))
    assert engine_options(engine, config, thresholds=True) == stored
    assert engine_options(engine, config) == {}
    assert backend_settings(engine, config) == configure(engine)  # restitution, histories
    scene = load_scene("fig5")
    assert job_settings(engine, 0.0, scene, 10.0, 12.0).dt == stored.get("dt",
                                                                          configure(engine).dt)


def test_a_settings_file_then_dt_go_over_the_calibrated_step():
    scene = load_scene("fig5")
    assert job_settings("pymunk", 0.0, scene, 10.0, 12.0, (("dt", 5e-4),)).dt == 5e-4
    assert job_settings("pymunk", 2e-4, scene, 10.0, 12.0, (("dt", 5e-4),)).dt == 2e-4
    config = CampaignConfig(engines=("pymunk",), engine_settings={"pymunk": {"iterations": 30}},
                            engine_dt=3e-4)
    options = engine_options("pymunk", config, thresholds=True)
    assert options == {"dt": 3e-4, "iterations": 30}


def test_the_report_names_the_threshold_step():
    from compare.report.tables import settings_rows
    doc = {"config": {"engines": ["pymunk"]}, "settings": {"pymunk": {"dt": 1e-4}},
           "threshold_settings": {"pymunk": {"dt": 2e-3}}}
    head, rows = settings_rows(doc)
    assert rows == [["dt", "1e-4"], ["dt (threshold searches)", "2e-3"]]
    doc["threshold_settings"]["pymunk"]["dt"] = 1e-4  # the same step: no extra row
    assert settings_rows(doc)[1] == [["dt", "1e-4"]]
