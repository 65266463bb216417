"""Helpers of the hostile-user tests: snapshots, one-line refusals, a decoy folder
and a read-only view of a directory."""
from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
from pathlib import Path

import pytest

from trilith_xval.compare.cli.main import main

__all__ = ["snapshot", "refused", "tree_digest", "read_only", "make_decoy", "decoy"]


def snapshot(directory: Path) -> dict:
    """Every file and directory under ``directory`` with its bytes (files) and mode."""
    out = {}
    for p in sorted(directory.rglob("*")):
        st = p.lstat()
        out[str(p.relative_to(directory))] = (st.st_mode, p.read_bytes() if p.is_file() else None)
    return out


def tree_digest(directory: Path) -> str:
    """SHA-256 over every path, mode and file's bytes under ``directory``."""
    h = hashlib.sha256()
    for name, (mode, data) in snapshot(directory).items():
        h.update(f"{name}\0{mode:o}\0".encode())
        h.update(hashlib.sha256(data or b"").digest())
    return h.hexdigest()


def refused(argv, capsys, needle: str) -> str:
    """``trilith ARGV`` exits 2 with one ``error:`` line containing ``needle``
    (returned)."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert code == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ") and needle in lines[0], lines[0]
    assert "Traceback" not in err
    return lines[0]


@contextlib.contextmanager
def read_only(directory: Path):
    """``directory`` made read-only for this process: a read-only bind mount when
    running as root (chmod does not stop root), else ``chmod a-w``; skips the
    test when neither is possible."""
    if os.geteuid() == 0:
        proc = subprocess.run(["mount", "--bind", str(directory), str(directory)],
                              capture_output=True)
        if proc.returncode != 0:
            pytest.skip("running as root, and a read-only bind mount is not permitted "
                        "here (chmod would not stop root)")
        try:
            if subprocess.run(["mount", "-o", "remount,bind,ro", str(directory)],
                              capture_output=True).returncode != 0:
                pytest.skip("a read-only remount is not permitted here")
            yield directory
        finally:
            if subprocess.run(["umount", str(directory)]).returncode != 0:
                subprocess.run(["umount", "-l", str(directory)], check=True)
        return
    mode = directory.stat().st_mode
    files = {p: p.stat().st_mode for p in directory.iterdir()}
    for p in files:
        p.chmod(0o400)
    directory.chmod(0o500)
    try:
        yield directory
    finally:
        directory.chmod(mode)
        for p, m in files.items():
            p.chmod(m)


def make_decoy(directory: Path) -> Path:
    """A user's folder a careless command line may point at: notes, a PNG named
    like an output, and a SQLite file named like the run store (another
    application's tables)."""
    import sqlite3
    directory.mkdir(mode=0o700, parents=True, exist_ok=True)
    (directory / "notes.txt").write_text("my notes\n")
    (directory / "fragility.png").write_bytes(b"\x89PNG\r\n\x1a\n my own figure")
    (directory / "fragility.json").write_text('{"mine": true}\n')
    con = sqlite3.connect(directory / "runs.sqlite")
    # WAL, as the store's own: a careless reader would leave -wal/-shm files beside it.
    con.execute("PRAGMA journal_mode=WAL")
    con.execute("CREATE TABLE runs (id INTEGER PRIMARY KEY, payload TEXT)")
    con.execute("CREATE TABLE notes (x TEXT)")
    con.execute("INSERT INTO runs (payload) VALUES ('my data')")
    con.commit()
    con.close()
    return directory


@pytest.fixture
def decoy(tmp_path):
    """:func:`make_decoy` under ``tmp_path``, hashed before and after the test:
    the test fails if the case changed, added or removed anything in it."""
    folder = make_decoy(tmp_path / "decoy")
    before = tree_digest(folder)
    yield folder
    assert tree_digest(folder) == before, "the decoy folder was changed"
