"""A stored atlas brought under the step rule: only the points where the rule can
act are remeasured, the rest carried; a remeasure of an atlas already under the
rule changes nothing; other model points or steps are refused."""
from __future__ import annotations

import copy
import json

import pytest

from trilith_xval.compare.campaign.atlas import AtlasConfig, run_atlas
from trilith_xval.compare.campaign.atlas_restep import (cause_changes, merge_restep,
                                                        restep_config, rule_points)
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.store import RunStore

# One Fig. 8 scene, two frequencies, Pymunk at 5e-4 s (a settings file's step, as
# the stored atlas's part) and 2.5e-3 s, where the low frequency fails and the high
# one agrees (stated by the first assertion).
CONFIG = AtlasConfig(engines=("pymunk",), scenes=(("fig8_lam5_gamma0.1", "sine"),),
                     omegas=(16.0, 18.0), factors=(1.0, 5.0), cases=("no_pendulum",),
                     settings=(("pymunk", (("dt", 5e-4),)),))


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    previous = runs.activate(RunStore(tmp_path_factory.mktemp("store")))
    try:
        yield run_atlas(CONFIG)
    finally:
        runs.activate(previous)


def _row(dt, cause):
    return {"dt": dt, "cause": cause, "cpu_s": 1.0, "sim_s": 1.0, "rel_error": 0.0,
            "n_runs": 1}


def _doc(rows_by_omega):
    return {"config": {"scenes": [["s", "sine"]], "omegas": list(rows_by_omega),
                       "factors": [1.0, 2.0], "cases": ["pendulum"], "rel_bracket": 0.03,
                       "rel_tol": 4e-3, "tol": 0.02},
            "steps": {"pymunk": [2e-4, 4e-4]},
            "points": [{"scene": "s", "case": "pendulum", "pulse": "sine", "omega": w,
                        "a_reference": 10.0, "mode": "after-impact", "valid": True,
                        "model_reason": "", "engines": {"pymunk": rows}}
                       for w, rows in rows_by_omega.items()]}


def test_the_rule_acts_only_on_failures_coarser_than_the_reference():
    doc = _doc({4.0: [_row(2e-4, "agrees"), _row(4e-4, "agrees")],
                6.0: [_row(2e-4, "agrees"), _row(4e-4, "window")],
                8.0: [_row(2e-4, "collapse")],           # coarser than 1e-4: the rule acts
                10.0: [_row(1e-4, "collapse")],          # at the reference: nothing finer
                12.0: []})                               # model invalid: no rows
    assert [p[3] for p in rule_points(doc, "pymunk")] == [6.0, 8.0]
    with pytest.raises(ValueError, match="--engine: 'drake' is not in the stored atlas"):
        rule_points(doc, "drake")


def test_changes_are_counted_per_step():
    before = _doc({6.0: [_row(2e-4, "agrees"), _row(4e-4, "window")]})
    after = _doc({6.0: [_row(2e-4, "agrees"), _row(4e-4, "discretisation")]})
    changes = cause_changes(before, after, "pymunk")
    assert changes[repr(4e-4)]["changed"] == changes[repr(4e-4)]["to_discretisation"] == 1
    assert changes[repr(2e-4)]["changed"] == 0


def test_other_model_points_or_steps_are_refused():
    doc = _doc({6.0: [_row(2e-4, "agrees"), _row(4e-4, "window")]})
    part = copy.deepcopy(doc)
    part["points"][0]["a_reference"] = 10.5
    with pytest.raises(ValueError, match="model's a_reference"):
        merge_restep(doc, part, "pymunk")
    part = copy.deepcopy(doc)
    part["steps"]["pymunk"] = [1e-4, 2e-4]
    with pytest.raises(ValueError, match="calibration changed"):
        merge_restep(doc, part, "pymunk")


