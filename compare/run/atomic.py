"""Atomic outputs: a file or a report directory appears whole or not at all.

Every writer here writes to a temporary name in the destination's own directory
(same filesystem, so the final ``os.replace`` is an atomic rename) and renames
it over the destination only once complete; a killed process leaves at most a
stray ``.<name>.tmp-*`` file, never a half-written output.

A report directory is built in a temporary sibling ``.<name>.tmp-*`` and
swapped in whole: the old directory is renamed away to ``.<name>.old-*``, the
new one renamed in, the old one deleted.  Between those two renames (two
syscalls, microseconds) ``<out>`` does not exist; a reader never sees old and
new files mixed.  A kill in that window leaves the complete old report in
``.<name>.old-*`` and the complete new one in ``.<name>.tmp-*``.

:func:`output_lock` takes ``fcntl.flock`` on ``<out>.lock``: a second process
writing the same output fails at once with a one-line ``ValueError`` instead of
racing.  The kernel drops the lock when its holder dies, even by SIGKILL.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

__all__ = ["write_text", "write_bytes", "savefig", "savetxt", "atomic_path",
           "output_lock", "report_dir"]


@contextlib.contextmanager
def atomic_path(path, suffix: str = ""):
    """Yield a temporary path next to ``path``; rename it to ``path`` on success.

    ``suffix`` keeps the extension for writers that look at it (matplotlib,
    Pillow): ``with atomic_path(p, ".png") as tmp: fig.savefig(tmp)``.
    """
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.tmp-", suffix=suffix, dir=parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; outputs are ordinary files
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_bytes(path, data: bytes) -> None:
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)


def write_text(path, text: str, encoding: str = "utf-8") -> None:
    write_bytes(path, text.encode(encoding))


def savefig(fig, path, **kwargs) -> None:
    """``fig.savefig(path, **kwargs)``, atomically (the format from ``path``'s suffix)."""
    path = Path(path)
    with atomic_path(path, path.suffix) as tmp:
        fig.savefig(tmp, **kwargs)


def savetxt(path, data, **kwargs) -> None:
    """``numpy.savetxt``, atomically."""
    import numpy as np
    with atomic_path(path) as tmp:
        np.savetxt(tmp, data, **kwargs)


@contextlib.contextmanager
def output_lock(path):
    """Hold ``<path>.lock`` (flock) for the block; ``ValueError`` if another
    process holds it.  The lock file stays (deleting it would race a waiter)."""
    import fcntl

    path = Path(path)
    lock = path.with_name(path.name + ".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    fh = open(lock, "a")
    try:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ValueError(f"--out {str(path)!r} is being written by another process "
                             f"(lock {str(lock)!r} held); wait for it or choose another "
                             "--out") from None
        yield lock
    finally:
        fh.close()


@contextlib.contextmanager
def report_dir(out, lock: bool = True):
    """Yield a fresh temporary directory; on success it replaces ``out`` whole.

    Takes :func:`output_lock` on ``out`` for the whole build (``lock=False``: the
    caller holds it already, e.g. for a long computation before).  ``ValueError``
    if ``out`` is an existing file.  On an exception the temporary directory is
    removed and ``out`` is left as it was.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a directory, got the file {str(out)!r}")
    parent = out.parent if str(out.parent) else Path(".")
    parent.mkdir(parents=True, exist_ok=True)
    with output_lock(out) if lock else contextlib.nullcontext():
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=parent))
        try:
            yield tmp
            os.chmod(tmp, 0o777 & ~_umask())
            old = None
            if out.exists():
                old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=parent))
                os.replace(out, old)  # an empty directory is replaced atomically
            os.replace(tmp, out)  # the window: between these two renames
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
