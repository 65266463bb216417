"""The run store's value format: data only, never code.

A stored value is ``MAGIC``, the length of a JSON header (8 bytes, little
endian), the header (UTF-8) and then the raw bytes of every numpy array, one
after the other.  The header is a tree of plain JSON values and tagged objects
``{"~": tag, ...}``:

``float``     a non-finite float (``"nan"``, ``"inf"``, ``"-inf"``); finite floats
              are JSON numbers (``repr``: shortest exact form, ``-0.0`` kept)
``tuple``     a tuple (lists are JSON arrays)
``dict``      a mapping, as ``[key, value]`` pairs (keys of any encodable type)
``array``     a numpy array or scalar: dtype (numeric kinds only: b i u f c),
              shape, and its place in the raw bytes
``class``     a dataclass instance of the project (module under ``analytic``,
              ``engines``, ``compare`` or ``scenes``): its module-qualified name
              and every field

Decoding runs no stored code: it parses JSON, copies bytes into arrays with a
stated numeric dtype, and fills the fields of a dataclass the project defines
(``object.__new__`` and ``object.__setattr__``: neither ``__init__`` nor
``__post_init__`` runs, so the object is the stored one field for field).
Anything else, including an old pickle, raises :class:`ForeignValue`.
Floats and arrays round-trip bit for bit (tests/compare/run/test_store.py).
"""
from __future__ import annotations

import dataclasses
import importlib
import json
import math
import struct

import numpy as np

__all__ = ["encode", "decode", "ForeignValue", "MAGIC"]

MAGIC = b"trilith-store-v1\n"
_PACKAGES = ("analytic", "engines", "compare", "scenes")
# A class is stored by its name inside the project ("compare.run.store:RunStore"),
# not by the import name it is installed under, so a store reads the same whatever
# that name is.
_ROOT = "trilith_xval."
_NUMERIC_KINDS = "biufc"
_NONFINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}


class ForeignValue(ValueError):
    """A stored value this format did not write (an old pickle, damage, another tool)."""


# ---------------------------------------------------------------------- encode
def encode(value) -> bytes:
    """``value`` as bytes (``TypeError`` for a type the format does not hold)."""
    chunks: list[bytes] = []
    offset = [0]

    def enc(v):
        if v is None or isinstance(v, (bool, str)):
            return v
        if isinstance(v, np.generic) or isinstance(v, np.ndarray):
            arr = np.asarray(v)
            if arr.dtype.kind not in _NUMERIC_KINDS:
                raise TypeError(f"store: arrays of dtype {arr.dtype} are not data")
            # order="C" (not ascontiguousarray, which makes a 0-d array 1-d)
            arr = np.asarray(arr, dtype=arr.dtype.newbyteorder("<"), order="C")
            raw = arr.tobytes()
            chunks.append(raw)
            node = {"~": "array", "dtype": arr.dtype.str, "shape": list(arr.shape),
                    "at": offset[0], "n": len(raw), "scalar": isinstance(v, np.generic)}
            offset[0] += len(raw)
            return node
        if isinstance(v, int):
            return v
        if isinstance(v, float):
            return v if math.isfinite(v) else {"~": "float", "v": repr(v)}
        if isinstance(v, tuple):
            return {"~": "tuple", "v": [enc(x) for x in v]}
        if isinstance(v, list):
            return [enc(x) for x in v]
        if isinstance(v, dict):
            return {"~": "dict", "v": [[enc(k), enc(x)] for k, x in v.items()]}
        if dataclasses.is_dataclass(v) and not isinstance(v, type):
            cls = type(v)
            module = cls.__module__.removeprefix(_ROOT)
            if module == cls.__module__ or module.split(".")[0] not in _PACKAGES:
                raise TypeError(f"store: {cls.__module__}.{cls.__qualname__} is not a "
                                "dataclass of this project")
            return {"~": "class", "cls": f"{module}:{cls.__qualname__}",
                    "v": {f.name: enc(getattr(v, f.name)) for f in dataclasses.fields(v)}}
        raise TypeError(f"store: cannot store a {type(v).__name__}")

    header = json.dumps(enc(value), separators=(",", ":"), allow_nan=False).encode()
    return b"".join([MAGIC, struct.pack("<Q", len(header)), header, *chunks])


# ---------------------------------------------------------------------- decode
def decode(blob: bytes):
    """The value :func:`encode` wrote; :class:`ForeignValue` for anything else."""
    blob = bytes(blob)
    if not blob.startswith(MAGIC):
        raise ForeignValue("not written by this store format")
    start = len(MAGIC) + 8
    if len(blob) < start:
        raise ForeignValue("truncated")
    (size,) = struct.unpack("<Q", blob[len(MAGIC):start])
    if size > len(blob) - start:
        raise ForeignValue("truncated header")
    raw = memoryview(blob)[start + size:]
    try:
        tree = json.loads(blob[start:start + size].decode())
        return _dec(tree, raw)
    except ForeignValue:
        raise
    except (ValueError, TypeError, KeyError, AttributeError, ImportError,
            RecursionError) as exc:
        raise ForeignValue(f"unreadable ({type(exc).__name__}: {exc})") from None


def _dec(node, raw):
    if isinstance(node, list):
        return [_dec(x, raw) for x in node]
    if not isinstance(node, dict):
        return node  # None, bool, int, float, str
    tag = node["~"]
    if tag == "float":
        return _NONFINITE[node["v"]]
    if tag == "tuple":
        return tuple(_dec(x, raw) for x in node["v"])
    if tag == "dict":
        return {_dec(k, raw): _dec(v, raw) for k, v in node["v"]}
    if tag == "array":
        return _array(node, raw)
    if tag == "class":
        return _instance(node, raw)
    raise ForeignValue(f"unknown tag {tag!r}")


def _array(node, raw):
    dtype = np.dtype(str(node["dtype"]))
    if dtype.kind not in _NUMERIC_KINDS:
        raise ForeignValue(f"array dtype {dtype} is not numeric")
    at, n = int(node["at"]), int(node["n"])
    shape = tuple(int(s) for s in node["shape"])
    if at < 0 or n < 0 or at + n > len(raw) or n != dtype.itemsize * math.prod(shape):
        raise ForeignValue("array bytes out of range")
    arr = np.frombuffer(raw[at:at + n], dtype=dtype).reshape(shape).copy()
    if not dtype.isnative:  # stored little-endian; a big-endian machine converts
        arr = arr.astype(dtype.newbyteorder("="))
    return arr[()] if node.get("scalar") else arr


def _instance(node, raw):
    module, _, qualname = str(node["cls"]).partition(":")
    if module.split(".")[0] not in _PACKAGES or not qualname:
        raise ForeignValue(f"class {node['cls']!r} is not of this project")
    cls = importlib.import_module(_ROOT + module)
    for part in qualname.split("."):
        cls = getattr(cls, part)
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        raise ForeignValue(f"{node['cls']!r} is not a dataclass")
    names = {f.name for f in dataclasses.fields(cls)}
    values = node["v"]
    if set(values) != names:
        raise ForeignValue(f"{node['cls']!r}: fields {sorted(values)} differ from "
                           f"{sorted(names)}")
    obj = object.__new__(cls)
    for name, v in values.items():
        object.__setattr__(obj, name, _dec(v, raw))
    return obj
