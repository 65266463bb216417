"""The trust atlas: staged steps, no engine run where the model is invalid, one
job for identical frames, resumable through the store; the page renders it."""
from __future__ import annotations

import base64
import json

import pytest

from trilith_xval.compare.campaign import atlas
from trilith_xval.compare.campaign.atlas import AtlasConfig, atlas_scenes, base_step, run_atlas
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.store import RunStore

# Two Fig. 8 scenes of one lam: their no-pendulum frames are one trilith.
SCENES = (("fig8_lam5_gamma0.1", "sine"), ("fig8_lam5_gamma0.3", "sine"))


@pytest.fixture
def store(tmp_path):
    previous = runs.activate(RunStore(tmp_path / "store"))
    yield
    runs.activate(previous)


def test_scenes_resolve_to_the_papers_figures():
    names = atlas_scenes(AtlasConfig())
    assert ("fig5", "cosine") in names  # Fig. 10
    assert sum(n.startswith("fig8_") for n, _ in names) == 9
    assert sum(n.startswith("fig9_") for n, _ in names) == 12
    assert sum(n.startswith("fig11_") for n, _ in names) == 4


@pytest.mark.parametrize("bad", [dict(factors=(2.0, 1.0)), dict(factors=(0.5,)),
                                 dict(engines=("bullet",))])
def test_bad_configs_are_refused(bad):
    with pytest.raises(ValueError):
        AtlasConfig(**bad)


@pytest.mark.slow
def test_staged_deduplicated_resumable(store, monkeypatch):
    config = AtlasConfig(engines=("pymunk",), scenes=SCENES, omegas=(18.0,),
                         factors=(1.0, 5.0), cases=("no_pendulum",))
    jobs = []
    real = atlas.runs.run_many

    def counting(fn, items, **kw):
        items = list(items)
        if fn.__name__ == "run_threshold":
            jobs.append(len(items))
        return real(fn, items, **kw)
    monkeypatch.setattr(atlas.runs, "run_many", counting)
    doc = run_atlas(config)
    pts = doc["points"]
    assert len(pts) == 2  # 2 scenes x 1 case x 1 Omega
    assert jobs[0] == 1  # the two no-pendulum frames are one job
    dt = base_step("pymunk", config)
    for pt in pts:
        rows = pt["engines"]["pymunk"]
        assert rows[0]["dt"] == pytest.approx(dt)
        # The coarser step ran exactly where the calibrated one agreed.
        assert (len(rows) == 2) == (rows[0]["cause"] == "agrees")
        if len(rows) == 2:
            assert rows[1]["dt"] == pytest.approx(5 * dt)
    assert any(len(pt["engines"]["pymunk"]) == 2 for pt in pts)  # Omega 18 agrees at 2e-3 s
    np_rows = [pt["engines"]["pymunk"] for pt in pts if pt["case"] == "no_pendulum"]
    assert np_rows[0] == np_rows[1]
    (first,) = [c for c in doc["cost"] if c["dt"] == pytest.approx(dt)]
    assert (first["points"], first["jobs"]) == (2, 1)  # one trick, counted once
    assert first["cpu_s"] == pytest.approx(pts[0]["engines"]["pymunk"][0]["cpu_s"])
    # Resumed: every result from the store, the same numbers.
    runs.STATS.clear()
    again = run_atlas(config)
    assert runs.STATS.get("computed", 0) == 0
    strip = [[{k: v for k, v in r.items() if k != "from_store"} for r in p["engines"]["pymunk"]]
             for p in again["points"]]
    assert strip == [[{k: v for k, v in r.items() if k != "from_store"}
                      for r in p["engines"]["pymunk"]] for p in pts]
    # The rows say who served them: computed first, the store on the rerun.
    assert not any(r["from_store"] for p in pts for r in p["engines"]["pymunk"])
    assert all(r["from_store"] for p in again["points"] for r in p["engines"]["pymunk"])


def test_spread_order_covers_every_scene_before_refining_omega():
    omegas = [4.0 + 2 * k for k in range(13)]
    points = [{"scene": s, "case": c, "pulse": "sine", "omega": w}
              for s in ("a", "b", "c") for c in ("pendulum", "no_pendulum") for w in omegas]
    order = atlas.spread_order(list(range(len(points))), points)
    assert sorted(order) == list(range(len(points)))  # a permutation: nothing lost
    groups = {(p["scene"], p["case"]) for p in points}
    # A budget that stops after one job per group has touched every scene and case ...
    assert {(points[i]["scene"], points[i]["case"]) for i in order[:6]} == groups
    # ... and after four per group each has Omegas spread over the range, not its
    # four lowest (coarse to fine: the gaps are at most a quarter of the range plus).
    for g in groups:
        first = sorted(points[i]["omega"] for i in order[:24]
                       if (points[i]["scene"], points[i]["case"]) == g)
        assert len(first) == 4 and first[0] == 4.0 and first[-1] >= 20.0
        assert max(b - a for a, b in zip(first, first[1:])) <= 8.0


