"""The shape of a stored atlas (``atlas.json``), checked before anything reads it.

``trilith atlas --from FILE`` renders and joins documents that a user may have
edited, truncated or confused with another file.  :func:`check_atlas` checks
every key and type the renderers (:mod:`compare.report.atlas_page`) and the
join (:mod:`compare.campaign.atlas_merge`) use, and refuses the document in one
``ValueError`` naming the file and the first key that is wrong, so that a bad
document is refused before any output is written.
"""
from __future__ import annotations

import math

__all__ = ["check_atlas", "read_atlas", "ATLAS_SCHEMAS"]

# The atlas schema versions this version reads.
ATLAS_SCHEMAS = (1,)
_NUMBER = (int, float)


def _fail(where: str, key: str, want: str, got) -> ValueError:
    return ValueError(f"{where}: {key} must be {want}, got {type(got).__name__} "
                      f"{str(got)[:40]!r}")


def _is_number(value, *, none: bool = False) -> bool:
    if value is None:
        return none
    return isinstance(value, _NUMBER) and not isinstance(value, bool)


def _check(cond: bool, where: str, key: str, want: str, got) -> None:
    if not cond:
        raise _fail(where, key, want, got)


def _check_row(row, where: str, key: str) -> None:
    _check(isinstance(row, dict), where, key, "an object", row)
    for name in ("a_engine", "rel_error"):
        _check(_is_number(row.get(name), none=True), where, f"{key}.{name}",
               "a number or null", row.get(name))
    _check(isinstance(row.get("cause", ""), str), where, f"{key}.cause", "a string",
           row.get("cause"))


def _check_point(point, where: str, key: str, steps: dict) -> None:
    _check(isinstance(point, dict), where, key, "an object", point)
    for name in ("scene", "case", "pulse"):
        _check(isinstance(point.get(name), str), where, f"{key}.{name}", "a string",
               point.get(name))
    _check(_is_number(point.get("omega")), where, f"{key}.omega", "a number",
           point.get("omega"))
    _check(_is_number(point.get("a_reference"), none=True), where, f"{key}.a_reference",
           "a number or null", point.get("a_reference"))
    _check(isinstance(point.get("valid"), bool), where, f"{key}.valid", "true or false",
           point.get("valid"))
    engines = point.get("engines")
    _check(isinstance(engines, dict), where, f"{key}.engines", "an object", engines)
    for engine, rows in engines.items():
        _check(isinstance(rows, list) and len(rows) <= len(steps.get(engine, ())),
               where, f"{key}.engines.{engine}", "a list of at most one row per step", rows)
        for i, row in enumerate(rows):
            _check_row(row, where, f"{key}.engines.{engine}[{i}]")


def check_atlas(doc, where: str) -> dict:
    """``doc`` if it is an atlas this version can render and join.

    Parameters
    ----------
    doc : object
        A parsed JSON document.
    where : str
        How messages name it (``"--from 'a.json'"``).

    Returns
    -------
    dict
        ``doc`` itself.

    Raises
    ------
    ValueError
        Naming ``where`` and the first missing or mistyped key.
    """
    from trilith_xval.scenes.safe_read import check_schema
    check_schema(doc, where, ATLAS_SCHEMAS)
    for name in ("config", "steps", "points"):
        if name not in doc:
            raise ValueError(f"{where}: not an atlas (no {name!r}; an atlas has 'config', "
                             "'steps' and 'points')")
    config, steps, points = doc["config"], doc["steps"], doc["points"]
    _check(isinstance(config, dict), where, "config", "an object", config)
    factors = config.get("factors", [])
    _check(isinstance(factors, list) and all(_is_number(f) for f in factors), where,
           "config.factors", "a list of numbers", factors)
    _check(_is_number(config.get("tol", 0.02)), where, "config.tol", "a number",
           config.get("tol"))
    _check(isinstance(steps, dict), where, "steps", "an object", steps)
    for engine, dts in steps.items():
        _check(isinstance(dts, list) and all(_is_number(dt) and math.isfinite(dt) and dt > 0
                                             for dt in dts),
               where, f"steps.{engine}", "a list of positive numbers", dts)
    _check(isinstance(points, list), where, "points", "a list", points)
    for i, point in enumerate(points):
        _check_point(point, where, f"points[{i}]", steps)
    for name, kind in (("cost", list), ("not_run", dict), ("parts", list)):
        if name in doc:
            _check(isinstance(doc[name], kind), where, name, f"a {kind.__name__}", doc[name])
    for i, row in enumerate(doc.get("cost", [])):
        _check(isinstance(row, dict) and isinstance(row.get("engine"), str)
               and _is_number(row.get("dt")), where, f"cost[{i}]",
               "an object with 'engine' and 'dt'", row)
    for engine, left in doc.get("not_run", {}).items():
        _check(isinstance(left, dict), where, f"not_run.{engine}", "an object", left)
    return doc


def read_atlas(path: str, option: str = "--from") -> dict:
    """A stored atlas read safely (:func:`scenes.safe_read.read_json`) and
    checked (:func:`check_atlas`); ``ValueError`` naming ``option`` and the file."""
    from trilith_xval.scenes.safe_read import read_json
    where = f"{option} {str(path)!r}"
    return check_atlas(read_json(path, where), where)