@pytest.mark.slow
def test_a_restep_remeasures_the_rules_points_and_reproduces_them(stored, tmp_path):
    rows = {p["omega"]: p["engines"]["pymunk"] for p in stored["points"]}
    assert rows[16.0][-1]["cause"] != "agrees" and rows[18.0][-1]["cause"] == "agrees"
    points = rule_points(stored, "pymunk")
    assert [p[3] for p in points] == [16.0]
    # A fresh store: the restep measures again, it does not read the first run.
    previous = runs.activate(RunStore(tmp_path / "fresh"))
    try:
        part = run_atlas(restep_config(stored, "pymunk", points))
    finally:
        runs.activate(previous)
    assert [p["omega"] for p in part["points"]] == [16.0]
    merged = merge_restep(stored, dict(part, command="restep"), "pymunk")
    strip = lambda doc: [[{k: v for k, v in r.items() if k not in ("cpu_s", "from_store")}
                          for r in p["engines"]["pymunk"]] for p in doc["points"]]
    # The atlas is already under the rule and the engine is deterministic: the
    # remeasured rows are the stored ones, and nothing changed.
    assert strip(merged) == strip(stored)
    (entry,) = merged["resteps"]
    assert entry["points"] == 1 and entry["command"] == "restep"
    assert all(c["changed"] == 0 for c in entry["changes"].values())
    json.dumps(merged, allow_nan=False)
    # The page says which rows were remeasured under the rule, and when.
    from trilith_xval.compare.report.atlas_page import atlas_html
    assert "step rule applied to Pymunk: 1 point where it can act" in atlas_html(merged)


@pytest.mark.parametrize("extra, message", [
    ((), "--restep writes the whole atlas: give --json FILE"),
    (("--json", "OUT", "--engine", "bullet"), "unknown engine"),
    (("--json", "OUT", "--engine", "pymunk", "--from", "X"), "--restep runs alone"),
])
def test_the_command_refuses_bad_restep_input_before_any_work(extra, message, tmp_path,
                                                               capsys):
    from trilith_xval.compare.cli.main import main
    from tests.support.paths import ROOT
    stored = ROOT / "docs" / "validation" / "atlas.json"
    args = [str(tmp_path / "out.json") if a == "OUT" else a for a in extra]
    assert main(["atlas", "--restep", str(stored), *args]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out.json").exists()


def test_a_missing_stored_atlas_is_named_by_its_option(tmp_path, capsys):
    from trilith_xval.compare.cli.main import main
    assert main(["atlas", "--restep", str(tmp_path / "none.json"), "--engine", "pymunk",
                 "--json", str(tmp_path / "out.json")]) == 2
    assert "--restep" in capsys.readouterr().err


def test_a_restep_records_the_command_that_repeats_it(tmp_path, monkeypatch, capsys):
    """The stored command names only what a restep reads; no point of a stored
    atlas already under the rule and at the reference step is rerun."""
    from trilith_xval.compare.cli.main import main
    doc = _doc({6.0: [_row(2e-4, "agrees")]})  # agrees: nothing to rerun
    doc.update(schema_version=1, cost=[], what="atlas")
    for key, value in (("omegas", [6.0]), ("scenes", [["fig5", "cosine"]]),
                       ("cases", ["pendulum"])):
        doc["config"][key] = value
    doc["points"][0].update(scene="fig5", pulse="cosine")
    doc["steps"] = {"pymunk": [2e-4, 4e-4]}  # Pymunk's calibrated step and 2x
    stored = tmp_path / "stored.json"
    stored.write_text(json.dumps(doc))
    out = tmp_path / "out.json"
    assert main(["atlas", "--restep", str(stored), "--engine", "pymunk", "--json", str(out),
                 "--no-cache", "--workers", "1"]) == 0
    (entry,) = json.loads(out.read_text())["resteps"]
    assert entry["points"] == 0
    assert entry["command"] == (f"trilith atlas --restep {stored} --engine pymunk --json {out} "
                                "--workers 1 --no-cache")
