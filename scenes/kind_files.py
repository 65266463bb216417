"""The ``kind`` key of a scene file: scenes beyond the parametric trilith.

A scene file with ``kind = "drums"``, ``"unequal"`` or ``"block_on_block"`` in
its ``[scene]`` table describes a scene of :mod:`analytic.kinds`; ``kind =
"trilith"`` (or no kind) is the parametric :class:`~analytic.parameters.Scene`.
A column of **one** drum is the parametric trilith itself: the file loads as the
Scene of the same numbers (``h`` = the drum's height), which the model covers.
Every check runs here, before any work; errors are one line naming the file
and the field (``docs/geometry.md``).
"""
from __future__ import annotations

from pathlib import Path

from trilith_xval.analytic.kinds import KINDS

__all__ = ["load_kind", "KIND_NAMES", "LIST_KEYS"]

KIND_NAMES = ("trilith", *KINDS)
# Keys whose values are lists of lengths [m] (the drums, bottom to top).
LIST_KEYS = ("heights", "widths")


def _check_list(where: str, key: str, value, check) -> list:
    # An empty list passes: the kind names the count it needs (e.g. 2 to 4 drums).
    if not isinstance(value, list):
        raise ValueError(f"{where}: {key} must be a list of lengths [m], got {value!r}")
    for item in value:
        check(where, key, item)
    return value


def load_kind(path: Path, table: dict, overrides: dict, check_value):
    """The scene of ``table`` (a ``[scene]`` table with a ``kind`` other than
    ``'trilith'``) with ``overrides`` applied; ``check_value(where, key,
    value)`` is the loader's number check.  A one-drum ``drums`` table returns
    the parametric Scene (see the module docstring)."""
    where = str(path)
    kind = table["kind"]
    if kind not in KINDS:
        raise ValueError(f"{where}: kind must be one of {', '.join(KIND_NAMES)}, got {kind!r}")
    cls = KINDS[kind]
    values = {k: v for k, v in table.items() if k != "kind"}
    allowed = set(cls.field_names())
    for key, value in values.items():
        if key not in allowed:
            raise ValueError(f"{where}: unknown key {key!r} for kind {kind!r}; allowed: "
                             f"{', '.join(sorted(allowed))}")
        if key in LIST_KEYS:
            values[key] = tuple(_check_list(where, key, value, check_value))
        else:
            check_value(where, key, value)
    for key, value in overrides.items():
        if key not in allowed or key in LIST_KEYS:
            raise ValueError(f"override: unknown key {key!r} for kind {kind!r}; allowed: "
                             f"{', '.join(sorted(allowed - set(LIST_KEYS)))}")
        check_value(f"override {key}={value!r}", key, value)
    values.setdefault("name", path.stem)
    if kind == "drums" and len(values.get("heights", ())) == 1:
        return _one_drum(where, values, overrides)
    return build_scene(cls, values, overrides, f"{where}: ")


def _one_drum(where: str, values: dict, overrides: dict):
    """One drum per column: the parametric Scene with ``h`` = the drum's height
    (as a trilith file giving ``h``), so the model covers it bit for bit."""
    from trilith_xval.analytic.parameters import Scene
    values = dict(values)
    (h,) = values.pop("heights")
    widths = values.pop("widths", None)
    b = values.get("b", Scene.b)
    if widths is not None and tuple(widths) != (b,):
        raise ValueError(f"{where}: widths[0] is the bottom drum's width b = {b:g} m, got "
                         f"{widths[0]!r}")
    if b > 0:  # otherwise Scene refuses b before it reads lam
        values["lam"] = h / b
    try:
        scene = Scene(**values)
        return scene.replace(**overrides) if overrides else scene
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: one drum is the trilith (h = {h:g} m): {exc}") from None


def build_scene(cls, values: dict, overrides: dict, where: str):
    """``cls(**values)`` with ``overrides`` applied; ``ValueError`` prefixed by
    ``where`` when the file's values are refused (their messages start with the
    field name, "b must be in ..."), or naming the override when the file alone is
    valid and the override is to blame."""
    try:
        scene = cls(**values)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}{exc}") from None
    if not overrides:
        return scene
    try:
        return scene.replace(**overrides)
    except (TypeError, ValueError) as exc:
        shown = ", ".join(f"{k}={v!r}" for k, v in overrides.items())
        raise ValueError(f"override {shown}: {exc}") from None
