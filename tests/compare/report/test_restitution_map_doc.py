"""The restitution-map block of docs/restitution-map.md is generated from the
stored map, never typed; the settings files it names are the generator's and
each loads as a ``--settings`` file; the report section renders the stored map."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.campaign.settings_file import read_settings_file
from trilith_xval.compare.report.restitution_map_doc import (MAP_BEGIN, MAP_END, SETTINGS_DIR,
                                                             STORED, render_map, settings_files)
from trilith_xval.compare.report.restitution_map_section import restitution_map_html

from tests.support.paths import ROOT


@pytest.fixture(scope="module")
def doc() -> dict:
    return json.loads(STORED.read_text(encoding="utf-8"))


def test_block_is_generated_from_the_stored_map(doc):
    text = (ROOT / "docs" / "restitution-map.md").read_text(encoding="utf-8")
    assert text.count(MAP_BEGIN) == 1 and text.count(MAP_END) == 1
    block = text.split(MAP_BEGIN, 1)[1].split(MAP_END, 1)[0].strip("\n")
    assert block == render_map(doc), (
        "docs/restitution-map.md differs from docs/validation/restitution_map.json; run: "
        "python -m trilith_xval.compare.report.restitution_map_doc "
        "docs/validation/restitution_map.json docs/restitution-map.md")


def test_stored_map_states_its_cost_and_provenance(doc):
    assert doc["cpu_s"] > 0 and doc["cells_cpu_s"] > 0 and len(doc["load_average"]) == 3
    assert doc["command"].startswith("trilith restitution-map") and doc["commit"]


def test_settings_files_are_the_generators_and_load(doc):
    expected = settings_files(doc)
    on_disk = {p.name: p.read_text(encoding="utf-8") for p in SETTINGS_DIR.glob("*.toml")}
    assert on_disk == expected
    # JSON keeps MuJoCo's solimp as a list; a settings file reads it as the tuple.
    grids = {e: {v["name"]: {k: tuple(x) if isinstance(x, list) else x
                             for k, x in v["options"].items()} for v in vs}
             for e, vs in doc["grids"].items()}
    for pick in doc["cheapest"]:
        if pick["variant"] is None:
            continue
        loaded = read_settings_file(SETTINGS_DIR / f"{pick['engine']}-{pick['range']}.toml")
        assert loaded.options(pick["engine"]) == grids[pick["engine"]][pick["variant"]]


def test_report_section_renders_every_cell(doc):
    text = restitution_map_html(doc, figures=False)
    assert text.startswith("<h2 id='restitution-map'>")
    assert text.count("<tr>") == len(doc["cells"]) + 1


def test_the_map_stands_beside_the_stored_measurement(tmp_path):
    """The report's measurement paragraph states the stored measured median and
    Housner's ratio (not typed numbers), and keeps the cited facts without it."""
    import json
    from trilith_xval.compare.report.restitution_map_section import measurements_html, _MEASURED
    s = json.loads(_MEASURED.read_text())["summary"]
    text = measurements_html()
    assert f"median {s['measured']['median']:+.2f}" in text
    assert f"Housner's {s['housner']:+.2f}" in text
    bare = measurements_html(tmp_path / "absent.json")
    assert "ElGawady" in bare and "median" not in bare
