"""Atlases of different engines, measured separately, join into one only when they
measured the same thing (compare/campaign/atlas_merge.py)."""
from __future__ import annotations

import copy
import json
import shlex

import pytest

from trilith_xval.compare.campaign import atlas
from trilith_xval.compare.campaign.atlas_merge import merge_atlases
from trilith_xval.compare.cli.main import main


def _part(engine: str, error: float, load: float) -> dict:
    pts = []
    for scene, valid in (("fig8_a", True), ("fig8_b", False)):
        rows = [{"dt": 1e-3, "rel_error": error, "cause": "agrees", "cpu_s": 0.5,
                 "sim_s": 5.0}] if valid else []
        pts.append({"scene": scene, "case": "pendulum", "pulse": "sine", "omega": 10.0,
                    "a_reference": 10.0, "mode": "no-impact", "valid": valid,
                    "model_reason": "" if valid else "columns hop", "engines": {engine: rows}})
    return {"schema_version": 1, "config": {"engines": [engine], "scenes": [["fig8_*", "sine"]],
                                            "omegas": [10.0], "factors": [1.0],
                                            "cases": ["pendulum"], "rel_bracket": 0.03,
                                            "rel_tol": 0.004, "tol": 0.02, "settings": {}},
            "versions": {engine: f"{engine} 1.0"}, "steps": {engine: [1e-3]}, "points": pts,
            "cost": atlas.cost_table(pts, (engine,)), "not_run": {},
            "command": f"trilith atlas --engine {engine}", "wall_s": 10.0,
            "parent_cpu_s": 8.0, "load_average": [load, load + 1], "workers": 1}


def test_parts_join_with_their_provenance():
    merged = merge_atlases([_part("pymunk", 0.001, 1.0), _part("dart", -0.004, 3.0)])
    assert list(merged["steps"]) == ["pymunk", "dart"]
    assert merged["points"][0]["engines"]["dart"][0]["rel_error"] == -0.004
    assert merged["points"][0]["engines"]["pymunk"][0]["rel_error"] == 0.001
    assert [p["command"] for p in merged["parts"]] == ["trilith atlas --engine pymunk",
                                                       "trilith atlas --engine dart"]
    assert merged["load_average"] == [1.0, 4.0] and merged["wall_s"] == 20.0
    assert {c["engine"] for c in merged["cost"]} == {"pymunk", "dart"}
    assert "pymunk" not in merged["engines_not_run"] and "drake" in merged["engines_not_run"]
    # A merged atlas merges again: its parts are kept, not nested.
    again = merge_atlases([merged, _part("drake", 0.0, 2.0)])
    assert len(again["parts"]) == 3 and list(again["steps"]) == ["pymunk", "dart", "drake"]


@pytest.mark.parametrize("spoil, needle", [
    (lambda d: d["config"].update(omegas=[12.0]), "config 'omegas' differs"),
    (lambda d: d["points"][0].update(a_reference=10.5), "the model differs at fig8_a"),
    (lambda d: d["points"].pop(), "different points"),
    (lambda d: d.update(steps={"pymunk": [1e-3]}), "engine 'pymunk' is in both"),
    (lambda d: d.pop("steps"), "not an atlas"),
])
def test_parts_that_measured_different_things_are_refused(spoil, needle):
    other = _part("dart", 0.0, 1.0)
    spoil(other)
    with pytest.raises(ValueError, match=needle):
        merge_atlases([_part("pymunk", 0.0, 1.0), copy.deepcopy(other)], ["a.json", "b.json"])


