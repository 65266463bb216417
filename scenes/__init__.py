"""Named scene files (TOML) and the one loader every command uses.

A scene file has one ``[scene]`` table whose keys are :class:`analytic.Scene`
fields (``b``, ``lam``, ``mu``, ``gamma``, ``l``, ...).  ``load_scene`` accepts a
name (a file in ``scenes/data``) or a path.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

from analytic.parameters import Scene

__all__ = ["load_scene", "scene_names", "SCENE_DIR"]

SCENE_DIR = Path(__file__).resolve().parent / "data"


def scene_names() -> tuple[str, ...]:
    return tuple(sorted(p.stem for p in SCENE_DIR.glob("*.toml")))


def _resolve(name_or_path: str | Path) -> Path:
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.exists():
        if not candidate.is_file():
            raise ValueError(f"scene file {str(candidate)!r} does not exist")
        return candidate
    path = SCENE_DIR / f"{name_or_path}.toml"
    if not path.is_file():
        raise ValueError(f"unknown scene {str(name_or_path)!r}; allowed: "
                         f"{', '.join(scene_names())} or a path to a .toml file")
    return path


def load_scene(name_or_path: str | Path = "fig5", **overrides) -> Scene:
    """Read a scene file and apply ``overrides`` (field name -> value).

    Raises ``ValueError`` naming the file and the key for unknown keys or bad values.
    """
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    table = data.get("scene")
    if not isinstance(table, dict) or set(data) - {"scene"}:
        raise ValueError(f"{path}: expected exactly one [scene] table, found "
                         f"{', '.join(data) or 'none'}")
    fields = set(Scene.field_names())
    for key in list(table) + list(overrides):
        if key not in fields:
            raise ValueError(f"{path}: unknown key {key!r}; allowed: {', '.join(sorted(fields))}")
    values = {"name": path.stem}
    values.update(table)
    values.update(overrides)
    for key, value in values.items():
        if key != "name" and isinstance(value, str):
            raise ValueError(f"{path}: key {key!r} must be a number, got {value!r}")
    try:
        return Scene(**values)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from None