def test_a_time_budget_records_the_jobs_it_did_not_run(store, monkeypatch):
    config = AtlasConfig(engines=("pymunk",), scenes=SCENES[:1], omegas=(12.0,),
                         factors=(1.0,), cases=("pendulum",))

    def no_engine(job):
        raise AssertionError("an engine ran after the budget")
    monkeypatch.setattr("trilith_xval.compare.campaign.study.run_threshold", no_engine)
    doc = run_atlas(config, budget_s=0.0)
    (pt,) = doc["points"]
    assert pt["engines"]["pymunk"] == []
    assert doc["not_run"] == {"pymunk": {repr(base_step("pymunk", config)): 1}}


def test_a_budget_leaves_points_measured_at_every_step(monkeypatch):
    # Twelve points, rounds of ten: a budget that ends after the first round's
    # two steps leaves ten points with both steps and two unmeasured, never
    # twelve at the calibrated step and none at the coarser one.
    config = AtlasConfig(engines=("pymunk",), scenes=SCENES,
                         omegas=tuple(4.0 + 4 * k for k in range(6)), factors=(1.0, 2.0),
                         cases=("pendulum",))
    clock = [0.0]
    calls = []

    def fake_run_many(fn, items, workers=1, on_done=None):
        if fn.__name__ == "run_reference":
            return [(10.0 + job[3], "no-impact") for job in items]
        if fn.__name__ == "_validity":
            return [{"model_valid": True, "model_reason": "valid"} for _ in items]
        clock[0] += 1.0  # each chunk of engine jobs takes one "second"
        calls.append(len(items))
        return [{"dt": job.dt, "dt_used": job.dt, "a_engine": job.a_ref, "rel_error": 0.0,
                 "cause": "agrees", "cpu_s": 1.0, "sim_s": 1.0} for job in items]
    monkeypatch.setattr(atlas.runs, "run_many", fake_run_many)
    monkeypatch.setattr(atlas.time, "perf_counter", lambda: clock[0])
    doc = run_atlas(config, workers=1, budget_s=1.5)
    dt = base_step("pymunk", config)
    counts = sorted(len(pt["engines"]["pymunk"]) for pt in doc["points"])
    assert counts == [0, 0] + [2] * 10
    assert calls == [10, 10]
    assert doc["not_run"] == {"pymunk": {repr(dt): 2}}


def test_no_engine_runs_where_the_model_is_invalid(store, monkeypatch):
    config = AtlasConfig(engines=("pymunk",), scenes=SCENES[:1], omegas=(12.0,),
                         factors=(1.0,), cases=("pendulum",))
    monkeypatch.setattr(atlas, "_validity", lambda job: {"model_valid": False,
                                                         "model_reason": "lintel lifts"})

    def no_engine(job):
        raise AssertionError("an engine ran where the model is invalid")
    monkeypatch.setattr("trilith_xval.compare.campaign.study.run_threshold", no_engine)
    doc = run_atlas(config)
    (pt,) = doc["points"]
    assert pt["valid"] is False and pt["model_reason"] == "lintel lifts"
    assert pt["engines"]["pymunk"] == []


def _synthetic() -> dict:
    pts = []
    for scene, valid, rows in (("fig8_a", True, [{"dt": 2e-3, "rel_error": 0.004,
                                                  "cause": "agrees", "cpu_s": 0.3,
                                                  "sim_s": 5.0},
                                                 {"dt": 4e-3, "rel_error": 0.03,
                                                  "cause": "window", "cpu_s": 0.2,
                                                  "sim_s": 5.0}]),
                               ("fig8_b", False, []),
                               ("fig9_c", True, [{"dt": 2e-3, "rel_error": -0.05,
                                                  "cause": "unknown", "cpu_s": 0.4,
                                                  "sim_s": 4.0}])):
        pts.append({"scene": scene, "case": "pendulum", "pulse": "sine", "omega": 10.0,
                    "a_reference": 10.0, "mode": "no-impact", "valid": valid,
                    "model_reason": "" if valid else "columns hop",
                    "engines": {"pymunk": rows}})
    return {"config": {"tol": 0.02, "factors": [1, 2], "omegas": [10.0]},
            "steps": {"pymunk": [2e-3, 4e-3]}, "points": pts, "engines_not_run": ["pybullet"],
            "cost": atlas.cost_table(pts, ("pymunk",))}


