"""A hostile and careless user of the run store: another application's SQLite
file where the store should be, tampered and swapped entries, an older
version's store, a read-only store and one that cannot grow.

Refusals are one ``error:`` line and exit 2; a foreign file is never written,
pruned or deleted (the decoy folder is hashed before and after each case).
"""
from __future__ import annotations

import json
import os
import resource
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.run import store_db
from trilith_xval.compare.run.codec import encode
from trilith_xval.compare.run.store import DB_NAME, RunStore

from tests.support.hostile import decoy, read_only, refused, snapshot  # noqa: F401
from tests.support.paths import ROOT

SPECTRUM = ["spectrum", "--omega", "10,12", "--json"]


def spectrum(capsys, cache: Path) -> tuple[dict, str]:
    """``trilith spectrum`` on two frequencies: (its JSON without timings, stderr)."""
    code = main([*SPECTRUM, "--cache", str(cache)])
    out = capsys.readouterr()
    assert code == 0, out.err
    doc = json.loads(out.out)
    for key in ("timings", "wall_time"):
        doc.pop(key, None)
    return doc, out.err


# ---------------------------------------------------------------- foreign files
@pytest.mark.parametrize("argv", [["cache", "info"], ["cache", "prune"], ["cache", "clear"],
                                  ["cache", "verify"], SPECTRUM])
def test_a_foreign_sqlite_file_is_never_touched(argv, decoy, capsys):
    refused([*argv, "--cache", str(decoy)], capsys, "not a trilith-xval run store")


def _write_foreign(path: Path, case: str) -> None:
    path.parent.mkdir(mode=0o700, exist_ok=True)
    if case == "empty":
        path.write_bytes(b"")
    elif case == "garbage":
        path.write_bytes(os.urandom(4096))
    else:
        con = sqlite3.connect(path)
        if case == "other_app_id":  # our exact table, another program's marker
            con.execute("PRAGMA application_id = 1234")
            con.execute("CREATE TABLE runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, "
                        "label TEXT NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, "
                        "value BLOB NOT NULL, code TEXT NOT NULL DEFAULT '')")
        else:  # our legacy table plus another application's
            con.execute("CREATE TABLE runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, "
                        "label TEXT NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, "
                        "value BLOB NOT NULL)")
            con.execute("CREATE TABLE accounts (name TEXT)")
        con.commit()
        con.close()


@pytest.mark.parametrize("case", ["empty", "garbage", "other_app_id", "extra_tables"])
@pytest.mark.parametrize("action", ["info", "prune", "clear"])
def test_a_file_not_proven_ours_is_kept(case, action, tmp_path, capsys):
    db = tmp_path / "c" / DB_NAME
    _write_foreign(db, case)
    before = snapshot(tmp_path)
    refused(["cache", action, "--cache", str(db.parent)], capsys, "left untouched")
    assert snapshot(tmp_path) == before


def test_the_environment_is_named_when_it_chose_the_store(decoy, capsys, monkeypatch):
    monkeypatch.setenv("TRILITH_CACHE", str(decoy))
    line = refused(SPECTRUM, capsys, "TRILITH_CACHE")
    assert line.startswith("error: TRILITH_CACHE (") and "set TRILITH_CACHE" in line
    refused([*SPECTRUM, "--cache", ""], capsys, "--cache must name a directory")


# -------------------------------------------------------------- proven entries
def test_a_changed_digit_is_never_served(tmp_path, capsys):
    cache = tmp_path / "c"
    fresh, _ = spectrum(capsys, cache)
    value = fresh["a_no_pendulum"][0]
    con = sqlite3.connect(cache / DB_NAME)
    key, blob = con.execute("SELECT key, value FROM runs WHERE instr(value, ?) > 0",
                            (repr(value).encode(),)).fetchone()
    changed = repr(value)[:-1] + str((int(repr(value)[-1]) + 1) % 10)
    con.execute("UPDATE runs SET value = ? WHERE key = ?",
                (blob.replace(repr(value).encode(), changed.encode()), key))
    con.commit()
    con.close()
    assert main(["cache", "verify", "--cache", str(cache)]) == 1
    assert key[:16] in capsys.readouterr().out
    again, err = spectrum(capsys, cache)
    assert again == fresh  # recomputed, not the changed digit
    lines = [line for line in err.splitlines() if "digest" in line]
    assert len(lines) == 1 and key[:16] in lines[0], err
    assert main(["cache", "verify", "--cache", str(cache)]) == 0  # replaced
    capsys.readouterr()


