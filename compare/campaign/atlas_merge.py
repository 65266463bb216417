"""One atlas from parts measured separately (``trilith atlas --from A.json --from B.json``).

An engine's atlas rows depend only on that engine and the model's points, so the
engines of the atlas can be measured in separate runs (on other machines, at other
times) and joined.  Parts join only when they measured the same thing: the same
scenes, frequencies, step factors, cases, search settings and tolerance, and the
same model points (threshold, mode and validity, compared exactly: the model is
deterministic, so a difference means other model code or settings).  An engine
may appear in one part only.  Each part's provenance (command, date, commit,
CPU, load) is kept in ``parts``, in the order given.
"""
from __future__ import annotations

__all__ = ["merge_atlases", "runnable_command", "select_engines", "SAME_CONFIG"]

# The config fields that must agree for two parts to be one atlas.
SAME_CONFIG = ("scenes", "omegas", "factors", "cases", "rel_bracket", "rel_tol", "tol")
# Per part: what describes how and when it was measured.
PART_FIELDS = ("command", "provenance", "wall_s", "parent_cpu_s", "local_cpu_s", "load_average",
               "workers", "budget_s", "settings_file", "versions")


def _point_id(pt: dict) -> tuple:
    return pt["scene"], pt["case"], pt["pulse"], pt["omega"]


def _model(pt: dict) -> tuple:
    return pt["a_reference"], pt["mode"], pt["valid"], pt["model_reason"]


# Commands recorded before the provenance took its flags from the parser wrote
# the -q/-v switches as '--verbosity N', which trilith refuses; same meaning.
_VERBOSITY = {"--verbosity 0": "", "--verbosity -1": "--quiet", "--verbosity 1": "--verbose"}


def runnable_command(command: str | None) -> str | None:
    """``command`` as trilith accepts it (a legacy ``--verbosity N`` as its switch)."""
    if not command:
        return command
    for legacy, switch in _VERBOSITY.items():
        command = command.replace(f" {legacy} ", f" {switch} " if switch else " ")
        if command.endswith(f" {legacy}"):
            command = command[:-len(legacy) - 1] + (f" {switch}" if switch else "")
    return command


def _parts_of(doc: dict) -> list[dict]:
    """A document's own parts (a merged atlas keeps them), or itself as one part,
    each with a command trilith accepts."""
    parts = list(doc["parts"]) if "parts" in doc else [
        {"engines": list(doc.get("steps", {})), **{k: doc.get(k) for k in PART_FIELDS}}]
    out = []
    for part in parts:
        part = {**part, "command": runnable_command(part.get("command"))}
        if isinstance(part.get("provenance"), dict):
            prov = part["provenance"]
            part["provenance"] = {**prov, "command": runnable_command(prov.get("command"))}
        out.append(part)
    return out


