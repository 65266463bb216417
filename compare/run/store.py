"""The run store: every finished run kept in an embedded SQLite database.

A result is stored under the SHA-256 of a canonical JSON of everything that
determines it (:mod:`compare.run.keys`: backend and engine version, scene,
excitation, settings, project version and a digest of the source files).

The value is data, never code (:mod:`compare.run.codec`: a JSON header and raw
little-endian arrays): a store shared on a cluster filesystem cannot make a reader
run anything.  Floats and arrays round-trip bit for bit, so a stored Trajectory
is identical to the one that was computed.  A value the format did not write (an
old pickle, a damaged row) is never interpreted: it counts as missing, is
recomputed and replaced.  Each row also records its code version (project
version and source digest) for ``trilith cache info|prune``.

Where: ``--cache DIR``, else ``$TRILITH_CACHE``, else ``$XDG_CACHE_HOME/trilith-xval``,
else ``~/.cache/trilith-xval``; when none of those can be created (a CI job with
an unusual ``HOME``) ``<tmp>/trilith-xval-<uid>``.  One file, ``runs.sqlite``.
The directory is created (mode 0700) only when a first result is stored, and
refused when another user owns it or others may write in it (a planted store).
The file must be this tool's (:mod:`compare.run.store_db`: a marker in the SQLite
header, checked through a read-only connection first): any other file called
``runs.sqlite`` is refused in one line and never written, pruned or deleted.
Every entry carries a digest of its key and value, checked on every read: an
entry that fails it is named in one line on stderr and recomputed, never served
(``trilith cache verify`` checks a whole store).  A store SQLite cannot read is
refused with one line naming the file.  A store that cannot be written (a
read-only filesystem or directory) is used read-only: its proven entries are
served and nothing is stored; a full disk, or a store that cannot grow, is
reported once on stderr and the results are still returned, just not kept.

Concurrency: WAL journal (readers never block the writer), every write one
autocommitted insert that keeps a proven existing value (a SIGKILL loses at most
the transaction in flight; SQLite rolls it back on the next open), and
``busy_timeout`` so
processes sharing a store wait for each other's lock instead of failing.
"""
from __future__ import annotations

import contextlib
import errno
import os
import sqlite3
import sys
import time
from pathlib import Path

from trilith_xval.compare.run import store_db
from trilith_xval.compare.run.store_db import default_cache_dir, default_cache_source
from trilith_xval.compare.run.codec import MAGIC, ForeignValue, decode, encode
from trilith_xval.compare.run.store_figures import StoreFigures

__all__ = ["RunStore", "default_cache_dir", "default_cache_source", "DB_NAME"]

DB_NAME = "runs.sqlite"
# Waiting for another process's write lock: writes take ~1 ms, so 60 s means a
# stuck peer, not contention.
BUSY_TIMEOUT_MS = 60_000


# -------------------------------------------------------------------------- store
class _DiskFull(Exception):
    """The filesystem under the store is full (reported once, never fatal)."""


