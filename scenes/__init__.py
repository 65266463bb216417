"""Named scene files (TOML) and the one loader every command uses.

A scene file has one ``[scene]`` table whose keys are :class:`analytic.Scene`
fields (``b``, ``lam``, ``mu``, ``gamma``, ``l``, ...).  ``load_scene`` accepts a
name (a file in ``scenes/data``) or a path.  Shipped scenes: ``fig5``, the
paper's Fig. 8, 9 and 11 grids (``fig8_lam5_gamma0.1``, ``fig9_lam3_b0.4``,
``fig11_mu2``, ...), ``single_block`` (Housner checks) and ``no_pendulum``;
each file's header comment says where its numbers come from and how sure
they are.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

from analytic.parameters import Scene

from .ground_motion import load_record
from .points import PAPER_OUTCOMES, POINTS, point_pulse

__all__ = ["load_scene", "load_record", "scene_names", "scene_path", "SCENE_DIR", "POINTS",
           "PAPER_OUTCOMES", "point_pulse"]

SCENE_DIR = Path(__file__).resolve().parent / "data"


def scene_names() -> tuple[str, ...]:
    """Names of the shipped scene files, sorted."""
    return tuple(sorted(p.stem for p in SCENE_DIR.glob("*.toml")))


def _resolve(name_or_path: str | Path) -> Path:
    if not isinstance(name_or_path, (str, Path)):
        raise TypeError(f"scene must be a name (str) or a path (str or Path), got "
                        f"{name_or_path!r} ({type(name_or_path).__name__})")
    candidate = Path(name_or_path)
    if candidate.suffix == ".toml" or candidate.exists() or candidate.is_symlink():
        if candidate.is_dir():
            raise ValueError(f"scene file {str(candidate)!r} is a directory, not a TOML file")
        if candidate.exists() and not candidate.is_file():
            raise ValueError(f"scene file {str(candidate)!r} is not a regular file "
                             "(a FIFO, socket or device)")
        if not candidate.is_file():
            raise ValueError(f"scene file {str(candidate)!r} does not exist")
        return candidate
    path = SCENE_DIR / f"{name_or_path}.toml"
    if not path.is_file():
        raise ValueError(f"unknown scene {str(name_or_path)!r}; allowed: "
                         f"{', '.join(scene_names())} or a path to a .toml file")
    return path


def scene_path(name_or_path: str | Path) -> Path:
    """The file a scene name (or path) refers to; ``ValueError`` if there is none."""
    return _resolve(name_or_path)


def _check_value(where: str, key: str, value) -> None:
    """Reject values that ``float()`` would silently accept but a scene file
    should not contain (booleans, strings), naming the file and the key."""
    if key == "name":
        if not isinstance(value, str):
            raise ValueError(f"{where}: key 'name' must be a string, got {value!r}")
        return
    # bool is an int subclass: float(True) == 1.0 would pass unnoticed.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}: key {key!r} must be a number, got {value!r}")
    if not math.isfinite(float(value)):
        raise ValueError(f"{where}: key {key!r} must be finite, got {value!r}")


def load_scene(name_or_path: str | Path = "fig5", **overrides) -> Scene:
    """Read a scene file and apply ``overrides`` (field name -> value).

    Raises ``TypeError`` when ``name_or_path`` is neither a str nor a Path,
    ``ValueError`` naming the file and the key for unknown keys or bad values
    in the file (wrong type, out of the range :class:`analytic.Scene` allows),
    or naming the override when the file is valid but an override is not.
    """
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a UTF-8 text file") from None
    table = data.get("scene")
    if not isinstance(table, dict) or set(data) - {"scene"}:
        raise ValueError(f"{path}: expected exactly one [scene] table, found "
                         f"{', '.join(data) or 'none'}")
    fields = set(Scene.field_names())
    allowed = ", ".join(sorted(fields))
    for key in table:
        if key not in fields:
            raise ValueError(f"{path}: unknown key {key!r}; allowed: {allowed}")
    for key in overrides:
        if key not in fields:
            raise ValueError(f"override: unknown key {key!r}; allowed: {allowed}")
    for key, value in table.items():
        _check_value(str(path), key, value)
    for key, value in overrides.items():
        _check_value(f"override {key}={value!r}", key, value)
    values = {"name": path.stem}
    values.update(table)
    try:
        scene = Scene(**values)
    except (TypeError, ValueError) as exc:
        # Scene's messages start with the field name ("b must be in ...").
        raise ValueError(f"{path}: {exc}") from None
    if not overrides:
        return scene
    try:
        return scene.replace(**overrides)
    except (TypeError, ValueError) as exc:
        # The file alone is valid: the override is to blame.
        shown = ", ".join(f"{k}={v!r}" for k, v in overrides.items())
        raise ValueError(f"override {shown}: {exc}") from None