def merge_atlases(docs: list[dict], names: list[str] | None = None) -> dict:
    """The atlas of every engine of ``docs`` (each an ``atlas.json`` document).

    Parameters
    ----------
    docs : list of dict
        At least two atlas documents (module docstring for what must agree).
    names : list of str, optional
        A label per document for the errors (e.g. its file name).

    Raises
    ------
    ValueError
        When a document is not an atlas, the configs or the model points differ,
        or an engine is in two documents; the message names the documents.
    """
    names = list(names) if names is not None else [f"atlas {i + 1}" for i in range(len(docs))]
    if len(docs) < 2 or len(names) != len(docs):
        raise ValueError("merge_atlases needs at least two documents (and one name each)")
    for doc, name in zip(docs, names):
        if not isinstance(doc, dict) or not {"points", "steps", "config"} <= set(doc):
            raise ValueError(f"{name}: not an atlas (needs 'points', 'steps' and 'config')")
    first, first_name = docs[0], names[0]
    seen: dict[str, str] = {}
    for doc, name in zip(docs, names):
        for key in SAME_CONFIG:
            if doc["config"].get(key) != first["config"].get(key):
                raise ValueError(f"{name} and {first_name} measured different atlases: "
                                 f"config {key!r} differs")
        if [_point_id(p) for p in doc["points"]] != [_point_id(p) for p in first["points"]]:
            raise ValueError(f"{name} and {first_name} have different points")
        for p, q in zip(doc["points"], first["points"]):
            if _model(p) != _model(q):
                raise ValueError(f"{name} and {first_name}: the model differs at "
                                 f"{p['scene']} {p['case']} Omega {p['omega']:g} "
                                 f"({_model(p)} vs {_model(q)})")
        for engine in doc["steps"]:
            if engine in seen:
                raise ValueError(f"engine {engine!r} is in both {seen[engine]} and {name}")
            seen[engine] = name
    engines = list(seen)
    # The engines' consensus where the model is invalid (a pass of its own,
    # atlas_consensus) comes from the first file that has one, whatever its place.
    agreed = next((doc for doc in docs if doc.get("consensus")), None)
    points = []
    for i, pt in enumerate(first["points"]):
        rows = {e: r for doc in docs for e, r in doc["points"][i]["engines"].items()
                if e in doc["steps"]}
        point = {k: v for k, v in pt.items() if k not in ("consensus", "own")}
        if agreed is not None:
            point.update({k: agreed["points"][i][k] for k in ("consensus", "own")
                          if k in agreed["points"][i]})
        points.append({**point, "engines": {e: rows[e] for e in engines}})
    parts = [part for doc in docs for part in _parts_of(doc)]
    loads = [x for part in parts for x in (part.get("load_average") or [])]
    from trilith_xval.engines import engine_names
    return {"schema_version": first.get("schema_version", 1), "what": first.get("what"),
            "config": {**first["config"], "engines": engines,
                       "settings": {e: s for doc in docs
                                    for e, s in doc["config"].get("settings", {}).items()}},
            "versions": {k: v for doc in docs for k, v in (doc.get("versions") or {}).items()},
            "steps": {e: r for doc in docs for e, r in doc["steps"].items()},
            "points": points,
            "cost": [c for doc in docs for c in doc.get("cost", [])],
            "not_run": {e: n for doc in docs for e, n in (doc.get("not_run") or {}).items()},
            "engines_not_run": [e for e in engine_names() if e not in engines],
            "parts": parts,
            "wall_s": sum(part.get("wall_s") or 0.0 for part in parts),
            "parent_cpu_s": sum(part.get("parent_cpu_s") or 0.0 for part in parts),
            "load_average": [min(loads), max(loads)] if loads else None,
            "workers": sorted({part.get("workers") for part in parts
                               if part.get("workers") is not None}),
            "budget_s": None,
            **({"consensus": agreed["consensus"]} if agreed is not None else {})}


def select_engines(doc: dict, engines) -> dict:
    """The atlas ``doc`` with only ``engines`` (e.g. to rejoin it with a remeasured
    part of the others): their rows, steps, cost and not-run counts; each part
    keeps its provenance and lists only the kept engines it measured."""
    keep = [e for e in doc["steps"] if e in set(engines)]
    missing = sorted(set(engines) - set(doc["steps"]))
    if missing:
        raise ValueError(f"engines not in the atlas: {', '.join(missing)}")
    parts = []
    for part in _parts_of(doc):
        mine = [e for e in part.get("engines", []) if e in keep]
        if mine:
            parts.append({**part, "engines": mine})
    return {**doc, "config": {**doc["config"], "engines": keep},
            "steps": {e: doc["steps"][e] for e in keep},
            "points": [{**pt, "engines": {e: pt["engines"][e] for e in keep}}
                       for pt in doc["points"]],
            "cost": [c for c in doc.get("cost", []) if c.get("engine") in keep],
            "not_run": {e: n for e, n in (doc.get("not_run") or {}).items() if e in keep},
            "parts": parts}
