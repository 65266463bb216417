"""The run store's database file: proven to be this tool's before anything touches it.

A store is a SQLite file whose header carries this tool's ``application_id``
(:data:`APPLICATION_ID`, SQLite's own field for "which program owns this file")
and whose ``user_version`` is the schema (:data:`SCHEMA_VERSION`).  A file is
identified through a read-only connection (``mode=ro``: SQLite writes nothing,
creates no table) before it is opened for writing, so another application's
database that happens to be called ``runs.sqlite`` is never written, pruned or
deleted.  A store of an older version of this tool (no ``application_id``, only
its ``runs`` table) is recognised by its exact columns and migrated: its entries
carry no digest, so none of them is ever served (each is recomputed and
replaced).

A new database is built beside its final name and hard-linked into place, so a
``runs.sqlite`` either does not exist or already carries the marker (a killed
process never leaves a bare file that would later look foreign).

Every entry carries a SHA-256 over its key (itself the digest of the inputs,
:mod:`compare.run.keys`) and its value bytes (:func:`entry_digest`): a changed
byte, or values swapped between keys, fails the check on read.
"""
from __future__ import annotations

import hashlib
import os
import sqlite3
import stat
import tempfile
import urllib.parse
from pathlib import Path

__all__ = ["APPLICATION_ID", "SCHEMA_VERSION", "COLUMNS", "NotAStore", "Damaged",
           "entry_digest", "identify", "create", "open_rw", "open_ro", "migrate",
           "header_is_ours", "default_cache_dir", "default_cache_source",
           "stale_temporaries", "check_directory", "bad_entries"]

APPLICATION_ID = 0x54724C78  # "TrLx"
SCHEMA_VERSION = 2
_HEADER = b"SQLite format 3\x00"
_TABLE = ("CREATE TABLE runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, "
          "label TEXT NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, "
          "value BLOB NOT NULL, code TEXT NOT NULL DEFAULT '', "
          "digest TEXT NOT NULL DEFAULT '')")
COLUMNS = frozenset({"key", "kind", "label", "cost", "created", "value", "code", "digest"})
# The columns of the stores older versions of this tool wrote (no marker, no digest).
_LEGACY = (COLUMNS - {"digest"}, COLUMNS - {"digest", "code"})


# ---------------------------------------------------------------------- where
def default_cache_source(environ=None) -> str:
    """What names the default store in messages: ``'TRILITH_CACHE'`` when that
    variable is set, else ``'the default store'``."""
    env = os.environ if environ is None else environ
    return "TRILITH_CACHE" if env.get("TRILITH_CACHE") else "the default store"


def default_cache_dir(environ=None) -> Path:
    """The store's directory when ``--cache`` is not given: ``$TRILITH_CACHE``, else
    ``$XDG_CACHE_HOME/trilith-xval``, else ``~/.cache/trilith-xval``, else
    ``<tmp>/trilith-xval-<uid>`` (the first whose nearest existing ancestor is a
    writable directory)."""
    env = os.environ if environ is None else environ
    if env.get("TRILITH_CACHE"):
        return Path(env["TRILITH_CACHE"]).expanduser()
    candidates = []
    xdg = env.get("XDG_CACHE_HOME", "")
    if xdg and os.path.isabs(xdg):
        candidates.append(Path(xdg) / "trilith-xval")
    home = env.get("HOME") or os.path.expanduser("~")
    if home and home != "~" and os.path.isabs(home):
        candidates.append(Path(home) / ".cache" / "trilith-xval")
    for path in candidates:  # not created here: only a stored result creates it
        if _creatable(path):
            return path
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(tempfile.gettempdir()) / f"trilith-xval-{uid}"


def _creatable(path: Path) -> bool:
    """``path`` is a writable directory, or its nearest existing ancestor is one."""
    return _not_creatable(path) is None


def _not_creatable(path: Path) -> str | None:
    """Why ``path`` cannot be created (or written in), or None."""
    for p in (path, *path.parents):
        if p.exists():
            if not p.is_dir():
                return f"{str(p)!r} is not a directory"
            if not os.access(p, os.W_OK | os.X_OK):
                return f"{str(p)!r} is not writable"
            return None
    return "no existing parent directory"



