"""The output-path check every command runs at the door (``--out``, ``--json FILE``,
``--csv``, ``--plot``): refused before any work, with one line naming the option."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from trilith_xval.compare.run.atomic import check_name_length, check_replaceable

__all__ = ["check_output_path"]


def check_output_path(path: str | os.PathLike, option: str, *, directory: bool = False,
                      replace: bool = False, suffixes: tuple[str, ...] | None = None,
                      files: tuple[str, ...] | None = None) -> Path:
    """Check an output path before any work; returns it as a Path.

    A file (``directory=False``): not an existing directory nor a special file,
    its suffix in ``suffixes`` when given, and its parent directory must exist
    (refused otherwise: a typo should not create directories) and be writable.
    A directory (``directory=True``): not an existing file; created with its
    parents when missing, then checked writable.  Files are written into it and
    nothing else there is touched, unless ``replace``: then the directory is
    replaced whole at the end, and refused now unless it is new, empty or one
    this tool wrote (:func:`compare.run.atomic.check_replaceable`); nothing is
    created now, its nearest existing ancestor is checked writable.  With
    ``files`` (the names to be written into the directory), likewise nothing is
    created now, and each must be missing or one this tool wrote there
    (:func:`compare.run.atomic.check_into`).  Writability is probed by creating a temporary file, which also holds for
    root on read-only mounts; names too long for the temporary name beside
    them are refused.
    """
    text = os.fspath(path)
    if not text.strip():
        raise ValueError(f"{option}: empty path")
    if "\0" in text:
        raise ValueError(f"{option}: the path contains a NUL character")
    p = Path(text)
    try:
        return _check_output_path(p, text, option, directory, replace, suffixes, files)
    except OSError as exc:  # a name too long, a loop of links, a permission
        raise ValueError(f"{option} {text[:60]!r}: {exc.strerror or exc}") from None


def _check_output_path(p: Path, text: str, option: str, directory: bool, replace: bool,
                       suffixes: tuple[str, ...] | None, files=None) -> Path:
    if directory:
        if p.exists() and not p.is_dir():
            raise ValueError(f"{option} must be a directory, but {text!r} is a file")
        if replace or files is not None:  # created by the writer: nothing now
            if replace:
                check_replaceable(p, option)
            else:
                from trilith_xval.compare.run.atomic import check_into
                check_into(p, files, option)
            ancestor = next(a for a in (p.absolute(), *p.absolute().parents) if a.exists())
            try:
                if not ancestor.is_dir():
                    raise NotADirectoryError(20, f"{str(ancestor)!r} is not a directory")
                fd, probe = tempfile.mkstemp(prefix=".trilith-probe-", dir=ancestor)
                os.close(fd)
                os.unlink(probe)
            except OSError as exc:
                raise ValueError(f"{option}: cannot create directory {text!r} "
                                 f"({exc.strerror or exc})") from None
            return p
        try:
            p.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"{option}: cannot create directory {text!r} "
                             f"({exc.strerror or exc})") from None
        _probe_writable(p, option, text)
        return p
    if p.is_dir():
        raise ValueError(f"{option} must be a file, but {text!r} is a directory")
    if p.exists() and not p.is_file():
        raise ValueError(f"{option}: {text!r} is not a regular file (a FIFO or device)")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise ValueError(f"{option} must end in {', '.join(suffixes)}, got {text!r}")
    check_name_length(p, option, p.suffix)
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        what = "is not a directory" if parent.exists() else "does not exist"
        raise ValueError(f"{option}: directory {str(parent)!r} {what} (create it first)")
    _probe_writable(parent, option, text)
    if p.exists() and not os.access(p, os.W_OK):
        raise ValueError(f"{option}: {text!r} exists and is not writable")
    return p


def _probe_writable(directory: Path, option: str, text: str) -> None:
    try:
        fd, probe = tempfile.mkstemp(prefix=".trilith-probe-", dir=directory)
    except OSError as exc:
        raise ValueError(f"{option}: cannot write in {str(directory)!r} for {text!r} "
                         f"({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
