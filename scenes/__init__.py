"""Named scene files (TOML) and the one loader every command uses.

A scene file has one ``[scene]`` table whose keys are :class:`analytic.Scene`
fields (``b``, ``lam``, ``mu``, ``gamma``, ``l``, ...); the column height ``h``
may be given instead of ``lam`` (``lam = h/b``), not beside it.  ``load_scene`` accepts a
name (a file in ``scenes/data``) or a path.  Shipped scenes: ``fig5``, the
paper's Fig. 8, 9 and 11 grids (``fig8_lam5_gamma0.1``, ``fig9_lam3_b0.4``,
``fig11_mu2``, ...), ``single_block`` (Housner checks), the rocking block family
``block_lam1.5``, ``block_lam2``, ``block_lam3``, ``block_lam5``, ``block_lam8``,
``block_lam10`` (mu = gamma = 0, b = 0.6 m) and ``no_pendulum``;
each file's header comment says where its numbers come from and how sure
they are.  A ``kind`` key (``"drums"``, ``"unequal"``, ``"block_on_block"``)
describes a scene beyond the parametric trilith (:mod:`scenes.kind_files`,
``docs/geometry.md``); the shipped examples are ``drums``, ``unequal`` and
``block_on_block``.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

from trilith_xval.analytic.parameters import Scene

from .ground_motion import load_record
from .points import PAPER_OUTCOMES, POINTS, point_pulse

__all__ = ["load_scene", "load_record", "read_toml", "scene_names", "scene_path", "SCENE_DIR",
           "POINTS", "PAPER_OUTCOMES", "point_pulse"]

SCENE_DIR = Path(__file__).resolve().parent / "data"
# Largest input file read: a scene or campaign file is a few hundred bytes; a
# megabyte is a mistake (or a device), refused before parsing.
MAX_FILE_BYTES = 1 << 20


def read_toml(path: Path, what: str) -> dict:
    """The TOML table of the regular file ``path``; ``ValueError`` naming the file
    (``what``: 'scene file', 'campaign file') when it is not a regular file, cannot
    be read, is over :data:`MAX_FILE_BYTES`, is not UTF-8 or not TOML (nesting too
    deep included)."""
    from trilith_xval.scenes.safe_read import read_bytes
    where = f"{what} {str(path)!r}"
    data = read_bytes(path, where, MAX_FILE_BYTES)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{where} is not a UTF-8 text file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where} is not valid TOML ({exc})") from None
    except RecursionError:
        raise ValueError(f"{where} is not valid TOML (nesting too deep)") from None
    except ValueError as exc:  # e.g. an integer over Python's digit limit
        raise ValueError(f"{where} is not valid TOML ({exc})") from None


def scene_names() -> tuple[str, ...]:
    """Names of the shipped scene files, sorted."""
    return tuple(sorted(p.stem for p in SCENE_DIR.glob("*.toml")))


def _find(name_or_path: str | Path) -> Path:
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


def _resolve(name_or_path: str | Path) -> Path:
    try:
        return _find(name_or_path)
    except OSError as exc:  # a name too long for the filesystem, a loop of links
        raise ValueError(f"scene {_short(str(name_or_path))}: {exc.strerror or exc}") from None


def _check_value(where: str, key: str, value) -> None:
    """Reject values that ``float()`` would silently accept but a scene file
    should not contain (booleans, strings), naming the file and the key."""
    if key == "name":
        if not isinstance(value, str):
            raise ValueError(f"{where}: key 'name' must be a string, got {value!r}")
        return
    # bool is an int subclass: float(True) == 1.0 would pass unnoticed.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}: key {key!r} must be a number, got {_short(value)}")
    if isinstance(value, int) and abs(value) > 1e300:  # float() would overflow
        raise ValueError(f"{where}: key {key!r} must be a finite number, got an integer "
                         f"of {len(str(abs(value)))} digits")
    if not math.isfinite(float(value)):
        raise ValueError(f"{where}: key {key!r} must be finite, got {value!r}")


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}... ({type(value).__name__})"


def load_scene(name_or_path: str | Path = "fig5", **overrides):
    """Read a scene file and apply ``overrides`` (field name -> value).

    Returns a :class:`~analytic.parameters.Scene`, or a scene of
    :mod:`analytic.kinds` when the file has a ``kind`` other than ``'trilith'``.

    Raises ``TypeError`` when ``name_or_path`` is neither a str nor a Path,
    ``ValueError`` naming the file and the key for unknown keys or bad values
    in the file (wrong type, out of the range :class:`analytic.Scene` allows),
    or naming the override when the file is valid but an override is not.
    """
    path = _resolve(name_or_path)
    data = read_toml(path, "scene file")
    table = data.get("scene")
    if not isinstance(table, dict) or set(data) - {"scene"}:
        raise ValueError(f"{path}: expected exactly one [scene] table, found "
                         f"{_short(', '.join(data)) or 'none'}")
    if table.get("kind", "trilith") != "trilith":
        from .kind_files import load_kind
        return load_kind(path, table, overrides, _check_value)
    table = {k: v for k, v in table.items() if k != "kind"}
    fields = set(Scene.field_names())
    allowed = ", ".join(sorted(fields | {"h"}))
    for key in table:
        if key not in fields | {"h"}:
            raise ValueError(f"{path}: unknown key {_short(key)}; allowed: {allowed}")
    if "h" in table and "lam" in table:
        raise ValueError(f"{path}: give either lam or h (h = lam b), not both")
    for key in overrides:
        if key not in fields:
            raise ValueError(f"override: unknown key {key!r}; allowed: {allowed}")
    for key, value in table.items():
        _check_value(str(path), key, value)
    for key, value in overrides.items():
        _check_value(f"override {key}={value!r}", key, value)
    values = {"name": path.stem}
    values.update(table)
    given_h = ""
    if "h" in values:
        # A file may state the height, as drawings do; the model's parameter is lam.
        h = values.pop("h")
        b = values.get("b", Scene.b)
        if b > 0:  # otherwise Scene refuses b before it reads lam
            values["lam"] = h / b
            given_h = f"h = {h:g} m and b = {b:g} m give lam = h/b = {h / b:g}; "
    from .kind_files import build_scene
    return build_scene(Scene, values, overrides, f"{path}: {given_h}")
