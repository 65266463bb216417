"""The default report's split: what it recomputes now, what it shows from storage.

``trilith report`` (``make report``) must run in minutes on 2 cores, while the
stored full validation (``docs/validation/summary.json``) cost ~1,300 CPU s,
most of it Drake's and DART's threshold searches.  With a stored run given
(:attr:`CampaignConfig.stored`), the campaign

* recomputes every cheap check (restitution, the A-D histories and verdicts,
  theta(t), the long runs) and, per engine and curve, a sample of threshold
  points chosen by :func:`recompute_omegas`;
* takes the other threshold points and the mode-jump shifts from the stored run,
  each labelled with its file, commit and date (:func:`merge`);
* re-verifies the stored full engine spectra (``engine_spectrum_<engine>.json``)
  on one point per engine (:func:`reverify_jobs`, :func:`reverify_one`): the
  point is measured again now and any disagreement beyond
  :data:`REVERIFY_TOL` fails the report.

``trilith report --full`` (``make report-full``) runs no part of this.
"""
from __future__ import annotations

import hashlib
import json
import subprocess
from pathlib import Path

__all__ = ["ROOT", "STORED_SUMMARY", "REVERIFY_TOL", "REVERIFY_OMEGA", "POINT_CPU_CAP",
           "source_of", "load_stored", "recompute_omegas", "reverify_jobs", "reverify_one",
           "merge"]

ROOT = Path(__file__).resolve().parents[2]
VALIDATION = ROOT / "docs" / "validation"
STORED_SUMMARY = VALIDATION / "summary.json"

# The re-verified point of every stored engine spectrum: the pendulum curve at
# 12 rad/s.  Both stored grids hold it (3:30:1, and Drake's 3:30:3); it lies above
# the Omega_1 jump, mid-axis of Fig. 5, where every engine brackets a threshold.
# Fixed before any result is seen, the same frequency for every engine.
REVERIFY_OMEGA = 12.0
REVERIFY_CASE = "pendulum"
# Two brackets of the robust search, each rel_tol = 0.5 % wide: a code change that
# moves a threshold inside its bracket may shift the reported end by up to one
# bracket either way; more than two widths apart is a different threshold.
REVERIFY_TOL = 0.01
# A threshold point whose stored search cost more than a tenth of the default
# report's 600 CPU s budget is shown from storage (labelled) instead of being
# recomputed: Drake's no-pendulum 14 rad/s point cost 336 CPU s alone (its
# step-convergence reruns), its 5 rad/s pendulum point 70 CPU s.
POINT_CPU_CAP = 60.0
THRESHOLD_RULE = (
    "per engine and curve, the lowest frequency (the longest pulse: most steps and "
    "impacts before overturning, where a step's error builds up most) and the frequency "
    "whose stored point had the largest |rel_error| (the engine's weakest region at its "
    "calibrated step; ties: the higher frequency); a point whose stored search cost more "
    f"than {POINT_CPU_CAP:g} CPU s is shown from storage instead; every other point is "
    "shown from storage, labelled, and counts in the verdicts as stored")


