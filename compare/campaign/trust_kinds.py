"""``trilith trust`` on a scene the model does not cover (:mod:`analytic.kinds`:
drums, unequal columns, a block on a block): **engine against engine**.

There is no model of these kinds, so nothing here is agreement with a model:

1. **thresholds**: at each frequency of the design (:func:`design_omegas`) each
   engine's own first-failure amplitude (overturn or collapse), converged in the
   step, and the engines' consensus (:func:`compare.measure.kind_scan.kind_point`:
   :func:`compare.measure.consensus.consensus_at` started from the scan guess);
2. **a verdict per engine** (:func:`verdict`): trusted for thresholds when it
   converged in the step and lies within
   :data:`compare.measure.consensus.OUTLIER_TOL` of the engines' median at every
   point; where not, why (its outlier cause, the two engines apart, or no answer
   with its cause); with one engine there is no consensus (not judged);
3. **time histories, the engines against each other**: at one frequency, at
   :data:`HISTORY_FACTORS` x the consensus threshold, whether every engine agrees
   on survive or fail, and each engine's peak rotation of the first (bottom) body;
4. **restitution and the model's theta(t)**: do not exist for a kind (Eq. 19-20
   and the model's trajectory are the trilith's); the document says so
   (:data:`NO_MODEL`);
5. **ground motions** (optional): each engine's own first failing PGA of each
   record, converged in the step, and their consensus
   (:func:`compare.measure.kind_scan.kind_record`, started from a scan of the
   record's PGA); each engine judged against it as for the thresholds.

Each engine runs its threshold settings (:class:`~compare.run.spec.RunSpec`,
calibrated where the scene is in the calibration's domain: for another kind the
reference step, :func:`engines.calibration.threshold_choice`), the time histories
its defaults; its cost is CPU seconds per threshold point and per simulated second.
"""
from __future__ import annotations

import math
import os
import statistics
import time

import numpy as np

__all__ = ["trust_kind", "design_omegas", "structure_p", "verdict", "OVER_P",
           "HISTORY_FACTORS", "NO_MODEL"]

# The design in units of p (structure_p): 6 frequencies spaced geometrically over
# 2-12 p.  This is the trilith's trust band (GRID_OVER_P, 1.5-13.5 p: Fig. 5's
# 3-30 rad/s) without its ends, where a rocking body's one-sine threshold rises
# from about twice its static uplift to tens of times it; geometric spacing puts
# more points at the low end, where the threshold changes fastest relative to
# itself.  Every point's threshold lies inside the scan (SCAN_STEPS probes up to
# ~190 times the uplift bound): on the three shipped kinds with Pymunk and MuJoCo the
# highest is under 60 % of the scan's end (docs/geometry.md).
OVER_P = tuple(float(x) for x in np.geomspace(2.0, 12.0, 6))
HISTORY_FACTORS = (0.9, 1.1)  # x the consensus threshold: all survive, all fail
NO_MODEL = {
    "restitution": "no model: restitution (Eq. 20, Eq. 19 with the pendulum) is the "
                   "trilith's; the {kind} kind has none to compare with",
    "model_theta": "no model: there is no theta(t) of the {kind} kind; the engines' time "
                   "histories are compared with each other instead",
}


def structure_p(scene) -> tuple[float, float, str]:
    """``(p [rad/s], R [m], body)``: the slowest rocking frequency parameter
    ``p = sqrt(3 g / (4 R))`` of the structure's stacks, ``R`` the half-diagonal of
    a stack (a body on the ground with the bodies resting on it alone, the lintel
    excluded: it rests on two), rocking as one rigid block as it does until a joint
    opens.  ``body`` names the stack's bottom body."""
    rects = {r.name: r for r in scene.layout()}
    below: dict[str, list[str]] = {}
    for upper, lower in scene.supports():
        below.setdefault(upper, []).append(lower)
    best = None
    for name, r in rects.items():
        if below.get(name) != ["ground"]:
            continue
        top, current = r.top, name
        while True:
            nxt = [u for u, low in below.items() if low == [current]]
            if not nxt:
                break
            current = nxt[0]
            top = rects[current].top
        R = 0.5 * math.hypot(r.b, top - r.bottom)
        if best is None or R > best[1]:
            best = (math.sqrt(3.0 * scene.g / (4.0 * R)), R, name)
    return best


def design_omegas(scene, over_p=OVER_P) -> list[float]:
    """The design's frequencies [rad/s]: ``over_p`` x :func:`structure_p`."""
    p = structure_p(scene)[0]
    return [round(p * f, 4) for f in over_p]


