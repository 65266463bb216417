"""The one conversion of results to strict JSON (every ``--json``, summary and bench file).

:func:`plain` turns dataclasses, objects with ``describe()`` (settings, criteria),
numpy scalars and arrays, tuples and mappings into plain JSON values, and
non-finite floats into ``None`` (strict JSON has no NaN).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

__all__ = ["plain"]


def plain(value):
    """A JSON-ready copy of ``value``.

    Examples
    --------
    >>> import numpy as np
    >>> plain({"a": (1.0, float("nan")), "b": np.float64(2.5), "c": np.arange(2)})
    {'a': [1.0, None], 'b': 2.5, 'c': [0, 1]}
    """
    if isinstance(value, np.generic):  # before float: np.float64 is a float subclass
        return plain(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, (str, int, bool)) or value is None:
        return value
    if isinstance(value, np.ndarray):
        return [plain(v) for v in value.tolist()]
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "describe"):
        return plain(value.describe())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return plain(dataclasses.asdict(value))
    if hasattr(value, "to_dict"):
        return plain(value.to_dict())
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
