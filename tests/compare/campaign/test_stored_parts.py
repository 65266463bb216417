"""The default report: which parts it recomputes, which it shows from storage
(labelled with file, commit and date), and that a stored value that no longer
holds fails it.

No test here runs the default report with its engines: the campaign's jobs are
replaced by stand-ins that record what was asked (the structure), and the one
real re-measurement is Pymunk's 12 rad/s spectrum point (~1 CPU s).
"""
from __future__ import annotations

import json
import shutil

import pytest

from tests.support.paths import ROOT
from trilith_xval.compare.campaign import stored_parts
from trilith_xval.compare.campaign.config import CampaignConfig

STORED = ROOT / "docs" / "validation" / "summary.json"


def _stored_doc(points: dict) -> dict:
    """A stored run holding ``points``: {(case, engine): [(omega, rel_error, cpu_s)]}."""
    spectra = {}
    for (case, engine), rows in points.items():
        spectra.setdefault(case, {"engines": {}})["engines"][engine] = [
            {"omega": w, "rel_error": e, "cpu_s": c, "a_engine": 1.0} for w, e, c in rows]
    return {"spectra": spectra}


def test_the_threshold_sample_rule():
    """The lowest frequency and the stored weakest point; a point over the CPU cap
    stays stored; with no stored run every frequency is recomputed."""
    omegas = [5.0, 7.5, 9.5, 12.0, 14.0, 19.5]
    doc = _stored_doc({("no_pendulum", "x"): [(5.0, -0.002, 27.0), (7.5, 0.002, 24.0),
                                               (9.5, 0.002, 18.0), (12.0, 0.0135, 24.0),
                                               (14.0, 0.0225, 336.0), (19.5, -0.004, 20.0)],
                       ("pendulum", "y"): [(w, 0.0023, 3.0) for w in omegas]})
    # weakest 14.0 cost 336 CPU s > POINT_CPU_CAP: shown from storage
    assert stored_parts.recompute_omegas(doc, "x", "no_pendulum", omegas) == [5.0]
    # ties: the higher frequency
    assert stored_parts.recompute_omegas(doc, "y", "pendulum", omegas) == [5.0, 19.5]
    assert stored_parts.recompute_omegas(None, "y", "pendulum", omegas) == omegas


def test_the_stored_run_is_refused_for_another_grid_or_scene():
    from trilith_xval.scenes import load_scene
    scene = load_scene("fig5")
    doc, why = stored_parts.load_stored(STORED, scene, CampaignConfig.default_report())
    assert doc is not None and why == ""
    _, why = stored_parts.load_stored(STORED, scene, CampaignConfig.default_report(
        n_frequencies=3))
    assert "grid" in why
    _, why = stored_parts.load_stored(STORED, scene.replace(lam=4.0),
                                      CampaignConfig.default_report())
    assert "scene" in why
    # nor is a stored engine spectrum re-measured on another scene
    assert stored_parts.reverify_jobs(["pymunk"], scene.replace(lam=4.0)) == []
    assert len(stored_parts.reverify_jobs(["pymunk"], scene)) == 1


@pytest.fixture(scope="module")
def default_run():
    """The default campaign on the real stored run, every engine job replaced by a
    stand-in: thresholds and the rest raise (recorded as errors, cheap), the
    re-verification returns a disagreeing row for Drake."""
    import trilith_xval.compare.campaign.validation as campaign
    from trilith_xval.compare.campaign import validation_jobs as jobs

    def refuse(job):
        raise RuntimeError("stand-in")

    def reverify(job):
        name, scene, point, source = job.args()
        return {"engine": name, "case": "pendulum", "omega": point["omega"],
                "a_stored": point["a_engine"], "a_now": point["a_engine"] * 1.05,
                "mode_stored": "x", "mode_now": "x", "rel_difference": 0.05,
                "tolerance": stored_parts.REVERIFY_TOL, "passed": name != "drake",
                "source": source}

    kinds = (jobs.HistoryJob, jobs.RestitutionJob, jobs.ThresholdPointJob, jobs.JumpJob,
             jobs.LongRunJob, jobs.ReverifyJob)
    saved = {kind: kind.__call__ for kind in kinds}
    for kind in kinds:
        kind.__call__ = reverify if kind is jobs.ReverifyJob else refuse
    try:
        config = CampaignConfig.default_report(engines=("pymunk", "drake"), points=("A",),
                                               restitution_lams=(5.0,),
                                               restitution_mus=(1.0,), pendulum_lams=(5.0,),
                                               long_runs=False, workers=1)
        result = campaign.run_campaign(config)
    finally:
        for kind, call in saved.items():
            kind.__call__ = call
    return result


