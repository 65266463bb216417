"""The run store: every finished run kept in an embedded SQLite database.

A result is stored under the SHA-256 of a canonical JSON of everything that
determines it (:func:`run_key`): backend name and engine version, the scene's
fields, the excitation (type and fields, sampled records sample by sample), the
backend settings, the project's version and a digest of the model/engine source
files (so an edited checkout never reuses results of older code).  The scene's
``name`` is a label and is left out: the same trilith under two names is one run.

The value is the pickled result (protocol 5): numpy arrays and floats round-trip
exactly, so a stored Trajectory is bit-identical to the one that was computed.

Where: ``--cache DIR``, else ``$TRILITH_CACHE``, else ``$XDG_CACHE_HOME/trilith-xval``,
else ``~/.cache/trilith-xval``; when none of those can be created (a CI job with
an unusual ``HOME``) ``<tmp>/trilith-xval-<uid>``.  One file, ``runs.sqlite``.

Concurrency: WAL journal (readers never block the writer), every write one
autocommitted ``INSERT OR IGNORE`` (a SIGKILL loses at most the transaction in
flight; SQLite rolls it back on the next open), and ``busy_timeout`` so
processes sharing a store wait for each other's lock instead of failing.
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import os
import pickle
import sqlite3
import tempfile
import time
from pathlib import Path

__all__ = ["RunStore", "default_cache_dir", "run_key", "canonical_json", "digest",
           "project_version", "DB_NAME"]

DB_NAME = "runs.sqlite"
# Waiting for another process's write lock: writes take ~1 ms, so 60 s means a
# stuck peer, not contention.
BUSY_TIMEOUT_MS = 60_000
_SCHEMA = ("CREATE TABLE IF NOT EXISTS runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, "
           "label TEXT NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, "
           "value BLOB NOT NULL)")
_ROOT = Path(__file__).resolve().parents[2]


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
    for path in candidates:
        try:
            path.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        if os.access(path, os.W_OK):
            return path
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(tempfile.gettempdir()) / f"trilith-xval-{uid}"


# --------------------------------------------------------------------------- keys
def _plain(value):
    """JSON-ready form of dataclasses, numpy values, tuples (recursively)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {"__type__": type(value).__name__,
                **{f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _plain(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)  # 'nan', 'inf': JSON has no such numbers
    return value


def canonical_json(obj) -> str:
    """Sorted keys, no spaces, floats by ``repr`` (shortest exact form)."""
    return json.dumps(_plain(obj), sort_keys=True, separators=(",", ":"), allow_nan=False)


def digest(obj) -> str:
    """SHA-256 (hex) of :func:`canonical_json`."""
    return hashlib.sha256(canonical_json(obj).encode()).hexdigest()


@functools.lru_cache(maxsize=None)
def project_version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("trilith-xval")
    except PackageNotFoundError:  # a bare source checkout
        return "unknown"


@functools.lru_cache(maxsize=None)
def source_digest(packages: tuple[str, ...]) -> str:
    """SHA-256 over the ``*.py`` files of ``packages`` and their subpackages (paths
    and bytes): ~1 ms once per process.  The project version alone would hand stale
    results to an edited checkout."""
    h = hashlib.sha256()
    for pkg in packages:
        for path in sorted((_ROOT / pkg).rglob("*.py")):
            h.update(f"{path.relative_to(_ROOT).as_posix()}\0".encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def _code_packages(backend: str) -> tuple[str, ...]:
    # The analytic backends depend on analytic/ only; engines also read analytic/.
    return ("analytic",) if backend.startswith("analytic") else ("analytic", "engines")


@functools.lru_cache(maxsize=None)
def _engine_version(backend: str) -> str:
    from engines import get_backend
    module = get_backend(backend)
    return module.version() if hasattr(module, "version") else "unknown"


def settings_dict(settings) -> dict:
    """A backend Settings as a plain dict (its ``describe()`` when it has one)."""
    if hasattr(settings, "describe"):
        return _plain(settings.describe())
    return _plain(settings)


def excitation_dict(excitation) -> dict:
    """Type and every field (a SampledRecord's samples included, not its summary)."""
    return {"type": type(excitation).__name__, **_plain(dataclasses.asdict(excitation))}


def scene_dict(scene) -> dict:
    """Every Scene field but ``name`` (a label: it does not change a run)."""
    out = dataclasses.asdict(scene)
    out.pop("name", None)
    return out


def run_key(backend: str, scene, excitation, settings) -> str:
    """The store key of one backend run (``settings`` already resolved)."""
    return digest({"kind": "run", "backend": backend, "engine": _engine_version(backend),
                   "scene": scene_dict(scene), "excitation": excitation_dict(excitation),
                   "settings": settings_dict(settings), "project": project_version(),
                   "code": source_digest(_code_packages(backend))})


# -------------------------------------------------------------------------- store
class RunStore:
    """A directory holding ``runs.sqlite``; safe to share between processes.

    Parameters
    ----------
    directory : str or Path
        Created if missing.  ``ValueError`` if it cannot be, or if the file there
        is not a run store.

    Examples
    --------
    >>> import tempfile
    >>> store = RunStore(tempfile.mkdtemp())
    >>> store.put("k", {"x": 1.5}, kind="demo", label="demo", cost=0.0)
    >>> store.get("k")
    {'x': 1.5}
    """

    def __init__(self, directory) -> None:
        self.directory = Path(directory).expanduser()
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"--cache: cannot create the store directory "
                             f"{str(self.directory)!r} ({exc.strerror})") from None
        self.path = self.directory / DB_NAME
        self._conn = None
        self._pid = None
        self._connect()  # validate now, before any work

    def __getstate__(self):  # a connection does not cross processes: reopen there
        return {"directory": self.directory}

    def __setstate__(self, state):
        self.__init__(state["directory"])

    def __repr__(self) -> str:
        return f"RunStore({str(self.directory)!r})"

    def _connect(self) -> sqlite3.Connection:
        if self._conn is not None and self._pid == os.getpid():
            return self._conn
        # A forked child must not touch its parent's connection: open its own.
        try:
            conn = sqlite3.connect(self.path, timeout=BUSY_TIMEOUT_MS / 1000,
                                   isolation_level=None, check_same_thread=False)
            conn.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
            if conn.execute("PRAGMA journal_mode").fetchone()[0] != "wal":
                conn.execute("PRAGMA journal_mode=WAL")
            # WAL + NORMAL: a commit survives a killed process (not a power cut).
            conn.execute("PRAGMA synchronous=NORMAL")
            conn.execute(_SCHEMA)
        except sqlite3.DatabaseError as exc:
            raise ValueError(f"--cache: {str(self.path)!r} is not a usable run store "
                             f"({exc})") from None
        self._conn, self._pid = conn, os.getpid()
        return conn

    def get(self, key: str):
        """The stored value under ``key``, or None."""
        row = self._connect().execute("SELECT value FROM runs WHERE key = ?",
                                      (key,)).fetchone()
        return None if row is None else pickle.loads(row[0])

    def put(self, key: str, value, *, kind: str, label: str, cost: float) -> None:
        """Store ``value`` unless ``key`` is there already (same key: same result)."""
        blob = pickle.dumps(value, protocol=5)
        self.put_blob(key, blob, kind=kind, label=label, cost=cost)

    def put_blob(self, key: str, blob: bytes, *, kind: str, label: str, cost: float) -> None:
        self._connect().execute(
            "INSERT OR IGNORE INTO runs (key, kind, label, cost, created, value) "
            "VALUES (?, ?, ?, ?, ?, ?)", (key, kind, label, float(cost), time.time(), blob))

    def count(self, kind: str | None = None, since: float | None = None) -> int:
        """Entries (of ``kind``; created at or after ``since``, a ``time.time()``)."""
        sql, args = "SELECT COUNT(*) FROM runs WHERE 1", []
        if kind is not None:
            sql, args = sql + " AND kind = ?", [*args, kind]
        if since is not None:
            sql, args = sql + " AND created >= ?", [*args, since]
        return int(self._connect().execute(sql, args).fetchone()[0])

    def created(self) -> dict[str, float]:
        """Key -> creation time of every entry (tests: nothing was rewritten)."""
        return dict(self._connect().execute("SELECT key, created FROM runs").fetchall())

    def mean_costs(self, kind: str = "run") -> dict[str, tuple[float, int]]:
        """Label -> (mean cost [s], count) over the stored entries of ``kind``."""
        rows = self._connect().execute(
            "SELECT label, AVG(cost), COUNT(*) FROM runs WHERE kind = ? GROUP BY label",
            (kind,)).fetchall()
        return {label: (float(mean), int(n)) for label, mean, n in rows}

    def close(self) -> None:
        if self._conn is not None and self._pid == os.getpid():
            self._conn.close()
        self._conn = None