def _is_full(exc: sqlite3.DatabaseError) -> bool:
    return getattr(exc, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL


class RunStore(StoreFigures):
    """A directory holding ``runs.sqlite``; safe to share between processes.

    Parameters
    ----------
    directory : str or Path
        Checked now, created (mode 0700) when the first result is stored.
        ``ValueError`` (one line) if it is not a directory, cannot be created,
        is owned by another user or writable by others, or if its
        ``runs.sqlite`` is not this tool's store or not readable.
    check_database : bool
        Open and check ``runs.sqlite`` now (default); False leaves that to the
        first use (:meth:`clear` of a damaged store).
    source : str
        Where ``directory`` came from, for messages: ``'--cache'`` (default),
        ``'TRILITH_CACHE'`` or ``'the default store'``.

    Examples
    --------
    >>> import tempfile
    >>> store = RunStore(tempfile.mkdtemp())
    >>> store.put("k", {"x": 1.5}, kind="demo", label="demo", cost=0.0)
    >>> store.get("k")
    {'x': 1.5}
    """

    def __init__(self, directory, *, check_database: bool = True,
                 source: str = "--cache") -> None:
        self.directory = Path(directory).expanduser()
        self.path = self.directory / DB_NAME
        self.source = source
        self.readonly = False
        self._legacy = False
        self._readonly_why = "it is read-only"
        self._conn = None
        self._pid = None
        self._warned: set[str] = set()
        self._check_directory()
        if check_database and self.path.exists():
            try:
                self._connect()  # validate now, before any work
            except _DiskFull:
                self._report_full()

    def __getstate__(self):  # a connection does not cross processes: reopen there
        return {"directory": self.directory, "source": self.source}

    def __setstate__(self, state):
        self.__init__(state["directory"], source=state.get("source", "--cache"))

    def __repr__(self) -> str:
        return f"RunStore({str(self.directory)!r})"

    # ------------------------------------------------------------- opening
    @property
    def _where(self) -> str:
        if self.source.startswith("-"):
            return f"{self.source} {str(self.directory)!r}"
        return f"{self.source} ({str(self.directory)!r})"

    def _check_directory(self) -> None:
        store_db.check_directory(self.directory, self._where)

    @property
    def _other(self) -> str:
        """The advice on where else to keep results, naming what chose this store."""
        if self.source == "TRILITH_CACHE":
            return "another --cache, or set TRILITH_CACHE to another directory"
        return "another --cache"

    def _damaged(self, exc: Exception) -> ValueError:
        # Only a file proven ours (its header's marker) is one 'cache clear' removes.
        cure = (f"remove it with 'trilith cache clear --cache {self.directory}'"
                if store_db.header_is_ours(self.path) else "move it away")
        return ValueError(f"run store {str(self.path)!r} is not usable ({exc}); {cure} or "
                          f"choose {self._other}")

    def _foreign(self, exc: Exception) -> ValueError:
        return ValueError(f"{self._where}: its {DB_NAME} is not a trilith-xval run store "
                          f"({exc}); it is left untouched: choose {self._other}")

    def _identify(self) -> str:
        try:
            return store_db.identify(self.path, BUSY_TIMEOUT_MS / 1000)
        except store_db.NotAStore as exc:
            raise self._foreign(exc) from None
        except store_db.Damaged as exc:
            raise self._damaged(exc) from None

    def _writable(self) -> bool:
        return (os.access(self.directory, os.W_OK | os.X_OK)
                and os.access(self.path, os.W_OK))

    def _connect(self, create: bool = False) -> sqlite3.Connection | None:
        """The connection (reopened in a forked child); None when the store does
        not exist yet and ``create`` is false or it cannot be created."""
        if self._conn is not None and self._pid == os.getpid():
            return self._conn
        if not self.path.exists() and not self.path.is_symlink():
            if not create:
                return None
            if not self._create():
                return None
        elif not self.path.is_file():
            raise self._foreign("not a regular file")
        kind = self._identify()
        timeout = BUSY_TIMEOUT_MS / 1000
        # A forked child must not touch its parent's connection: open its own.
        conn = None
        try:
            if self._writable():
                try:
                    conn = store_db.open_rw(self.path, timeout)
                    conn.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
                    # WAL + NORMAL: a commit survives a killed process (not a power cut).
                    conn.execute("PRAGMA synchronous=NORMAL")
                    if kind == "legacy":
                        store_db.migrate(conn)
                        kind = "current"
                except sqlite3.OperationalError as exc:
                    if _is_full(exc):
                        raise
                    if conn is not None:  # e.g. a file size limit: read what is there
                        conn.close()
                    conn, self._readonly_why = None, f"it cannot be written ({exc})"
            if conn is None:
                conn = store_db.open_ro(self.path, timeout)
                conn.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
                self.readonly = True
            self._legacy = kind == "legacy"  # read-only and never migrated: serve nothing
        except sqlite3.DatabaseError as exc:
            if conn is not None:
                conn.close()
            if _is_full(exc):
                raise _DiskFull from None
            raise self._damaged(exc) from None
        self._conn, self._pid = conn, os.getpid()
        return conn

    def _create(self) -> bool:
        """Create the directory and a marked database; False (reported once) when
        the filesystem does not let us."""
        try:
            self.directory.mkdir(mode=0o700, parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"{self._where}: cannot create the store directory "
                             f"({exc.strerror})") from None
        self._check_directory()
        try:
            store_db.create(self.path)
        except sqlite3.DatabaseError as exc:
            if _is_full(exc):
                raise _DiskFull from None
            self._warn("created", f"cannot be created ({exc})")
            return False
        except OSError as exc:
            if exc.errno == errno.ENOSPC:
                raise _DiskFull from None
            self._warn("created", f"cannot be created ({exc.strerror or exc})")
            return False
        return True

    def _warn(self, what: str, text: str) -> None:
        """One line on stderr per kind of trouble, never more."""
        if what not in self._warned:
            self._warned.add(what)
            print(f"warning: run store {self.directory}: {text}; results are computed "
                  "but not stored", file=sys.stderr)

    def _report_full(self) -> None:
        self._warn("full", "the disk is full")

    def _query(self, sql: str, args=()) -> list:
        try:
            conn = self._connect()
            if conn is None:
                return []
            return conn.execute(sql, args).fetchall()
        except _DiskFull:
            self._report_full()
            return []
        except sqlite3.DatabaseError as exc:
            if _is_full(exc):
                self._report_full()
                return []
            raise self._damaged(exc) from None

    def create(self) -> None:
        """Create the directory and the database now: before several processes
        write to it, so that they never race to create it."""
        try:
            self._connect(create=True)
        except _DiskFull:
            self._report_full()

    # ------------------------------------------------------------ values
    def get(self, key: str):
        """The stored value under ``key``, or None: also for an entry whose digest
        does not match its key and value (named on stderr), one without a digest
        (an older store) and a value this format did not write; none of them is
        served, and the next :meth:`put` replaces it."""
        if self._connect() is not None and self._legacy:
            return None
        rows = self._query("SELECT value, digest FROM runs WHERE key = ?", (key,))
        if not rows:
            return None
        blob, stored = rows[0]
        if not isinstance(blob, bytes) or stored != store_db.entry_digest(key, blob):
            # Once per entry (a lookup may precede the computation); an entry
            # without a digest is an older store's: silently redone.
            if stored and f"digest {key}" not in self._warned:
                self._warned.add(f"digest {key}")
                print(f"warning: run store {str(self.path)!r}: entry {key[:16]} fails its "
                      "digest check (changed after it was written); recomputed",
                      file=sys.stderr)
            return None
        try:
            return decode(blob)
        except ForeignValue:
            return None

    def put(self, key: str, value, *, kind: str, label: str, cost: float,
            code: str = "") -> None:
        """Store ``value`` unless ``key`` holds a proven value already (same key:
        same result).  ``code``: the :func:`~compare.run.keys.code_version` of the key.
        A value the format cannot hold is not stored (one warning): the caller
        still has its result."""
        try:
            blob = encode(value)
        except TypeError as exc:
            print(f"warning: run store: a {kind!r} result is not stored ({exc})",
                  file=sys.stderr)
            return
        self.put_blob(key, blob, kind=kind, label=label, cost=cost, code=code)

    def put_blob(self, key: str, blob: bytes, *, kind: str, label: str, cost: float,
                 code: str = "") -> None:
        """Store raw bytes under ``key`` with their digest (see :meth:`put`).  Never
        raises for the database: a store that cannot take the entry (full, cannot
        grow, read-only, damaged) is reported once and the run goes on."""
        try:
            conn = self._connect(create=True)
            if conn is None:
                return
            if self.readonly:
                self._warn("readonly", self._readonly_why)
                return
            conn.execute(
                "INSERT INTO runs (key, kind, label, cost, created, value, code, digest) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?) ON CONFLICT(key) DO UPDATE SET "
                "kind = excluded.kind, label = excluded.label, cost = excluded.cost, "
                "created = excluded.created, value = excluded.value, code = excluded.code, "
                "digest = excluded.digest WHERE substr(runs.value, 1, ?) != ? "
                "OR runs.digest IS NOT trilith_digest(runs.key, runs.value)",
                (key, kind, label, float(cost), time.time(), blob, code,
                 store_db.entry_digest(key, blob), len(MAGIC), MAGIC))
        except _DiskFull:
            self._report_full()
        except sqlite3.DatabaseError as exc:
            if _is_full(exc):
                self._report_full()
            else:  # cannot grow (a file size limit), I/O error, damage
                self._warn("write", f"cannot store a result ({exc})")

    def files(self) -> list[Path]:
        """The store's files that exist (the database, its WAL and shared memory)."""
        return [p for p in (self.path, self.path.with_name(DB_NAME + "-wal"),
                            self.path.with_name(DB_NAME + "-shm")) if p.exists()]

    def prune(self, keep: set[str]) -> int:
        """Delete entries whose code version is not in ``keep``, foreign ones and
        any that fail their digest; returns how many, and gives the space back to
        the filesystem."""
        if self._connect() is None:
            return 0
        if self.readonly:
            raise ValueError(f"{self._where}: the store is read-only; nothing pruned")
        marks = ",".join("?" * len(keep)) or "''"
        before = self.count()
        self._query(f"DELETE FROM runs WHERE code NOT IN ({marks}) "
                    "OR substr(value, 1, ?) != ? "
                    "OR digest IS NOT trilith_digest(key, value)",
                    (*sorted(keep), len(MAGIC), MAGIC))
        self._query("VACUUM")
        return before - self.count()

    def clear(self) -> int:
        """Delete the store's files (nothing else in the directory); returns the
        number of entries there were when readable, else -1.  ``ValueError`` when
        ``runs.sqlite`` is not this tool's: then nothing is deleted."""
        n = -1
        if self.path.exists() or self.path.is_symlink():
            if self.path.is_symlink() or not self.path.is_file():
                raise self._foreign("not a regular file")
            try:
                self._identify()
                n = self.count()
            except ValueError:
                if not store_db.header_is_ours(self.path):  # foreign: left untouched
                    raise
        self.close()
        if self.files() and not os.access(self.directory, os.W_OK | os.X_OK):
            raise ValueError(f"{self._where}: the store's directory is read-only; "
                             "nothing cleared")
        for p in (*self.files(), *store_db.stale_temporaries(self.directory, DB_NAME)):
            p.unlink()
        with contextlib.suppress(OSError):
            self.directory.rmdir()  # only when empty: the directory may hold user files
        return n

    def close(self) -> None:
        if self._conn is not None and self._pid == os.getpid():
            self._conn.close()
        self._conn = None