def test_cli_joins_files_and_refuses_a_bad_one(tmp_path, capsys):
    a, b, out = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "all.json"
    a.write_text(json.dumps(_part("pymunk", 0.001, 1.0)))
    b.write_text(json.dumps(_part("mujoco", 0.002, 1.0)))
    assert main(["atlas", "--from", str(a), "--from", str(b), "--json", str(out),
                 "--html", str(tmp_path / "all.html")]) == 0
    doc = json.loads(out.read_text())
    assert list(doc["steps"]) == ["pymunk", "mujoco"]
    # The recorded command is the join itself: no engine list, grid or workers,
    # which a join does not read (and which would name engines it does not hold).
    assert shlex.split(doc["command"]) == ["trilith", "atlas", "--from", str(a), "--from", str(b),
                                           "--json", str(out), "--html",
                                           str(tmp_path / "all.html")]
    assert "Trusted region" in (tmp_path / "all.html").read_text()
    # A part's time budget left points unmeasured: the joined page says whose.
    part = _part("dart", 0.0, 1.0)
    part.update(budget_s=600.0, not_run={"dart": {"0.001": 1}})
    b.write_text(json.dumps(part))
    assert main(["atlas", "--from", str(a), "--from", str(b), "--html",
                 str(tmp_path / "b.html")]) == 0
    assert "a part's time budget (10 min) reached" in (tmp_path / "b.html").read_text()
    capsys.readouterr()
    (tmp_path / "c.json").write_text(json.dumps(_part("pymunk", 0.0, 1.0)))
    assert main(["atlas", "--from", str(a), "--from", str(tmp_path / "c.json"),
                 "--json", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: engine 'pymunk' is in both") and err.count("\n") == 1
    assert not (tmp_path / "x.json").exists()


def test_a_legacy_verbosity_in_a_recorded_command_becomes_its_switch():
    import shlex

    from trilith_xval.compare.campaign.atlas_merge import runnable_command
    from trilith_xval.compare.cli.main import build_parser

    parser, _ = build_parser()
    for legacy, expect in (("--verbosity 0", 0), ("--verbosity -1", -1), ("--verbosity 1", 1)):
        for line in (f"trilith atlas {legacy} --engine dart --workers 1",
                     f"trilith atlas --engine dart {legacy}"):
            fixed = runnable_command(line)
            assert "--verbosity" not in fixed
            args = parser.parse_args(shlex.split(fixed)[1:])  # trilith accepts it
            assert args.verbosity == expect and args.engine == "dart"
    assert runnable_command(None) is None


def test_select_engines_keeps_their_rows_and_rejoins_whole():
    """The stored atlas split into two engine sets and joined again is the same
    atlas (rows, steps, cost), its parts listing only the engines each measured."""
    import json
    from pathlib import Path

    from trilith_xval.compare.campaign.atlas_merge import merge_atlases, select_engines
    stored = json.loads((Path(__file__).parents[3] / "docs/validation/atlas.json").read_text())
    engines = list(stored["steps"])
    a, b = select_engines(stored, engines[:2]), select_engines(stored, engines[2:])
    assert list(a["steps"]) == engines[:2] and all(set(pt["engines"]) == set(engines[:2])
                                                   for pt in a["points"])
    assert {c["engine"] for c in b["cost"]} == set(engines[2:])
    joined = merge_atlases([a, b])
    assert joined["points"] == stored["points"] and joined["steps"] == stored["steps"]
    assert sorted(map(str, joined["cost"])) == sorted(map(str, stored["cost"]))
    with pytest.raises(ValueError, match="not in the atlas: nosuch"):
        select_engines(stored, ["nosuch"])


def test_atlas_diff_counts_cause_changes_per_engine_and_step():
    import copy
    import json
    from pathlib import Path

    from trilith_xval.compare.report.atlas_diff import cause_changes, markdown
    old = json.loads((Path(__file__).parents[3] / "docs/validation/atlas.json").read_text())
    new = copy.deepcopy(old)
    engine = next(iter(new["steps"]))
    dt = new["steps"][engine][1]
    changed = 0
    for pt in new["points"]:
        for row in pt["engines"][engine]:
            if abs(row["dt"] - dt) < 1e-12 and row["cause"] != "agrees" and changed < 3:
                row["cause"] = "contact" if row["cause"] != "contact" else "unknown"
                changed += 1
    rows = {(r["engine"], r["dt"]): r for r in cause_changes(old, new, [engine])}
    assert rows[(engine, round(dt, 12))]["changed"] == changed > 0
    assert sum(r["changed"] for r in rows.values()) == changed
    assert "-> contact" in markdown(list(rows.values())) or "-> unknown" in markdown(
        list(rows.values()))


def test_a_join_keeps_the_consensus_of_the_part_that_has_one():
    """The engines' consensus where the model is invalid survives a join, whichever
    part carried it (a remeasured engine part is often joined first)."""
    import json

    from trilith_xval.compare.campaign.atlas_merge import merge_atlases, select_engines
    from tests.support.paths import ROOT
    stored = json.loads((ROOT / "docs" / "validation" / "atlas.json").read_text())
    if not stored.get("consensus"):
        pytest.skip("the stored atlas carries no consensus")
    engines = list(stored["steps"])
    one, rest = select_engines(stored, engines[:1]), select_engines(stored, engines[1:])
    rest = {**rest, "consensus": None,
            "points": [{k: v for k, v in p.items() if k not in ("consensus", "own")}
                       for p in rest["points"]]}
    for order in ((one, rest), (rest, one)):
        joined = merge_atlases(list(order), ["a", "b"])
        assert joined["consensus"] == stored["consensus"]
        assert [p.get("consensus") for p in joined["points"]] == \
            [p.get("consensus") for p in stored["points"]]