def _where(p: dict) -> str:
    return f"record {p['record']}" if "record" in p else f"Omega {p['omega']:g} rad/s"


def verdict(points: list[dict], engine: str) -> dict:
    """Thresholds (or records' intensities) of ``engine`` engine against engine
    (module docstring, step 2)."""
    from trilith_xval.compare.measure.consensus import OUTLIER_TOL
    judged, unjudged, failing = 0, [], []
    noun = "records" if points and "record" in points[0] else "points"
    for p in points:
        miss = [n for n in p["no_answer"] if n["engine"] == engine]
        row = p["engines"].get(engine)
        if miss:
            failing.append(f"{_where(p)}: no answer ({miss[0]['cause']}: "
                           f"{miss[0]['detail']})")
        elif row is None or len(p["engines"]) < 2:
            unjudged.append(_where(p))
        elif abs(row["deviation"]) > OUTLIER_TOL:
            odd = [o for o in p["outliers"] if o["engine"] == engine]
            cause = (f"outlier, cause {odd[0]['cause']}" if odd else
                     "two engines apart, neither is the odd one out")
            failing.append(f"{_where(p)}: {100 * row['deviation']:+.2f} % "
                           f"from the median ({cause})")
            judged += 1
        else:
            judged += 1
    note = "; no other engine answered at " + ", ".join(unjudged) if unjudged else ""
    if failing:
        return {"trusted": False, "why": f"{len(failing)} of {len(points)} {noun} off: "
                                         + "; ".join(failing) + note}
    if not judged:
        return {"trusted": None, "why": "no consensus: no other engine to compare with "
                                        "(not judged)"}
    return {"trusted": True, "why": f"{judged} of {judged} {noun} converged in the step and "
                                    f"within {100 * OUTLIER_TOL:g} % of the engines' median"
                                    + note}


def trust_kind(scene, engines, *, records=(), over_p=OVER_P, options: dict | None = None,
               quiet: bool = False) -> dict:
    """The trust document of ``scene`` (another kind) for ``engines`` (module
    docstring).

    Parameters
    ----------
    scene : KindScene
        A scene of another kind than the trilith.
    engines : sequence of str
        Engines in :data:`engines.geometry.STRUCTURE_ENGINES`.
    records : sequence of ground motions
        Records whose first failing PGA is measured (default none).
    over_p : sequence of float
        The design in units of :func:`structure_p` (default :data:`OVER_P`).
    options : dict, optional
        Settings over every engine's (e.g. ``{"dt": 1e-3}``); default none.
    quiet : bool
        No progress lines on stderr.
    """
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.analytic.ida import IDASettings
    from trilith_xval.analytic._workers import cpu_seconds
    from trilith_xval.compare.campaign.trust_check import StageProgress
    from trilith_xval.compare.measure.consensus import OUTLIER_TOL, STEP_AGREE
    from trilith_xval.compare.measure.kind_scan import kind_point, kind_record
    from trilith_xval.compare.run.keys import project_version
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.engines import configure, get_backend
    from trilith_xval.engines.calibration import threshold_choice
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    if getattr(scene, "kind", "trilith") == "trilith":
        raise ValueError("trust_kind: scene is a trilith, which the model covers; use "
                         "compare.campaign.trust_check.trust_scene")
    odd = [e for e in engines if e not in STRUCTURE_ENGINES]
    if not engines or odd:
        raise ValueError(f"trust_kind: engines must be one or more of "
                         f"{', '.join(STRUCTURE_ENGINES)}, got {list(engines)!r}")
    if not over_p or not all(isinstance(f, (int, float)) and math.isfinite(f) and f > 0
                             for f in over_p):
        raise ValueError(f"trust_kind: over_p must be positive finite multiples of p, "
                         f"got {over_p!r}")
    t0, c0, load0 = time.perf_counter(), cpu_seconds(), os.getloadavg()[0]
    layer = dict(overrides=options, overrides_from="trust_kind(options=...)")
    runs = {e: RunSpec.resolve(e, scene, Still(), calibrated=True, **layer) for e in engines}
    defaults = {e: RunSpec.resolve(e, scene, **layer) for e in engines}
    p, R, body = structure_p(scene)
    omegas = design_omegas(scene, over_p)
    progress = StageProgress(2 + bool(records), quiet)
    progress.next("thresholds, engine against engine", len(omegas))
    points, n_scan = [], 0
    for i, w in enumerate(omegas):
        point, n = kind_point(runs, scene, w)
        n_scan += n
        points.append(point)
        progress.stage("thresholds, engine against engine", i + 1, len(omegas))
    progress.next("time histories, engine against engine")
    histories = _histories(defaults, scene, points)
    found, st = None, IDASettings()
    if records:
        found = []
        progress.next("ground motions, engine against engine", len(records))
        for i, rec in enumerate(records):
            point, n = kind_record(runs, scene, rec, st)
            n_scan += n
            found.append(point)
            progress.stage("ground motions, engine against engine", i + 1, len(records))
    doc = {"schema_version": 1, "what": "trust of each engine on one scene, engine against "
                                        "engine", "kind": scene.kind, "model": None,
           "scene": scene.to_dict(),
           "no_model": {k: v.format(kind=scene.kind) for k, v in NO_MODEL.items()},
           "design": {"p": p, "R": R, "stack": body, "over_p": list(over_p), "omegas": omegas,
                      "scan_runs": n_scan},
           "tolerances": {"outlier": OUTLIER_TOL, "step_agree": STEP_AGREE},
           "points": points, "histories": histories, "records": found,
           "record_tail": None if found is None else st.tail, "engines": {},
           "project": project_version()}
    for e in engines:
        choice = threshold_choice(e, scene)
        doc["engines"][e] = {
            "label": get_backend(e).label, "version": get_backend(e).version(),
            "threshold_dt": runs[e].settings.dt, "reference_dt": configure(e).dt,
            "calibrated_inside": choice.inside, "note": choice.note,
            "threshold_verdict": verdict(points, e),
            "history_verdict": _history_verdict(histories, e),
            "record_verdict": None if found is None else verdict(found, e),
            "cost": _cost(points, e)}
    doc["cost"] = {"wall_s": time.perf_counter() - t0, "cpu_s": cpu_seconds() - c0,
                   "load_average": [load0, os.getloadavg()[0]]}
    return doc


