"""Report figures kept by the data they plot.

A report figure is a function of what it draws (the arrays, numbers and labels
handed to its drawing function), of its options (size, resolution, type sizes)
and of the code that draws it (:mod:`compare.report.plots` and matplotlib's
version).  Its key is the SHA-256 of all of them; its PNG bytes are kept in the
active run store (:mod:`compare.run.runs`) as a row of kind ``'figure'``: a
``uint8`` array in the store's data format (never code), written by one SQLite
insert (whole or absent).  A report rebuilt from stored runs then draws
nothing it drew before.  With no active store (``--no-cache``) every figure is
drawn.

Arrays enter the key by dtype, shape and the SHA-256 of their bytes; everything
else by its canonical JSON (:func:`compare.run.keys.canonical_json`), floats
by ``repr``: a figure is reused only for bit-identical data.
"""
from __future__ import annotations

import base64
import functools
import hashlib
import time
from pathlib import Path

import numpy as np

__all__ = ["figure_key", "png_base64", "KIND"]

KIND = "figure"


def _fingerprint(value):
    """``value`` with every numpy array replaced by its dtype, shape and digest."""
    if isinstance(value, np.ndarray):
        arr = np.ascontiguousarray(value)
        return {"array": arr.dtype.str, "shape": list(arr.shape),
                "sha256": hashlib.sha256(arr.tobytes()).hexdigest()}
    if isinstance(value, dict):
        return {str(k): _fingerprint(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_fingerprint(v) for v in value]
    return value


@functools.lru_cache(maxsize=None)
def _drawing_code() -> str:
    """matplotlib's version and the digest of the drawing module's source."""
    from importlib.metadata import version  # not matplotlib itself: 0.2 s to import

    source = Path(__file__).with_name("plots.py").read_bytes()
    return f"matplotlib {version('matplotlib')}, plots.py {hashlib.sha256(source).hexdigest()}"


def figure_key(name: str, data: dict, options: dict) -> str:
    """The store key of figure ``name`` drawing ``data`` under ``options``."""
    from trilith_xval.compare.run.keys import digest

    return digest({"kind": KIND, "figure": name, "data": _fingerprint(data),
                   "options": options, "code": _drawing_code()})


def png_base64(name: str, data: dict, options: dict, draw) -> str:
    """The figure's PNG, base64-encoded: stored, or ``draw()`` (PNG bytes) and stored.

    ``draw`` must draw ``data`` under ``options`` and nothing else: the key
    (:func:`figure_key`) is all that tells two figures apart.
    """
    from trilith_xval.compare.run import runs

    store = runs.active()
    if store is None:
        return base64.b64encode(draw()).decode("ascii")
    key = figure_key(name, data, options)
    stored = store.get(key)
    if isinstance(stored, dict) and isinstance(stored.get("png"), np.ndarray):
        return base64.b64encode(stored["png"].tobytes()).decode("ascii")
    t0 = time.process_time()
    png = draw()
    from trilith_xval.compare.run.keys import code_version

    store.put(key, {"png": np.frombuffer(png, dtype=np.uint8)}, kind=KIND, label=name,
              cost=time.process_time() - t0, code=code_version(runs.ALL_CODE))
    return base64.b64encode(png).decode("ascii")
