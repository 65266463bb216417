"""``trilith restitution-map`` end to end on a small map (Pymunk, two lam, two
settings variants, no trilith): the document, the figures, the settings files
(which ``--settings`` reads), and bad input refused with one line, exit 2."""
from __future__ import annotations

import json
import math

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.campaign.settings_file import read_settings_file
from trilith_xval.compare.measure.restitution_map import R_TOL, cheapest, grid, grids, passes


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("rmap")
    argv = ["restitution-map", "--engine", "pymunk", "--lam", "2", "--lam", "5",
            "--variant", "default", "--variant", "dt=5e-4", "--no-trilith", "--no-cache",
            "--json", str(tmp / "map.json"), "--out", str(tmp / "out"), "-q"]
    assert main(argv) == 0
    return tmp, json.loads((tmp / "map.json").read_text())


def test_small_map_measures_every_cell(small_map):
    _, doc = small_map
    cells = doc["cells"]
    assert [(c["variant"], c["scene"]) for c in cells] == [
        ("default", "block_lam2"), ("default", "block_lam5"),
        ("dt=5e-4", "block_lam2"), ("dt=5e-4", "block_lam5")]
    for c in cells:
        assert c["complete"] and c["n_impacts"] == 4 and c["equation"] == "Eq. 20"
        assert math.isfinite(c["r_ratio"]) and math.isfinite(c["thr_error"])
        assert c["cpu_s"] > 0
    # Pymunk at its calibrated defaults: every impact within 0.24 % of Eq. 20
    # (engines/pymunk_), so inside the map's 0.5 % band.
    assert all(c["r_worst"] <= R_TOL for c in cells if c["variant"] == "default")
    assert doc["cpu_s"] > 0 and len(doc["load_average"]) == 3
    assert doc["command"].startswith("trilith restitution-map")
    assert doc["cheapest"] == cheapest(cells)


def test_cheapest_passes_every_cell_of_its_range(small_map):
    _, doc = small_map
    for pick in doc["cheapest"]:
        mine = [c for c in doc["cells"] if c["scene"] in pick["scenes"]]
        if pick["variant"] is not None:
            assert all(passes(c) for c in mine if c["variant"] == pick["variant"])
        else:
            assert not any(all(passes(c) for c in mine if c["variant"] == v)
                           for v in {c["variant"] for c in mine})


def test_outputs_are_figures_and_loadable_settings(small_map):
    tmp, doc = small_map
    assert (tmp / "out" / "restitution_map_pymunk.png").stat().st_size > 0
    files = sorted((tmp / "out" / "settings").glob("*.toml"))
    assert len(files) == sum(p["variant"] is not None for p in doc["cheapest"])
    options = {v.name: v.options for v in grid("pymunk")}
    for f in files:
        loaded = read_settings_file(f)
        pick = next(p for p in doc["cheapest"] if f.name == f"pymunk-{p['range']}.toml")
        assert loaded.options("pymunk") == options[pick["variant"]]


def test_every_grid_variant_is_a_loadable_settings_file(tmp_path):
    # Any variant may come out cheapest, so each must be writable and read back
    # as the same options (MuJoCo's solimp tuple as a TOML array included).
    from trilith_xval.compare.campaign.settings_file import settings_toml
    for engine, variants in grids().items():
        for k, v in enumerate(variants):
            path = tmp_path / f"{engine}-{k}.toml"
            path.write_text(settings_toml(engine, v.options, v.why))
            assert read_settings_file(path).options(engine) == v.options


@pytest.mark.parametrize("args, words", [
    (["--lam", "4"], "--lam must be one of 1.5, 2, 3, 5, 8, 10, got 4"),
    (["--engine", "bullet"], "--engine must be one of"),
    (["--engine", "pymunk", "--variant", "dt=1"], "--variant must be one of"),
    (["--workers", "0"], "--workers must be in"),
    (["--json", "/nonexistent-dir/map.json"], "--json"),
])
def test_bad_input_is_one_line_exit_2(capsys, args, words):
    assert main(["restitution-map", "--no-cache", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error:") and words in err


def test_a_cell_is_a_value_holding_its_variants_run(monkeypatch):
    """A cell's run is the engine's RunSpec with its variant's options over the
    defaults; the whole cell is stored under the description it always had."""
    from trilith_xval.compare.measure import restitution_map as rm
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.engines import configure
    cell = rm.MapCell("pymunk", "dt=5e-4", "fig5_eq20", 12.0, 8.8, "after-impact")
    run = cell.run()
    assert isinstance(run, RunSpec) and run.scene == rm.cell_scene("fig5_eq20")
    assert run.settings == configure("pymunk", dt=5e-4)
    assert dict(run.origin) == {"dt": "the variant dt=5e-4"}
    seen = []
    monkeypatch.setattr(runs, "memo", lambda kind, key, compute, **kw: seen.append((kind, key)))
    rm._cell_memo(cell)
    assert seen == [("restitution_map_cell",
                     {"cell": ["pymunk", "dt=5e-4", "fig5_eq20", 12.0, 8.8, "after-impact"],
                      "options": {"dt": 5e-4}, "n_impacts": rm.N_IMPACTS})]


def test_the_grids_are_the_engines_own_and_unchanged_in_the_stored_map():
    """Each engine's variants live on its class (engines/NAME_/): the grids the
    stored map was measured with are the ones the registry gives now."""
    import json
    from tests.support.paths import ROOT
    stored = json.loads((ROOT / "docs" / "validation" / "restitution_map.json").read_text())
    now = {e: [v.to_dict() for v in variants] for e, variants in grids(stored["engines"]).items()}
    assert json.loads(json.dumps(now)) == stored["grids"]
    from trilith_xval.compare.measure.restitution_map import not_exposed
    assert not_exposed() == stored["not_exposed"]