def _histories(defaults: dict, scene, points: list[dict]) -> list[dict]:
    """Each engine (at its defaults) at :data:`HISTORY_FACTORS` x the consensus
    threshold at the middle frequency with a median: verdicts and the bottom
    body's peak rotation."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.run import runs
    answered = [p for p in points if p["median"] is not None]
    if not answered:
        return []
    at = answered[len(answered) // 2]
    bottom = scene.layout()[0]
    alpha = math.atan2(bottom.b, bottom.h)
    out = []
    for f in HISTORY_FACTORS:
        pulse = Pulse(f * at["median"], at["omega"])
        rows = {}
        for e, spec in defaults.items():
            tr = runs.simulate(e, scene, pulse, spec.at(scene, pulse).settings)
            ratio = tr.diagnostics.get(f"max_angle_over_alpha.{bottom.name}")
            rows[e] = {"status": tr.verdict.status,
                       "failed": tr.verdict.status in ("overturned", "collapsed"),
                       "peak_over_alpha": ratio,
                       "peak_rad": None if ratio is None else ratio * alpha}
        fails = {r["failed"] for r in rows.values()}
        out.append({"omega": at["omega"], "factor": f, "amplitude": pulse.amplitude,
                    "body": bottom.name, "engines": rows, "agree": len(fails) == 1})
    return out


def _history_verdict(histories: list[dict], engine: str) -> dict:
    """Whether ``engine`` agrees with every other on survive or fail at each run."""
    if not histories:
        return {"agrees": None, "why": "no consensus threshold to run around"}
    if len(histories[0]["engines"]) < 2:
        return {"agrees": None, "why": "one engine: no other to compare with (not judged)"}
    apart = [h for h in histories if not h["agree"]]
    mine = "; ".join(f"{h['factor']:g}x: {h['engines'][engine]['status']}" for h in histories)
    if apart:
        return {"agrees": False, "why": "the engines differ at "
                + ", ".join(f"{h['factor']:g}x" for h in apart) + f" ({mine})"}
    return {"agrees": True, "why": f"every engine agrees ({mine})"}


def _cost(points: list[dict], engine: str) -> dict:
    """CPU s per threshold point (the engine's search over its step ladder) and per
    simulated second (over every run of those searches)."""
    owns = [p["own"][engine] for p in points if engine in p.get("own", {})]
    per = [o["cpu_s"] for o in owns if o["cpu_s"] is not None and math.isfinite(o["cpu_s"])]
    steps = [s for o in owns for s in o["steps"]
             if s["cpu_s"] is not None and s["sim_s"] and math.isfinite(s["cpu_s"])]
    sim = math.fsum(s["sim_s"] for s in steps)
    return {"threshold_point_cpu_s": statistics.median(per) if per else None,
            "cpu_per_sim_s": math.fsum(s["cpu_s"] for s in steps) / sim if sim else None,
            "points": len(per)}
