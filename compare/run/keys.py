"""Store keys: the SHA-256 of a canonical JSON of everything that determines a result.

A backend run's key (:func:`run_key`) holds the backend name and engine version,
the scene's fields, the excitation (type and fields, sampled records sample by
sample), the backend settings, the project's version and a digest of the
model/engine source files (so an edited checkout never reuses results of older
code).  The scene's ``name`` is a label and is left out: the same trilith under
two names is one run.  :func:`code_version` names the code a key came from
(``trilith cache info|prune``).
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
from pathlib import Path

__all__ = ["backend_version", "run_key", "canonical_json", "digest", "project_version",
           "source_digest", "code_version", "run_code", "scene_dict", "settings_dict", "excitation_dict",
           "CODE_SETS"]

# The sets of source packages a key can depend on: the analytic backends
# (analytic/), engine runs and model-side results (+ engines/), results computed
# by compare/ itself (+ compare/).
CODE_SETS = (("analytic",), ("analytic", "engines"), ("analytic", "engines", "compare"))
_ROOT = Path(__file__).resolve().parents[2]

def _plain(value):
    """The canonical form hashed into a key: like :func:`compare.run.jsonable.plain`,
    but a dataclass keeps its type's name and NaN/inf are strings, so two different
    inputs never hash alike."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"__type__": type(value).__name__,
                **{f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _plain(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)  # 'nan', 'inf': JSON has no such numbers
    return value


def canonical_json(obj) -> str:
    """Sorted keys, no spaces, floats by ``repr`` (shortest exact form)."""
    return json.dumps(_plain(obj), sort_keys=True, separators=(",", ":"), allow_nan=False)


def digest(obj) -> str:
    """SHA-256 (hex) of :func:`canonical_json`."""
    return hashlib.sha256(canonical_json(obj).encode()).hexdigest()


@functools.lru_cache(maxsize=None)
def project_version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("trilith-xval")
    except PackageNotFoundError:  # a bare source checkout
        return "unknown"


@functools.lru_cache(maxsize=None)
def source_digest(packages: tuple[str, ...]) -> str:
    """SHA-256 over the ``*.py`` files of ``packages`` and their subpackages (paths
    and bytes): ~1 ms once per process.  The project version alone would hand stale
    results to an edited checkout."""
    h = hashlib.sha256()
    for pkg in packages:
        for path in sorted((_ROOT / pkg).rglob("*.py")):
            h.update(f"{path.relative_to(_ROOT).as_posix()}\0".encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def _code_packages(backend: str) -> tuple[str, ...]:
    # The analytic backends depend on analytic/ only; engines also read analytic/.
    return ("analytic",) if backend.startswith("analytic") else ("analytic", "engines")


@functools.lru_cache(maxsize=None)
@functools.lru_cache(maxsize=None)
def backend_version(name: str) -> str:
    """The version string of registered backend ``name`` (its ``version()``), the
    one every key, result and report carries."""
    from trilith_xval.engines import get_backend
    return str(get_backend(name).version())


def settings_dict(settings) -> dict:
    """A backend Settings as a plain dict (its ``describe()`` when it has one)."""
    if hasattr(settings, "describe"):
        return _plain(settings.describe())
    return _plain(settings)


def excitation_dict(excitation) -> dict:
    """The excitation's ``key_fields()``: its class name and every field (a
    SampledRecord's samples included, not its summary)."""
    from trilith_xval.analytic.excitation import check_excitation
    return _plain(check_excitation(excitation).key_fields())


def scene_dict(scene) -> dict:
    """Every Scene field but ``name`` (a label: it does not change a run); a scene of
    another kind (:mod:`analytic.kinds`) adds its ``kind`` (a Scene's dict, hence
    every stored key, stays as it was)."""
    out = dataclasses.asdict(scene)
    out.pop("name", None)
    kind = getattr(scene, "kind", None)
    if kind is not None:
        out["kind"] = kind
    return out


@functools.lru_cache(maxsize=None)
def code_version(packages: tuple[str, ...]) -> str:
    """``'<project version>+<source digest, 12 hex>'``: the code a stored row came from."""
    return f"{project_version()}+{source_digest(tuple(packages))[:12]}"


def run_code(backend: str) -> str:
    """:func:`code_version` of a backend run's key."""
    return code_version(_code_packages(backend))


def run_key(backend: str, scene, excitation, settings) -> str:
    """The store key of one backend run (``settings`` already resolved)."""
    return digest({"kind": "run", "backend": backend, "engine": backend_version(backend),
                   "scene": scene_dict(scene), "excitation": excitation_dict(excitation),
                   "settings": settings_dict(settings), "project": project_version(),
                   "code": source_digest(_code_packages(backend))})
