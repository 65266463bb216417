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
A store that SQLite cannot read is refused with one line naming the file; a
full disk under the store is reported once on stderr and the results are still
returned, just not kept.

Concurrency: WAL journal (readers never block the writer), every write one
autocommitted insert that keeps a readable existing value (a SIGKILL loses at most the transaction in
flight; SQLite rolls it back on the next open), and ``busy_timeout`` so
processes sharing a store wait for each other's lock instead of failing.
"""
from __future__ import annotations

import contextlib
import os
import stat
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

from compare.run.codec import MAGIC, ForeignValue, decode, encode

__all__ = ["RunStore", "default_cache_dir", "DB_NAME"]

DB_NAME = "runs.sqlite"
# Waiting for another process's write lock: writes take ~1 ms, so 60 s means a
# stuck peer, not contention.
BUSY_TIMEOUT_MS = 60_000
_SCHEMA = ("CREATE TABLE IF NOT EXISTS runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, "
           "label TEXT NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, "
           "value BLOB NOT NULL, code TEXT NOT NULL DEFAULT '')")
_COLUMNS = {"key", "kind", "label", "cost", "created", "value", "code"}


def default_cache_dir(environ=None) -> Path:
    """The store's directory when ``--cache`` is not given (see the module doc)."""
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


# -------------------------------------------------------------------------- store
class _DiskFull(Exception):
    """The filesystem under the store is full (reported once, never fatal)."""


def _is_full(exc: sqlite3.DatabaseError) -> bool:
    return getattr(exc, "sqlite_errorcode", None) == sqlite3.SQLITE_FULL


