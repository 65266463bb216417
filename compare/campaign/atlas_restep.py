"""A stored atlas brought under the step rule without remeasuring what the rule
cannot change (``trilith atlas --restep FROM.json --engine E``).

The step rule (:mod:`compare.measure.step_rule`) acts only on a point that
*fails* at a step coarser than the engine's reference step: it remeasures that
point at finer steps before any cause is named.  A point that agrees at every
step it reached, or that fails only at the reference step itself, is measured
exactly as before.  So an atlas part measured before the rule existed is brought
under it by remeasuring, whole and at this commit, only the points of
:func:`rule_points`; every other row is carried from the stored part with its
provenance.  DART's and Drake's parts cost 10 and 29 CPU hours whole
(docs/atlas.md); their points the rule can change are a fraction of that.

The remeasured points replace the engine's rows of those points; the model's
points must be the stored ones exactly (the model is deterministic: a difference
means other model code, and the restep is refused).  The atlas gains a
``resteps`` entry per run: the engine, the points, the command, its provenance
and cost, and how many causes changed per step (:func:`cause_changes`).
"""
from __future__ import annotations

from collections import Counter

__all__ = ["rule_points", "restep_config", "merge_restep", "cause_changes"]


def _point_id(pt: dict) -> tuple:
    return pt["scene"], pt["case"], pt["pulse"], float(pt["omega"])


def rule_points(doc: dict, engine: str) -> list[tuple]:
    """``(scene, case, pulse, omega)`` of the points of ``doc`` where ``engine`` has
    a row that is not ``agrees`` at a step coarser than its reference step: the
    points on which the step rule can act.

    Parameters
    ----------
    doc : dict
        A stored atlas (``atlas.json``) that holds ``engine``.
    engine : str
        A registered engine.
    """
    from trilith_xval.engines.calibration import reference_dt
    from trilith_xval.compare.measure.step_rule import finer_steps
    if engine not in doc.get("steps", {}):
        raise ValueError(f"--engine: {engine!r} is not in the stored atlas (it holds "
                         f"{', '.join(doc.get('steps', {})) or 'no engine'})")
    ref = reference_dt(engine)
    return [_point_id(pt) for pt in doc["points"]
            if any(r.get("cause") != "agrees" and finer_steps(r["dt"], ref)
                   for r in pt["engines"].get(engine, []))]


def restep_config(doc: dict, engine: str, points: list[tuple]):
    """The :class:`~compare.campaign.atlas.AtlasConfig` that remeasures ``points``
    of ``doc`` for ``engine``: the stored grid, factors, cases, tolerances and the
    engine's stored settings, restricted to ``points``."""
    from trilith_xval.compare.campaign.atlas import AtlasConfig
    c = doc["config"]
    settings = c.get("settings", {}).get(engine)
    return AtlasConfig(engines=(engine,), scenes=tuple(tuple(s) for s in c["scenes"]),
                       omegas=tuple(float(w) for w in c["omegas"]),
                       factors=tuple(float(f) for f in c["factors"]),
                       cases=tuple(c["cases"]), rel_bracket=c["rel_bracket"],
                       rel_tol=c["rel_tol"], tol=c["tol"],
                       settings=((engine, tuple(sorted(settings.items()))),) if settings else (),
                       only=tuple(points))


def cause_changes(before: dict, after: dict, engine: str) -> dict:
    """Per step [s, as text]: ``{"rows_before", "rows_after", "changed",
    "to_discretisation", "causes_before", "causes_after"}`` over the points of
    ``after`` (the remeasured part), against the same points of ``before``."""
    old = {_point_id(pt): {r["dt"]: r["cause"] for r in pt["engines"].get(engine, [])}
           for pt in before["points"]}
    out: dict = {}
    for pt in after["points"]:
        was = old.get(_point_id(pt), {})
        now = {r["dt"]: r["cause"] for r in pt["engines"].get(engine, [])}
        for dt in sorted(set(was) | set(now)):
            s = out.setdefault(repr(dt), {"rows_before": 0, "rows_after": 0, "changed": 0,
                                          "to_discretisation": 0, "causes_before": Counter(),
                                          "causes_after": Counter()})
            if dt in was:
                s["rows_before"] += 1
                s["causes_before"][was[dt]] += 1
            if dt in now:
                s["rows_after"] += 1
                s["causes_after"][now[dt]] += 1
            if was.get(dt) != now.get(dt):
                s["changed"] += 1
                s["to_discretisation"] += now.get(dt) == "discretisation"
    return {dt: {**s, "causes_before": dict(s["causes_before"]),
                 "causes_after": dict(s["causes_after"])} for dt, s in out.items()}


def merge_restep(doc: dict, part: dict, engine: str) -> dict:
    """``doc`` with ``engine``'s rows of the points of ``part`` replaced by
    ``part``'s, a ``resteps`` entry added and the cost table recomputed.

    Raises
    ------
    ValueError
        When ``part`` measured another grid or steps, or a model point differs.
    """
    from trilith_xval.compare.campaign.atlas import cost_table
    from trilith_xval.compare.campaign.atlas_merge import SAME_CONFIG
    for key in SAME_CONFIG:
        if doc["config"][key] != part["config"][key]:
            raise ValueError(f"restep: the remeasured part's {key} differs from the stored "
                             f"atlas's ({part['config'][key]!r} vs {doc['config'][key]!r})")
    if [float(s) for s in part["steps"][engine]] != [float(s) for s in doc["steps"][engine]]:
        raise ValueError(f"restep: {engine}'s steps are now {part['steps'][engine]} s, the "
                         f"stored atlas has {doc['steps'][engine]} s (its calibration changed: "
                         "remeasure the whole part)")
    index = {_point_id(pt): i for i, pt in enumerate(doc["points"])}
    points = [dict(pt, engines=dict(pt["engines"])) for pt in doc["points"]]
    for pt in part["points"]:
        i = index.get(_point_id(pt))
        if i is None:
            raise ValueError(f"restep: point {_point_id(pt)} is not in the stored atlas")
        for field in ("a_reference", "mode", "valid", "model_reason"):
            if points[i][field] != pt[field]:
                raise ValueError(f"restep: the model's {field} at {_point_id(pt)} is "
                                 f"{pt[field]!r} now, {points[i][field]!r} stored (other "
                                 "model code or settings)")
        points[i]["engines"][engine] = pt["engines"][engine]
    out = dict(doc, points=points)
    out["cost"] = cost_table(points, list(doc["steps"]))
    entry = {"engine": engine, "points": len(part["points"]),
             "changes": cause_changes(doc, part, engine)}
    for key in ("command", "provenance", "wall_s", "parent_cpu_s", "local_cpu_s",
                "load_average", "workers", "versions"):
        entry[key] = part.get(key)
    out["resteps"] = [*doc.get("resteps", []), entry]
    return out
