"""Bit-for-bit comparison of results (a stored run against a fresh one)."""
from __future__ import annotations

import dataclasses
import struct

import numpy as np


def same(x, y) -> bool:
    """Deep equality, bit for bit: arrays by bytes, floats by their 8 bytes (so NaN
    equals NaN and -0.0 differs from 0.0), containers and dataclasses field by field."""
    if type(x) is not type(y):
        return False
    if isinstance(x, np.ndarray):
        return x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()
    if isinstance(x, float):
        return struct.pack("<d", x) == struct.pack("<d", y)
    if dataclasses.is_dataclass(x):
        return all(same(getattr(x, f.name), getattr(y, f.name)) for f in dataclasses.fields(x))
    if isinstance(x, dict):
        return x.keys() == y.keys() and all(same(x[k], y[k]) for k in x)
    if isinstance(x, (list, tuple)):
        return len(x) == len(y) and all(same(a, b) for a, b in zip(x, y))
    return x == y


# Timings of a run (its cost, not its result): the only things a new run changes.
TIMINGS = ("wall_time", "cpu_time")


def assert_same_trajectory(a, b, timings: bool = True) -> None:
    """Every field bit-identical; ``timings=False`` skips the wall times (the field
    and the diagnostics entry), which differ between two computations."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if not timings and f.name in TIMINGS:
            continue
        if not timings and f.name == "diagnostics":
            x, y = ({k: v for k, v in d.items() if k not in TIMINGS} for d in (x, y))
        assert same(x, y), f.name
