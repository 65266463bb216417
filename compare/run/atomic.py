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

Only a directory this tool wrote is ever replaced: each one holds the marker
file :data:`MARKER`.  An existing ``<out>`` that is neither empty nor marked
(a user's folder) is refused with one line before any work
(:func:`check_replaceable`), and checked again just before the swap.  The next
build of ``<out>`` removes the ``.<name>.tmp-*`` and ``.<name>.old-*`` that
killed builds left (marked, or empty; never anything else).

:func:`output_lock` takes ``fcntl.flock`` on ``<out>.lock``: a second process
writing the same output fails at once with a one-line ``ValueError`` instead of
racing.  The kernel drops the lock when its holder dies, even by SIGKILL.  The
lock file holds :data:`LOCK_TEXT` and is removed by its holder when it is done
(a waiter that locked the removed file sees it is gone and takes the new one);
a file of that name the tool did not write is locked but never removed.

A rewritten file keeps the mode of the file it replaces (a 0640 output stays
0640); a new one gets the ordinary 0666 less the umask.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from pathlib import Path

__all__ = ["write_text", "write_bytes", "savefig", "savetxt", "atomic_path",
           "output_lock", "report_dir", "check_replaceable", "check_name_length", "MARKER",
           "MANIFEST", "check_into", "record_into"]

# The file that marks a directory as written (and replaceable) by this tool.
MARKER = ".trilith-output"
# The list of files this tool wrote into a folder it shares with other files
# (figures --out, bench --out): only those are ever rewritten there.
MANIFEST = ".trilith-written"
# The content of an output's lock file: what proves this tool wrote it.
LOCK_TEXT = "trilith-xval output lock: removed when the output is written\n"
# Bytes a temporary name adds to an output's name: '.' + '.tmp-' + 8 random ones
# (tempfile), and a file's suffix on top; the lock file's '.lock' adds fewer.
_TMP_EXTRA = len(".") + len(".tmp-") + 8

# The exact file sets of report and campaign directories written before the
# marker existed: replaced like marked ones (a folder of a user's holds other files).
_UNMARKED_OUTPUTS = ({"index.html", "summary.json", "summary.md"},
                     {"index.html", "campaign.json"},
                     {"fragility.json", "fragility.csv", "fragility.png"})


def check_name_length(path, option: str, suffix: str = "") -> None:
    """``ValueError`` when the temporary name next to ``path``
    (``.<name>.tmp-XXXXXXXX<suffix>``) is longer than the filesystem allows."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    try:
        limit = os.pathconf(parent, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    need = len(os.fsencode(path.name)) + _TMP_EXTRA + len(os.fsencode(suffix))
    if need > limit:
        room = limit - _TMP_EXTRA - len(os.fsencode(suffix))
        raise ValueError(f"{option}: the name {path.name[:40]!r}... is "
                         f"{len(os.fsencode(path.name))} bytes; at most {room} here (the "
                         f"temporary name adds {need - len(os.fsencode(path.name))})")


def check_replaceable(out, option: str = "--out") -> None:
    """``ValueError`` unless ``out`` may be replaced whole: missing, an empty
    directory, a directory holding :data:`MARKER`, or one holding exactly the
    files an earlier report or campaign wrote before the marker existed; never
    the working directory or one of its ancestors, never a file."""
    out = Path(out)
    if out.is_symlink():  # the swap would replace the link, not the folder it names
        raise ValueError(f"{option} {str(out)!r} is a symbolic link (to "
                         f"{os.readlink(out)!r}); name the directory itself")
    if out.exists() and not out.is_dir():
        raise ValueError(f"{option} must be a directory, got the file {str(out)!r}")
    here, target = Path.cwd().resolve(), out.resolve()
    if target == here or target in here.parents:
        raise ValueError(f"{option} {str(out)!r} is the working directory or one of its "
                         "parents; name a directory for the output, e.g. --out report")
    check_name_length(target, option)
    if out.is_dir() and not (out / MARKER).is_file():
        try:
            names = {p.name for p in out.iterdir() if p.is_file() and not p.is_symlink()}
            entries = sum(1 for _ in out.iterdir())
        except OSError as exc:
            raise ValueError(f"{option} {str(out)!r}: {exc.strerror or exc}") from None
        if entries and not any(names == set(files) for files in _UNMARKED_OUTPUTS):
            raise ValueError(f"{option} {str(out)!r} holds files this tool did not write "
                             f"(no {MARKER} inside) and is not replaced; choose a new or "
                             "empty directory")


def _recorded(out: Path) -> set[str]:
    try:
        lines = (out / MANIFEST).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return set()
    return {line for line in lines if line and not line.startswith("#")}


def check_into(out, names, option: str = "--out") -> None:
    """``ValueError`` naming ``option`` unless every file of ``names`` is missing
    from the folder ``out`` or recorded in its :data:`MANIFEST` (written there
    by this tool before): a user's file of the same name is never overwritten."""
    out = Path(out)
    if out.is_symlink():
        raise ValueError(f"{option} {str(out)!r} is a symbolic link (to "
                         f"{os.readlink(out)!r}); name the directory itself")
    if not out.is_dir():
        return
    ours = _recorded(out)
    if not (out / MANIFEST).exists():
        try:
            present = {p.name for p in out.iterdir()}
        except OSError as exc:
            raise ValueError(f"{option} {str(out)!r}: {exc.strerror or exc}") from None
        if present == set(names):  # exactly a whole output of a version before the manifest
            return
    for name in names:
        target = out / name
        if (target.exists() or target.is_symlink()) and name not in ours:
            raise ValueError(f"{option} {str(out)!r}: {name} exists and this tool did not "
                             f"write it (not in {MANIFEST}); move it or choose another "
                             f"{option}")


def record_into(out, names) -> None:
    """Add ``names`` to the :data:`MANIFEST` of the folder ``out`` (created with its
    parents), before the files are written: a killed run leaves them claimable."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(_recorded(out) | set(names))
    write_text(out / MANIFEST, "# files written here by trilith-xval (rewritten by its next "
               "run; nothing else here is touched)\n" + "\n".join(names) + "\n")


def _remove_stale(out: Path) -> None:
    """Remove the ``.<name>.tmp-*``/``.<name>.old-*`` directories of killed builds
    of ``out`` (the caller holds its lock, so none is in use): marked or empty."""
    parent = out.parent
    for pattern in (f".{out.name}.tmp-*", f".{out.name}.old-*"):
        for stale in parent.glob(pattern):
            if stale.is_symlink() or not stale.is_dir():
                continue
            if (stale / MARKER).is_file():
                shutil.rmtree(stale, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    stale.rmdir()  # only when empty


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
        try:  # a rewritten output keeps its mode; mkstemp made the new one 0600
            mode = stat.S_IMODE(os.stat(path).st_mode)
        except OSError:
            mode = 0o666 & ~_umask()
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.errno is not None:
            # A writer's failure (a full disk) names the output, not its temporary name.
            raise OSError(exc.errno, exc.strerror, str(path)) from None
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


def _open_lock(lock: Path):
    """The lock file, open; created with :data:`LOCK_TEXT` when missing."""
    try:
        fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        os.write(fd, LOCK_TEXT.encode())
        os.close(fd)
    except FileExistsError:
        pass
    return open(lock, "a")


def _ours(lock: Path) -> bool:
    try:
        return lock.is_file() and not lock.is_symlink() and lock.read_text() == LOCK_TEXT
    except (OSError, UnicodeDecodeError):
        return False


@contextlib.contextmanager
def output_lock(path, option: str = "--out"):
    """Hold ``<path>.lock`` (flock) for the block; ``ValueError`` naming ``option``
    if another process holds it.  The lock file is removed at the end when this
    tool wrote it (:data:`LOCK_TEXT`)."""
    import fcntl

    path = Path(path)
    lock = path.with_name(path.name + ".lock")
    # Folders made for the lock are removed at the end when still empty: a
    # refused or failed run leaves no new folder behind.
    made = [p for p in (lock.parent, *lock.parent.parents) if not p.exists()]
    lock.parent.mkdir(parents=True, exist_ok=True)
    while True:
        fh = _open_lock(lock)
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.close()
            raise ValueError(f"{option} {str(path)!r} is being written by another process "
                             f"(lock {str(lock)!r} held); wait for it or choose another "
                             f"{option}") from None
        try:  # the holder before us may have removed the file we locked: retry
            same = os.path.samestat(os.fstat(fh.fileno()), os.stat(lock))
        except OSError:
            same = False
        if same:
            break
        fh.close()
    try:
        yield lock
    finally:
        if _ours(lock):  # removed while still locked: a waiter notices and retries
            with contextlib.suppress(OSError):
                os.unlink(lock)
        fh.close()
        for folder in made:  # innermost first; only the empty ones go
            with contextlib.suppress(OSError):
                folder.rmdir()


@contextlib.contextmanager
def report_dir(out, lock: bool = True):
    """Yield a fresh temporary directory; on success it replaces ``out`` whole.

    Takes :func:`output_lock` on ``out`` for the whole build (``lock=False``: the
    caller holds it already, e.g. for a long computation before).  ``ValueError``
    unless :func:`check_replaceable`.  The temporary directory holds
    :data:`MARKER` from the start.  On an exception it is removed and ``out`` is
    left as it was.
    """
    out = Path(out)
    check_replaceable(out)
    parent = out.parent if str(out.parent) else Path(".")
    with output_lock(out) if lock else contextlib.nullcontext():
        parent.mkdir(parents=True, exist_ok=True)  # the lock made it (and removes it)
        _remove_stale(Path(parent) / out.name)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=parent))
        try:
            (tmp / MARKER).write_text("written by trilith-xval: this directory is replaced "
                                      "whole by the next run with the same --out\n")
            yield tmp
            check_replaceable(out)  # a user's files may have appeared meanwhile
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