def test_trusted_region_counts_only_valid_points():
    from trilith_xval.compare.report.atlas_page import trusted_rows
    rows = trusted_rows(_synthetic())
    assert rows[0][:5] == ["pymunk", "0.002", "1 / 2", "50 %", "5 %"]
    assert "fig9_c 10: unknown" in rows[0][5]
    assert rows[1][:4] == ["pymunk", "0.004", "0 / 2", "0 %"]
    assert "fig8_a 10: window" in rows[1][5]


def test_the_share_counts_the_points_a_budget_reached():
    from trilith_xval.compare.report.atlas_page import trusted_rows
    doc = _synthetic()
    doc["points"][2]["engines"]["pymunk"] = []  # fig9_c: left by the budget at 2e-3 s
    doc["not_run"] = {"pymunk": {repr(2e-3): 1}}
    rows = trusted_rows(doc)
    # One valid point reached, and it agrees at 2e-3 s: 100 % of what was measured,
    # with the valid points it was not judged on stated beside.
    assert rows[0][2:4] == ["1 / 1 (of 2)", "100 %"]
    assert "1 points not run" in rows[0][5]


def test_page_shows_maps_tables_and_what_was_not_run(tmp_path):
    from trilith_xval.compare.report.atlas_page import write_page
    path = write_page(_synthetic(), tmp_path / "atlas.html")
    text = path.read_text()
    assert "not run: pybullet" in text and "Trusted region per engine and step" in text
    png = text.split("data:image/png;base64,")[1].split("'")[0]
    assert base64.b64decode(png)[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.dumps(_synthetic())  # the document is plain data


def test_the_report_section_reads_the_stored_atlas(tmp_path):
    from trilith_xval.compare.report.atlas_page import stored_atlas_section
    assert "No stored atlas" in stored_atlas_section(tmp_path / "missing.json")
    path = tmp_path / "atlas.json"
    path.write_text(json.dumps(_synthetic()))
    text = stored_atlas_section(path)
    assert "id='atlas'" in text and text.count("data:image/png;base64,") == 1


def test_a_point_left_by_the_budget_is_marked_not_measured():
    # A valid point with no engine row was never measured: a dash, never read as
    # an agreeing cell (blank white is the colour of a 0 % error).
    from trilith_xval.compare.report.atlas_page import _grid
    doc = _synthetic()
    doc["points"][0]["engines"]["pymunk"] = []
    labels, omegas, err, text, invalid = _grid(doc, "pymunk", "pendulum")
    assert text[0][0] == "–" and err[0, 0] != err[0, 0]  # NaN: nothing to colour


@pytest.mark.slow
def test_the_cost_counts_the_workers_cpu():
    # With a pool the engine jobs run in child processes: the parent's own CPU is
    # a few per cent of the work, so the atlas records the workers' too.
    config = AtlasConfig(engines=("pymunk",), scenes=SCENES[:1], omegas=(12.0, 18.0),
                         factors=(1.0,), cases=("pendulum",))
    doc = run_atlas(config, workers=2)
    jobs_cpu = sum(c["cpu_s"] for c in doc["cost"])
    assert jobs_cpu > 0
    # Each job's CPU is measured inside a worker, so the workers' total holds it
    # (1 % for the two clocks' rounding).
    assert doc["local_cpu_s"] >= 0.99 * jobs_cpu
    assert doc["local_cpu_s"] > doc["parent_cpu_s"]


def test_a_part_line_never_calls_the_parents_cpu_the_whole_cost():
    from trilith_xval.compare.report.atlas_page import part_line, parts_of
    doc = _synthetic()
    doc.update(workers=2, parent_cpu_s=14.0, wall_s=600.0, load_average=[0.1, 1.9])
    (part,) = parts_of(doc)
    assert part["engine_cpu_s"] == pytest.approx(sum(c["cpu_s"] for c in doc["cost"]))
    assert "in the engine jobs (the workers' whole CPU was not recorded)" in part_line(part)
    assert "14 CPU s" not in part_line(part)
    doc["local_cpu_s"] = 900.0
    assert "900 CPU s (the process and its workers)" in part_line(parts_of(doc)[0])
    doc.update(workers=1, local_cpu_s=None)
    assert "14 CPU s in the process" in part_line(parts_of(doc)[0])