# ---------------------------------------------------------------------- what
class NotAStore(ValueError):
    """The file is not this tool's store: it is never written, pruned or deleted."""


class Damaged(ValueError):
    """This tool's store (its marker is in the header), but SQLite cannot read it."""


def entry_digest(key: str, blob: bytes) -> str:
    """SHA-256 (hex) binding a value's bytes to its key.

    Parameters
    ----------
    key : str
        The entry's key.
    blob : bytes
        The encoded value (:func:`compare.run.codec.encode`).

    Returns
    -------
    str
        64 hex digits.
    """
    h = hashlib.sha256(b"trilith-entry\0")
    h.update(str(key).encode())
    h.update(b"\0")
    h.update(bytes(blob))
    return h.hexdigest()


def _sql_digest(key, blob):  # for SQL: NULL or text values never match a digest
    if key is None or not isinstance(blob, bytes):
        return None
    return entry_digest(key, blob)


def header_is_ours(path: Path) -> bool:
    """The first 100 bytes are a SQLite header carrying :data:`APPLICATION_ID`."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(100)
    except OSError:
        return False
    return (len(head) == 100 and head.startswith(_HEADER)
            and int.from_bytes(head[68:72], "big") == APPLICATION_ID)


def _uri(path: Path, **params) -> str:
    query = "&".join(f"{k}={v}" for k, v in params.items())
    return f"file:{urllib.parse.quote(str(Path(path).absolute()))}?{query}"


def open_ro(path: Path, timeout: float, immutable: bool = False) -> sqlite3.Connection:
    """A read-only connection (``mode=ro``; ``immutable=1`` when asked, or when
    SQLite cannot create the WAL index beside a file on a read-only filesystem or
    directory: then it creates no file at all)."""
    if immutable:
        return sqlite3.connect(_uri(path, mode="ro", immutable=1), uri=True, timeout=timeout,
                               isolation_level=None, check_same_thread=False)
    try:
        conn = sqlite3.connect(_uri(path, mode="ro"), uri=True, timeout=timeout,
                               isolation_level=None, check_same_thread=False)
        conn.execute("SELECT COUNT(*) FROM sqlite_master").fetchone()
        return conn
    except sqlite3.OperationalError:
        # Nobody can write a file in a directory nobody may create files in.
        conn = sqlite3.connect(_uri(path, mode="ro", immutable=1), uri=True,
                               timeout=timeout, isolation_level=None,
                               check_same_thread=False)
        return conn


def open_rw(path: Path, timeout: float) -> sqlite3.Connection:
    """A read-write connection to an existing file (``mode=rw``: never creates one)."""
    conn = sqlite3.connect(_uri(path, mode="rw"), uri=True, timeout=timeout,
                           isolation_level=None, check_same_thread=False)
    conn.create_function("trilith_digest", 2, _sql_digest, deterministic=True)
    return conn


def identify(path: Path, timeout: float) -> str:
    """``'current'`` or ``'legacy'`` (an older version's store, to migrate).

    Raises
    ------
    NotAStore
        Not SQLite, or SQLite without this tool's marker and tables (named).
    Damaged
        Carries the marker but SQLite cannot read it, or a newer schema.
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(100)
    except OSError as exc:
        raise Damaged(f"cannot be read ({exc.strerror or exc})") from None
    if not head.startswith(_HEADER):
        what = "an empty file" if not head else "not an SQLite database"
        raise NotAStore(f"it is {what}")
    ours = header_is_ours(path)
    app_header = int.from_bytes(head[68:72], "big") if len(head) >= 72 else 0
    if app_header not in (0, APPLICATION_ID):  # another program's marker: not opened
        raise NotAStore(f"application id {app_header:#x}: another program's database")
    conn = None
    try:
        # Not proven ours yet: opened immutable, so that SQLite creates no -wal or
        # -shm file beside another application's database.
        conn = open_ro(path, timeout, immutable=not ours)
        app = conn.execute("PRAGMA application_id").fetchone()[0]
        version = conn.execute("PRAGMA user_version").fetchone()[0]
        tables = {r[0] for r in conn.execute(
            "SELECT name FROM sqlite_master WHERE type = 'table' "
            "AND name NOT LIKE 'sqlite_%'")}
        columns = {r[1] for r in conn.execute("PRAGMA table_info(runs)")}
    except sqlite3.DatabaseError as exc:
        if ours:
            raise Damaged(str(exc)) from None
        raise NotAStore(f"SQLite cannot read it as a run store ({exc})") from None
    finally:
        if conn is not None:
            conn.close()
    if app == APPLICATION_ID:
        if version > SCHEMA_VERSION:
            raise Damaged(f"written by a newer version of this tool (schema {version}, "
                          f"this one reads {SCHEMA_VERSION})")
        if tables != {"runs"} or columns != COLUMNS:
            raise Damaged(f"its tables {sorted(tables)} / columns {sorted(columns)} are "
                          "not a run store's")
        return "current"
    if app == 0 and tables == {"runs"} and columns in _LEGACY:
        return "legacy"
    raise NotAStore(f"application id {app:#x}, tables {sorted(tables)}"
                    + (f", 'runs' columns {sorted(columns)}" if columns else "")
                    + ": not a run store's")


def migrate(conn: sqlite3.Connection) -> None:
    """Give an older version's store the digest column and the marker (its entries
    keep an empty digest: never served, recomputed when next needed)."""
    conn.execute("BEGIN IMMEDIATE")
    try:
        columns = {r[1] for r in conn.execute("PRAGMA table_info(runs)")}
        if "code" not in columns:
            conn.execute("ALTER TABLE runs ADD COLUMN code TEXT NOT NULL DEFAULT ''")
        if "digest" not in columns:
            conn.execute("ALTER TABLE runs ADD COLUMN digest TEXT NOT NULL DEFAULT ''")
        conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
        conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
        conn.execute("COMMIT")
    except BaseException:
        conn.execute("ROLLBACK")
        raise
    conn.execute("PRAGMA wal_checkpoint(PASSIVE)")  # the marker into the file's header


def create(path: Path) -> None:
    """Build a new, marked store beside ``path`` and link it into place (no-op when
    another process got there first)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.new-", dir=path.parent)
    os.close(fd)
    try:
        conn = sqlite3.connect(tmp, isolation_level=None)
        try:
            conn.execute("PRAGMA journal_mode=WAL")
            conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
            conn.execute(_TABLE)
        finally:
            conn.close()  # checkpoints: the marker is in the file itself
        try:
            os.link(tmp, path)
        except FileExistsError:
            pass
        except OSError:  # a filesystem without hard links
            if not path.exists():
                os.rename(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def stale_temporaries(directory: Path, name: str) -> list[Path]:
    """Databases :func:`create` was building when its process was killed."""
    return sorted(p for p in directory.glob(f".{name}.new-*") if p.is_file())


def check_directory(directory: Path, where: str) -> None:
    """``ValueError`` naming ``where`` unless ``directory`` can hold a store: it is
    (or can be created as) a directory of this user that others cannot write in."""
    if not directory.exists():
        why = _not_creatable(directory)
        if why is not None:
            raise ValueError(f"{where}: cannot create the store directory ({why})")
        return
    try:
        st = directory.stat()
    except OSError as exc:
        raise ValueError(f"{where}: {exc.strerror or exc}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise ValueError(f"{where} is not a directory")
    if hasattr(os, "getuid") and st.st_uid != os.getuid():
        raise ValueError(f"{where} belongs to another user (uid {st.st_uid}); a run "
                         "store must be your own: choose another --cache")
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        raise ValueError(f"{where} is writable by other users (mode "
                         f"{stat.S_IMODE(st.st_mode):o}); 'chmod go-w' it or choose "
                         "another --cache")


def bad_entries(rows, decode) -> list[tuple]:
    """``(key, kind, label, why)`` for every row ``(key, kind, label, value, digest)``
    that would not be served: no digest, a digest that does not match, or a value
    ``decode`` refuses."""
    bad = []
    for key, kind, label, blob, stored in rows:
        if not stored:
            why = "no digest (written by an older version)"
        elif not isinstance(blob, bytes) or stored != entry_digest(key, blob):
            why = "digest mismatch (changed after it was written)"
        else:
            try:
                decode(blob)
                continue
            except ValueError as exc:
                why = f"value not of this format ({exc})"
        bad.append((key, kind, label, why))
    return bad