def test_default_report_recomputes_the_sample_and_labels_the_rest(default_run):
    result = default_run
    stored = json.loads(STORED.read_text())
    asked = {(e["args"][2], e["backend"], e["args"][3]) for e in result.errors
             if e["job"] == "threshold"}
    assert not [e for e in result.errors if e["job"] == "jump"]  # jumps: from storage
    parts = result.sources["parts"]
    for case in ("pendulum", "no_pendulum"):
        for engine in ("pymunk", "drake"):
            split = parts["thresholds"][engine][case]
            points = stored["spectra"][case]["engines"][engine]
            rule = stored_parts.recompute_omegas(stored, engine, case,
                                                 [p["omega"] for p in points])
            assert split["recomputed"] == rule
            assert {w for c, e, w in asked if (c, e) == (case, engine)} == set(rule)
            assert sorted(split["recomputed"] + split["stored"]) == [p["omega"] for p in points]
            shown = result.spectra[case]["engines"][engine]
            label = result.sources["stored_run"]
            for p in shown:  # every point shown is stored-and-labelled (the others raised)
                assert p["stored"] == label and p["omega"] in split["stored"]
    assert label["file"] == "docs/validation/summary.json"
    assert label["run_commit"] == stored["provenance"]["commit"]
    assert label["commit"] != "unknown" and label["date"] != "unknown"
    shifts = result.spectra["pendulum"]["jump_shifts"]
    assert set(shifts) == {"pymunk", "drake"} and all(s["stored"] == label
                                                        for s in shifts.values())
    assert parts["jump_shifts"] == "stored" and parts["restitution"] == "recomputed"
    for engine in ("pymunk", "drake"):
        src = result.sources["engine_spectra"][engine]
        assert src["file"] == f"docs/validation/engine_spectrum_{engine}.json"
        assert src["commit"] != "unknown"
    assert result.sources["atlas"]["file"] == "docs/validation/atlas.json"


@pytest.fixture
def no_validity(monkeypatch):
    """The model-validity overlay of the spectra (tens of CPU s) is not under test."""
    from trilith_xval.compare.report import html
    monkeypatch.setattr(html, "add_model_validity", lambda doc, scene, workers=1: doc)


def test_the_page_and_json_label_what_is_stored(default_run, tmp_path, no_validity):
    from trilith_xval.compare.report.html import write_report
    paths = write_report(default_run, tmp_path)
    doc = json.loads(paths["json"].read_text())
    assert doc["sources"]["stored_run"]["file"] == "docs/validation/summary.json"
    page = paths["html"].read_text()
    assert "Recomputed and stored parts" in page and "docs/validation/summary.json" in page
    assert doc["sources"]["stored_run"]["commit"][:12] in page
    assert "engine_spectrum_drake.json" in page and "DISAGREES" in page
    # one line above the trust table, the section after it (the first screen stays the table)
    assert page.index("Default report:") < page.index("<h2>Trust table</h2>") < page.index(
        "id='sources'")
    assert "re-verification failed: drake" in page.split("<h2>Trust table</h2>")[0]
    md = paths["md"].read_text()
    assert "re-verification failed: drake" in md


