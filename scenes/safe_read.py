"""The one way this tool reads a file a user names or it stored earlier.

Every input file (scene, campaign and settings TOML, ground-motion records,
stored atlas, summary and spectrum JSON) goes through :func:`read_bytes`: a
directory, FIFO, socket or device is refused before it is opened (a FIFO would
block, ``/dev/zero`` never ends), the file is opened without blocking and
checked again on the open descriptor (it cannot be swapped in between), and at
most ``max_bytes + 1`` bytes are read, so an oversized file is refused without
being read whole.  :func:`read_json` also bounds the nesting depth before
parsing (a deep ``[[[[...`` would exhaust Python's recursion) and checks the
``schema_version`` of a stored document.  Every failure is one ``ValueError``
whose message starts with ``where`` (the option or the kind of file).
"""
from __future__ import annotations

import json
import os
import re
import stat

__all__ = ["read_bytes", "read_text", "read_json", "check_schema", "MAX_JSON_DEPTH",
           "MAX_JSON_BYTES"]

# Deepest nesting of a stored document (an atlas is 5 levels deep).
MAX_JSON_DEPTH = 64
# Largest stored JSON document read (the stored atlas is 2 MB).
MAX_JSON_BYTES = 256 * 2**20
_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.S)
_NOT_REGULAR = "is not a regular file (a directory, FIFO, socket or device)"


def read_bytes(path, where: str, max_bytes: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes`` of them.

    Parameters
    ----------
    path : str or Path
        The file.
    where : str
        How messages name it: ``"--from 'a.json'"``, ``"scene file 'x.toml'"``.
    max_bytes : int
        Larger files are refused (only ``max_bytes + 1`` bytes are ever read).

    Returns
    -------
    bytes

    Raises
    ------
    ValueError
        Missing, not a regular file, unreadable or too large; the message starts
        with ``where``.
    """
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # before open: a FIFO would block
            raise ValueError(f"{where} {_NOT_REGULAR}")
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped after the stat
                raise ValueError(f"{where} {_NOT_REGULAR}")
            with os.fdopen(fd, "rb", closefd=False) as fh:
                data = fh.read(max_bytes + 1)
        finally:
            os.close(fd)
    except FileNotFoundError:
        raise ValueError(f"{where} does not exist") from None
    except IsADirectoryError:
        raise ValueError(f"{where} {_NOT_REGULAR}") from None
    except OSError as exc:
        raise ValueError(f"{where} cannot be read ({exc.strerror or exc})") from None
    if len(data) > max_bytes:
        raise ValueError(f"{where} is larger than {max_bytes} bytes")
    return data


def read_text(path, where: str, max_bytes: int) -> str:
    """:func:`read_bytes` decoded as UTF-8 (a byte-order mark is not data)."""
    try:
        return read_bytes(path, where, max_bytes).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{where} is not a UTF-8 text file") from None


def _depth(data: bytes) -> int:
    """Deepest nesting of ``[`` and ``{`` outside strings."""
    import numpy as np
    codes = np.frombuffer(_STRING.sub(b'""', data), dtype=np.uint8)
    steps = ((codes == 91) | (codes == 123)).astype(np.int64) \
        - ((codes == 93) | (codes == 125)).astype(np.int64)
    return int(np.cumsum(steps).max()) if steps.size else 0


def check_schema(doc, where: str, versions) -> None:
    """``ValueError`` unless ``doc`` is an object whose ``schema_version`` is one of
    ``versions`` (a document without one is version 1)."""
    if not isinstance(doc, dict):
        raise ValueError(f"{where}: not a JSON object but a {type(doc).__name__}")
    version = doc.get("schema_version", 1)
    if isinstance(version, bool) or version not in tuple(versions):
        raise ValueError(f"{where}: schema_version {version!r} is not one this version "
                         f"reads ({', '.join(str(v) for v in versions)})")


def read_json(path, where: str, *, max_bytes: int = MAX_JSON_BYTES,
              max_depth: int = MAX_JSON_DEPTH, schema_versions=None):
    """A JSON document read by :func:`read_bytes`, nesting bounded by ``max_depth``,
    and, with ``schema_versions``, its ``schema_version`` checked
    (:func:`check_schema`).

    Raises
    ------
    ValueError
        Any of the above, or not UTF-8 JSON; the message starts with ``where``.
    """
    data = read_bytes(path, where, max_bytes)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{where} is not a UTF-8 text file") from None
    if _depth(data) > max_depth:
        raise ValueError(f"{where}: JSON nested deeper than {max_depth} levels")
    try:
        doc = json.loads(text)
    except RecursionError:
        raise ValueError(f"{where}: JSON nested too deep") from None
    except ValueError as exc:
        raise ValueError(f"{where} is not valid JSON ({exc})") from None
    if schema_versions is not None:
        check_schema(doc, where, schema_versions)
    return doc