def _git(path: Path, fmt: str) -> str | None:
    """``git log -1 --format=fmt -- path`` in the checkout, or None outside one."""
    try:
        out = subprocess.run(["git", "log", "-1", f"--format={fmt}", "--", str(path)],
                             cwd=ROOT, capture_output=True, text=True, timeout=10,
                             check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return out or None


def source_of(path, provenance: dict | None = None) -> dict:
    """Where a stored part comes from: ``file`` (relative to the checkout when
    inside it), ``sha256``, the ``commit`` and ``date`` that stored it (git),
    and, for a stored run, the ``run_commit``/``run_date`` of the code that
    measured it (its provenance)."""
    p = Path(path).resolve()
    try:
        name = str(p.relative_to(ROOT))
    except ValueError:
        name = str(p)
    out = {"file": name, "sha256": hashlib.sha256(p.read_bytes()).hexdigest(),
           "commit": _git(p, "%H") or "unknown", "date": _git(p, "%cI") or "unknown"}
    if provenance:
        out["run_commit"] = str(provenance.get("commit", "unknown"))
        out["run_date"] = str(provenance.get("date", "unknown"))
    return out


def load_stored(path, scene, config) -> tuple[dict | None, str]:
    """The stored run at ``path`` when it measured the same scene and the same
    threshold grid as ``config`` (else its points would not be the points this
    campaign chooses), with the reason when it cannot be used."""
    from trilith_xval.compare.campaign.summary import load
    from trilith_xval.compare.run.keys import scene_dict

    doc = load(path).raw  # ValueError naming the file
    grid = ("omega_range", "n_frequencies", "spectrum_step", "jump_margin", "rel_bracket",
            "rel_tol", "spectrum_cases", "jump_cases", "engine_dt", "engine_settings")
    ours = config.to_dict()
    theirs = doc.get("config") or {}
    if doc.get("sources"):  # a default report's summary: its points are partly stored already
        return None, "the stored run is itself a default report, not a full run"
    if doc.get("quick") or any(theirs.get(k) != ours.get(k) for k in grid):
        return None, "the stored run used another threshold grid or other settings"
    theirs_scene = doc.get("scene") or {}
    if any(theirs_scene.get(k) != v for k, v in scene_dict(scene).items()):
        return None, "the stored run measured another scene"
    return doc, ""


def uses_stored_long_runs(stored: dict | None, config) -> bool:
    """Whether the long runs are shown from ``stored`` rather than run: asked for
    (``long_run`` in ``config.stored_jobs``, long runs on) and measured over the
    same window."""
    return (stored is not None and config.long_runs and "long_run" in config.stored_jobs
            and (stored.get("config") or {}).get("long_run_t_max") == config.long_run_t_max
            and bool(stored.get("long_runs")))


def _stored_points(stored: dict | None, engine: str, case: str) -> dict:
    pts = ((stored or {}).get("spectra", {}).get(case) or {}).get("engines", {}).get(engine, [])
    return {round(float(p["omega"]), 6): p for p in pts}


def recompute_omegas(stored: dict | None, engine: str, case: str, omegas) -> list[float]:
    """The threshold frequencies of ``engine`` on curve ``case`` that the default
    report recomputes, out of the campaign's ``omegas``.

    The rule, stated before any result: the lowest frequency (the longest pulse:
    most steps and impacts before overturning, where a step's error builds up
    most) and the frequency whose stored point had the largest |rel_error| (the
    engine's weakest region at its calibrated step; ties and unbracketed points:
    the highest frequency).  A point whose stored search cost more than
    :data:`POINT_CPU_CAP` is shown from storage instead.  With no stored run
    every frequency is recomputed.
    """
    omegas = sorted(float(w) for w in omegas)
    if stored is None or not omegas:
        return omegas
    points = _stored_points(stored, engine, case)

    def weakness(w):
        err = (points.get(round(w, 6)) or {}).get("rel_error")
        return (float("inf") if err is None else abs(float(err)), w)
    chosen = {omegas[0], max(omegas[1:] or omegas, key=weakness)}

    def cost(w):
        return float((points.get(round(w, 6)) or {}).get("cpu_s") or 0.0)
    return sorted(w for w in chosen if cost(w) <= POINT_CPU_CAP)


def _spectrum_file(engine: str) -> Path:
    return VALIDATION / f"engine_spectrum_{engine}.json"


def reverify_jobs(engines, scene=None) -> list[tuple]:
    """``(engine, stored point, source)`` per engine with a stored spectrum of
    ``scene`` (default: any): its :data:`REVERIFY_CASE` point nearest
    :data:`REVERIFY_OMEGA`."""
    from trilith_xval.compare.run.keys import scene_dict
    jobs = []
    for engine in engines:
        path = _spectrum_file(engine)
        if not path.is_file():
            continue
        doc = json.loads(path.read_text())
        theirs = (doc.get("inputs") or {}).get("scene") or {}
        if scene is not None and any(theirs.get(k) != v for k, v in scene_dict(scene).items()):
            continue  # a spectrum of another scene says nothing of this one
        curve = doc["engines"][engine]["curves"][REVERIFY_CASE]
        point = min(curve, key=lambda p: abs(float(p["omega"]) - REVERIFY_OMEGA))
        jobs.append((engine, point, source_of(path)))
    return jobs


def reverify_one(engine: str, scene, point: dict, source: dict) -> dict:
    """Measure the stored spectrum ``point`` of ``engine`` again now, with the
    settings its command used (the calibrated threshold step, the point's
    ``rel_tol``; no step-convergence reruns: the stored ``a_engine`` is the
    calibrated step's), and compare: same verdict mode and
    |a_now - a_stored| / a_stored <= :data:`REVERIFY_TOL`."""
    from trilith_xval.compare.measure.engine_spectrum import measure_point, threshold_spec

    sc = scene if REVERIFY_CASE == "pendulum" else scene.without_pendulum()
    omega, a_ref = float(point["omega"]), float(point["a_reference"])
    spec = threshold_spec(engine, sc, omega, a_ref, calibrated=True)
    now = measure_point(spec, omega, a_ref, point.get("mode_reference"), case=REVERIFY_CASE,
                        rel_tol=float(point.get("rel_tol") or 5e-3), convergence=False).to_dict()
    a_then, a_now = point.get("a_engine"), now.get("a_engine")
    if a_then is None or a_now is None:
        diff, passed = None, a_then is None and a_now is None
    else:
        diff = (float(a_now) - float(a_then)) / float(a_then)
        passed = abs(diff) <= REVERIFY_TOL and now.get("mode_engine") == point.get("mode_engine")
    return {"engine": engine, "case": REVERIFY_CASE, "omega": omega,
            "a_stored": a_then, "a_now": a_now, "mode_stored": point.get("mode_engine"),
            "mode_now": now.get("mode_engine"), "rel_difference": diff,
            "tolerance": REVERIFY_TOL, "passed": bool(passed),
            "dt_stored": (point.get("provenance") or {}).get("dt"),
            "dt_now": (now.get("provenance") or {}).get("dt"),
            "cpu_s": now.get("cpu_s"), "source": source}


def failures(doc: dict) -> list[str]:
    """One line per stored value that did not hold when re-measured (``doc``: a
    summary document or a :class:`CampaignResult`'s ``sources``)."""
    sources = doc.get("sources", doc) or {}
    return [reverify_message(r) for r in sources.get("reverified") or () if not r["passed"]]


def reverify_message(row: dict) -> str:
    """The one line that says a stored value no longer holds."""
    if row.get("error"):
        return (f"re-verification failed: {row['engine']} {row['source']['file']} "
                f"({row['case']}, Omega = {row['omega']:g} rad/s): {row['error']}")
    def fmt(a):
        return "none" if a is None else f"{float(a):.4g}"
    diff = row["rel_difference"]
    return (f"re-verification failed: {row['engine']} {row['source']['file']} "
            f"({row['case']}, Omega = {row['omega']:g} rad/s): stored a_engine "
            f"{fmt(row['a_stored'])}"
            f" ({row['mode_stored']}), now {fmt(row['a_now'])} ({row['mode_now']})"
            + ("" if diff is None else f", {100 * diff:+.2f} %")
            + f"; tolerance {100 * row['tolerance']:g} %")


def merge(result, stored: dict | None, source: dict | None, recomputed: dict,
          reverified: list, reason: str = "") -> None:
    """Complete ``result`` (a :class:`CampaignResult` whose spectra hold the
    recomputed points) with the stored parts, each labelled, and record in
    ``result.sources`` what was recomputed and what was stored.

    ``recomputed``: ``{(case, engine): [omega, ...]}`` recomputed now;
    ``reverified``: rows of :func:`reverify_one`.
    """
    from trilith_xval.compare.report.atlas_page import STORED as ATLAS

    label = None if source is None else {k: source[k] for k in ("file", "commit", "date",
                                                                "run_commit", "run_date")
                                         if k in source}
    parts = {"restitution": "recomputed", "histories": "recomputed",
             "long_runs": "recomputed" if result.config.long_runs else "not run"}
    thresholds = {}
    for case, spec in result.spectra.items():
        engines = spec.setdefault("engines", {})
        for engine in result.config.engines:
            now = [round(float(w), 6) for w in recomputed.get((case, engine), [])]
            kept = [dict(p, stored=label) for w, p in
                    sorted(_stored_points(stored, engine, case).items()) if w not in now]
            engines[engine] = sorted([*engines.get(engine, []), *kept],
                                     key=lambda p: float(p["omega"]))
            thresholds.setdefault(engine, {})[case] = {
                "recomputed": sorted(now), "stored": [float(p["omega"]) for p in kept]}
        if stored is not None and "jump" in result.config.stored_jobs:
            shifts = (stored["spectra"].get(case) or {}).get("jump_shifts")
            if shifts:
                spec["jump_shifts"] = {e: dict(v, stored=label) for e, v in shifts.items()
                                       if e in result.config.engines}
    parts["thresholds"] = thresholds
    if uses_stored_long_runs(stored, result.config):
        result.long_runs = [dict(r, stored=label) for r in stored.get("long_runs", [])
                            if r["backend"] in result.config.engines]
        parts["long_runs"] = "stored"
    parts["jump_shifts"] = ("stored" if stored is not None and "jump" in result.config.stored_jobs
                            else "recomputed")
    reverified = list(reverified)
    done = {r["engine"] for r in reverified}
    for engine in result.config.engines:  # a job that raised is a failed re-verification
        if (result.config.reverify and engine not in done
                and reverify_jobs([engine], result.scene)):
            reverified.append({"engine": engine, "case": REVERIFY_CASE, "omega": REVERIFY_OMEGA,
                               "passed": False, "tolerance": REVERIFY_TOL,
                               "error": "not measured (the run raised: see errors)",
                               "source": source_of(_spectrum_file(engine))})
    spectra = {r["engine"]: r["source"] for r in reverified}
    result.sources = {
        "mode": "default (recomputes the cheap checks and a sample, shows the rest from "
                "storage)",
        "stored_run": label, "stored_run_unused": reason or None, "parts": parts,
        "rules": {"thresholds": THRESHOLD_RULE,
                  "point_cpu_cap_s": POINT_CPU_CAP,
                  "reverify": f"per engine the stored {REVERIFY_CASE} point nearest "
                              f"{REVERIFY_OMEGA:g} rad/s, measured again now; tolerance "
                              f"{100 * REVERIFY_TOL:g} % (two 0.5 % search brackets)"},
        "engine_spectra": spectra, "reverified": reverified,
        "atlas": source_of(ATLAS) if ATLAS.is_file() else None,
        "atlas_note": "shown from storage and not re-verified by the default report; "
                      "make atlas remeasures it"}


def summary_line(sources: dict) -> str:
    """One line: how many threshold points were recomputed, how many stored, and
    how the re-verification went."""
    th = (sources.get("parts") or {}).get("thresholds") or {}
    now = sum(len(c["recomputed"]) for e in th.values() for c in e.values())
    kept = sum(len(c["stored"]) for e in th.values() for c in e.values())
    rows = sources.get("reverified") or []
    run = sources.get("stored_run") or {}
    origin = (f" from {run.get('file')} (run of {run.get('run_date', '?')}, commit "
              f"{str(run.get('run_commit', '?'))[:12]})" if run else "")
    return (f"thresholds: {now} points recomputed, {kept} shown{origin}; stored engine "
            f"spectra re-verified: {sum(r['passed'] for r in rows)}/{len(rows)} agree")


def annotate(verdicts: list, sources: dict) -> list:
    """Say in each threshold verdict's detail how many of its points are stored
    (and from which run), so a verdict is never read as all measured now."""
    th = (sources.get("parts") or {}).get("thresholds") or {}
    run = sources.get("stored_run") or {}
    for v in verdicts:
        case = {"threshold_pendulum": "pendulum",
                "threshold_no_pendulum": "no_pendulum"}.get(v.get("id"))
        split = (th.get(v["backend"]) or {}).get(case) if case else None
        if split and split["stored"]:
            v["detail"] += (f"; {len(split['stored'])} of "
                            f"{len(split['stored']) + len(split['recomputed'])} points "
                            f"from {run.get('file', 'the stored run')} (run "
                            f"{str(run.get('run_commit', '?'))[:12]})")
    return verdicts