def test_a_disagreement_fails_the_report(default_run, monkeypatch, tmp_path, capsys,
                                         no_validity):
    """The CLI exits 1 and names the stored file, frequency and both values."""
    import trilith_xval.compare.campaign.validation as campaign
    from trilith_xval.compare.cli.main import main
    monkeypatch.setattr(campaign, "run_campaign", lambda config, progress=False: default_run)
    assert main(["report", "--engine", "pymunk,drake", "--out", str(tmp_path / "r")]) == 1
    err = capsys.readouterr().err
    assert "re-verification failed: drake docs/validation/engine_spectrum_drake.json" in err
    assert "tolerance 1 %" in err


def test_a_tampered_stored_spectrum_point_fails_the_reverification(tmp_path, monkeypatch):
    """Pymunk's stored 12 rad/s point measured again: as stored it agrees; with its
    a_engine raised 3 % (beyond the 1 % tolerance) it fails."""
    from trilith_xval.scenes import load_scene
    src = ROOT / "docs" / "validation" / "engine_spectrum_pymunk.json"
    monkeypatch.setattr(stored_parts, "VALIDATION", tmp_path)
    shutil.copy(src, tmp_path / src.name)
    ((engine, point, source),) = stored_parts.reverify_jobs(["pymunk"])
    scene = load_scene("fig5")
    assert stored_parts.reverify_one(engine, scene, point, source)["passed"]
    doc = json.loads(src.read_text())
    for p in doc["engines"]["pymunk"]["curves"]["pendulum"]:
        if p["omega"] == point["omega"]:
            p["a_engine"] *= 1.03
    (tmp_path / src.name).write_text(json.dumps(doc))
    ((engine, point, source),) = stored_parts.reverify_jobs(["pymunk"])
    row = stored_parts.reverify_one(engine, scene, point, source)
    assert not row["passed"] and row["rel_difference"] == pytest.approx(-0.03 / 1.03, rel=1e-6)
    (line,) = stored_parts.failures({"reverified": [row]})
    assert "pymunk" in line and "Omega = 12 rad/s" in line


def test_the_default_report_shows_the_stored_long_runs_labelled(monkeypatch):
    """No long run is run; the stored rows are shown with their run, and the verdict
    says where they come from."""
    import trilith_xval.compare.campaign.validation as campaign
    from trilith_xval.compare.campaign import validation_jobs as jobs
    ran = []

    def refuse(job):
        ran.append(type(job).__name__)
        raise RuntimeError("stand-in")
    for kind in (jobs.HistoryJob, jobs.RestitutionJob, jobs.ThresholdPointJob, jobs.JumpJob,
                 jobs.LongRunJob, jobs.ReverifyJob):
        monkeypatch.setattr(kind, "__call__", refuse)
    config = CampaignConfig.default_report(engines=("pymunk",), points=("A",),
                                           restitution_lams=(5.0,), restitution_mus=(1.0,),
                                           pendulum_lams=(5.0,), reverify=False, workers=1)
    result = campaign.run_campaign(config)
    stored = json.loads(STORED.read_text())
    assert "LongRunJob" not in ran and ran  # the other jobs were asked for
    assert result.sources["parts"]["long_runs"] == "stored"
    rows = [r for r in stored["long_runs"] if r["backend"] == "pymunk"]
    assert [{k: v for k, v in r.items() if k != "stored"} for r in result.long_runs] == rows
    label = result.sources["stored_run"]
    assert all(r["stored"] == label for r in result.long_runs)
    (verdict,) = [v for v in result.verdicts if v["id"] == "long_run"]
    assert "from docs/validation/summary.json" in verdict["detail"]
    # Another window: the stored rows do not apply and the long runs are run.
    ran.clear()
    campaign.run_campaign(CampaignConfig.default_report(
        engines=("pymunk",), points=("A",), restitution_lams=(5.0,), restitution_mus=(1.0,),
        pendulum_lams=(5.0,), reverify=False, workers=1, long_run_t_max=10.0))
    assert "LongRunJob" in ran