class RunStore:
    """A directory holding ``runs.sqlite``; safe to share between processes.

    Parameters
    ----------
    directory : str or Path
        Checked now, created (mode 0700) when the first result is stored.
        ``ValueError`` (one line) if it is not a directory, cannot be created,
        is owned by another user or writable by others, or if its
        ``runs.sqlite`` is not a readable run store.
    check_database : bool
        Open and check ``runs.sqlite`` now (default); False leaves that to the
        first use (:meth:`clear` of a damaged store).

    Examples
    --------
    >>> import tempfile
    >>> store = RunStore(tempfile.mkdtemp())
    >>> store.put("k", {"x": 1.5}, kind="demo", label="demo", cost=0.0)
    >>> store.get("k")
    {'x': 1.5}
    """

    def __init__(self, directory, *, check_database: bool = True) -> None:
        self.directory = Path(directory).expanduser()
        self.path = self.directory / DB_NAME
        self._conn = None
        self._pid = None
        self._full_reported = False
        self._check_directory()
        if check_database and self.path.exists():
            try:
                self._connect()  # validate now, before any work
            except _DiskFull:
                self._report_full()

    def __getstate__(self):  # a connection does not cross processes: reopen there
        return {"directory": self.directory}

    def __setstate__(self, state):
        self.__init__(state["directory"])

    def __repr__(self) -> str:
        return f"RunStore({str(self.directory)!r})"

    # ------------------------------------------------------------- opening
    def _check_directory(self) -> None:
        where = f"--cache {str(self.directory)!r}"
        if not self.directory.exists():
            why = _not_creatable(self.directory)
            if why is not None:
                raise ValueError(f"{where}: cannot create the store directory ({why})")
            return
        try:
            st = self.directory.stat()
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

    def _damaged(self, exc: Exception) -> ValueError:
        return ValueError(f"run store {str(self.path)!r} is not usable ({exc}); remove it "
                          f"with 'trilith cache clear --cache {self.directory}' or choose "
                          "another --cache")

    def _connect(self, create: bool = False) -> sqlite3.Connection | None:
        """The connection (reopened in a forked child); None when the store does
        not exist yet and ``create`` is false."""
        if self._conn is not None and self._pid == os.getpid():
            return self._conn
        if not self.path.exists():
            if not create:
                return None
            try:
                self.directory.mkdir(mode=0o700, parents=True, exist_ok=True)
            except OSError as exc:
                raise ValueError(f"--cache: cannot create the store directory "
                                 f"{str(self.directory)!r} ({exc.strerror})") from None
            self._check_directory()
        elif not self.path.is_file():
            raise self._damaged("not a regular file")
        # A forked child must not touch its parent's connection: open its own.
        conn = None
        try:
            conn = sqlite3.connect(self.path, timeout=BUSY_TIMEOUT_MS / 1000,
                                   isolation_level=None, check_same_thread=False)
            conn.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
            if conn.execute("PRAGMA journal_mode").fetchone()[0] != "wal":
                conn.execute("PRAGMA journal_mode=WAL")
            # WAL + NORMAL: a commit survives a killed process (not a power cut).
            conn.execute("PRAGMA synchronous=NORMAL")
            conn.execute(_SCHEMA)
            columns = {row[1] for row in conn.execute("PRAGMA table_info(runs)")}
            if columns == _COLUMNS - {"code"}:  # a store from before code versions
                conn.execute("ALTER TABLE runs ADD COLUMN code TEXT NOT NULL DEFAULT ''")
            elif columns != _COLUMNS:
                raise sqlite3.DatabaseError(f"its 'runs' table has the columns "
                                            f"{sorted(columns)}, not a run store's")
        except sqlite3.DatabaseError as exc:
            if conn is not None:
                conn.close()
            if _is_full(exc):
                raise _DiskFull from None
            raise self._damaged(exc) from None
        self._conn, self._pid = conn, os.getpid()
        return conn

    def _report_full(self) -> None:
        if not self._full_reported:
            self._full_reported = True
            print(f"warning: run store {self.directory}: the disk is full; results are "
                  "computed but not stored", file=sys.stderr)

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
        """The stored value under ``key``, or None (also for a value this format
        did not write: it is never interpreted, and replaced by the next put)."""
        rows = self._query("SELECT value FROM runs WHERE key = ?", (key,))
        if not rows:
            return None
        try:
            return decode(rows[0][0])
        except ForeignValue:
            return None

    def put(self, key: str, value, *, kind: str, label: str, cost: float,
            code: str = "") -> None:
        """Store ``value`` unless ``key`` holds a readable value already (same key:
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
        try:
            conn = self._connect(create=True)
            conn.execute(
                "INSERT INTO runs (key, kind, label, cost, created, value, code) "
                "VALUES (?, ?, ?, ?, ?, ?, ?) ON CONFLICT(key) DO UPDATE SET "
                "kind = excluded.kind, label = excluded.label, cost = excluded.cost, "
                "created = excluded.created, value = excluded.value, code = excluded.code "
                "WHERE substr(runs.value, 1, ?) != ?",
                (key, kind, label, float(cost), time.time(), blob, code, len(MAGIC), MAGIC))
        except _DiskFull:
            self._report_full()
        except sqlite3.DatabaseError as exc:
            if not _is_full(exc):
                raise self._damaged(exc) from None
            self._report_full()

    # ------------------------------------------------------------- figures
    def count(self, kind: str | None = None, since: float | None = None) -> int:
        """Entries (of ``kind``; created at or after ``since``, a ``time.time()``)."""
        sql, args = "SELECT COUNT(*) FROM runs WHERE 1", []
        if kind is not None:
            sql, args = sql + " AND kind = ?", [*args, kind]
        if since is not None:
            sql, args = sql + " AND created >= ?", [*args, since]
        rows = self._query(sql, args)
        return int(rows[0][0]) if rows else 0

    def created(self) -> dict[str, float]:
        """Key -> creation time of every entry (tests: nothing was rewritten)."""
        return dict(self._query("SELECT key, created FROM runs"))

    def mean_costs(self, kind: str = "run") -> dict[str, tuple[float, int]]:
        """Label -> (mean cost [s], count) over the stored entries of ``kind``."""
        rows = self._query("SELECT label, AVG(cost), COUNT(*) FROM runs WHERE kind = ? "
                           "GROUP BY label", (kind,))
        return {label: (float(mean), int(n)) for label, mean, n in rows}

    def by_code(self) -> list[tuple[str, int, int]]:
        """``(code version, entries, value bytes)`` per code version; entries this
        format did not write (old pickles) are grouped under ``'foreign'``."""
        rows = self._query(
            "SELECT CASE WHEN substr(value, 1, ?) = ? THEN code ELSE 'foreign' END AS c, "
            "COUNT(*), SUM(length(value)) FROM runs GROUP BY c ORDER BY c",
            (len(MAGIC), MAGIC))
        return [(code or "unknown", int(n), int(size or 0)) for code, n, size in rows]

    def files(self) -> list[Path]:
        """The store's files that exist (the database, its WAL and shared memory)."""
        return [p for p in (self.path, self.path.with_name(DB_NAME + "-wal"),
                            self.path.with_name(DB_NAME + "-shm")) if p.exists()]

    def prune(self, keep: set[str]) -> int:
        """Delete entries whose code version is not in ``keep`` (and foreign ones);
        returns how many, and gives the space back to the filesystem."""
        if self._connect() is None:
            return 0
        marks = ",".join("?" * len(keep)) or "''"
        before = self.count()
        self._query(f"DELETE FROM runs WHERE code NOT IN ({marks}) "
                    "OR substr(value, 1, ?) != ?", (*sorted(keep), len(MAGIC), MAGIC))
        self._query("VACUUM")
        return before - self.count()

    def clear(self) -> int:
        """Delete the store's files (nothing else in the directory); returns the
        number of entries there were when readable, else -1."""
        try:
            n = self.count()
        except ValueError:  # damaged: clearing is the cure
            n = -1
        self.close()
        for p in self.files():
            p.unlink()
        with contextlib.suppress(OSError):
            self.directory.rmdir()  # only when empty: the directory may hold user files
        return n

    def close(self) -> None:
        if self._conn is not None and self._pid == os.getpid():
            self._conn.close()
        self._conn = None