def test_values_swapped_between_keys_are_never_served(tmp_path, capsys):
    cache = tmp_path / "c"
    fresh, _ = spectrum(capsys, cache)
    con = sqlite3.connect(cache / DB_NAME)
    (k1, v1, d1), (k2, v2, d2) = con.execute(
        "SELECT key, value, digest FROM runs WHERE kind = 'spectrum-point'").fetchall()
    con.execute("UPDATE runs SET value = ?, digest = ? WHERE key = ?", (v2, d2, k1))
    con.execute("UPDATE runs SET value = ?, digest = ? WHERE key = ?", (v1, d1, k2))
    con.commit()
    con.close()
    again, err = spectrum(capsys, cache)
    assert again == fresh
    assert sum("fails its digest check" in line for line in err.splitlines()) == 2, err


def test_an_older_stores_entries_are_recomputed_not_served(tmp_path):
    d = tmp_path / "old"
    d.mkdir(mode=0o700)
    con = sqlite3.connect(d / DB_NAME)
    con.execute("CREATE TABLE runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, label TEXT "
                "NOT NULL, cost REAL NOT NULL, created REAL NOT NULL, value BLOB NOT NULL, "
                "code TEXT NOT NULL DEFAULT '')")
    con.execute("INSERT INTO runs VALUES ('k', 'demo', 'demo', 0, 0, ?, '')",
                (encode({"x": 666.0}),))  # readable, but nothing proves it
    con.commit()
    con.close()
    store = RunStore(d)
    assert store.get("k") is None
    assert store.verify()[1][0][3].startswith("no digest")
    store.put("k", {"x": 1.0}, kind="demo", label="demo", cost=0.0)
    assert store.get("k") == {"x": 1.0} and store.verify() == (1, [])
    store.close()
    assert store_db.header_is_ours(d / DB_NAME) or store_db.identify(d / DB_NAME, 1) == "current"


# ------------------------------------------------------------ read-only stores
def test_an_intact_read_only_store_is_used_read_only(tmp_path, capsys):
    cache = tmp_path / "c"
    fresh, _ = spectrum(capsys, cache)
    RunStore(cache).close()
    before = snapshot(cache)
    with read_only(cache):
        again, err = spectrum(capsys, cache)
        assert again == fresh
        assert "cache clear" not in err and "not usable" not in err, err
        code = main(["spectrum", "--omega", "14", "--cache", str(cache)])
        err = capsys.readouterr().err
        assert code == 0 and "read-only" in err and "cache clear" not in err, err
        assert main(["cache", "verify", "--cache", str(cache)]) == 0
        refused(["cache", "prune", "--cache", str(cache)], capsys, "read-only")
        refused(["cache", "clear", "--cache", str(cache)], capsys, "read-only")
        assert snapshot(cache) == before


def test_a_store_that_cannot_grow_is_not_called_unusable(tmp_path, capsys):
    cache = tmp_path / "c"
    spectrum(capsys, cache)
    RunStore(cache).close()
    limit = (cache / DB_NAME).stat().st_size + 40_000  # the WAL index fits, not much more

    def cap():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", "spectrum", "--omega",
                           "10:30:1", "--cache", str(cache)], cwd=tmp_path, preexec_fn=cap,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr and "cache clear" not in proc.stderr, proc.stderr
    assert main(["cache", "verify", "--cache", str(cache)]) == 0  # what was kept is whole
    capsys.readouterr()
