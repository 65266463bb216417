"""A careless user's output folders: an existing folder of their own, a symlink,
refused runs that must leave nothing behind, lock files, file modes.

A decoy folder is hashed before and after each case that points at it; a
refused run leaves the working directory exactly as it was (no folder, no lock,
no temporary file).
"""
from __future__ import annotations

import os

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.run import atomic

from tests.support.hostile import decoy, make_decoy, refused, snapshot, tree_digest  # noqa: F401
from tests.system.test_fragility_cli import ARGS, write_suite


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_fragility_never_writes_into_a_users_folder(decoy, here, capsys):
    write_suite(here / "suite", n=1)
    refused(["fragility", "--records", "suite", "--out", str(decoy), "--no-cache", *ARGS],
            capsys, "--out")


@pytest.mark.parametrize("extra, needle", [
    (["--records", "missing"], "missing"),
    (["--records", "bad"], "bad"),
    (["--records", "suite", "--scheduler", "nonsense"], "--scheduler"),
    (["--records", "suite", "--engine", "nosuch"], "--engine"),
])
def test_a_refused_fragility_run_leaves_nothing(extra, needle, here, capsys):
    write_suite(here / "suite", n=2)
    (here / "bad").mkdir()
    (here / "bad" / "r.csv").write_text("t,a\n0,x\n")
    before = snapshot(here)
    refused(["fragility", *extra, "--out", "new", "--no-cache", *ARGS], capsys, needle)
    assert snapshot(here) == before  # no 'new' folder, no new.lock, no .new.tmp-*


def test_fragility_output_is_whole_marked_and_lock_free(here, capsys):
    write_suite(here / "suite", n=2)
    argv = ["fragility", "--records", "suite", "--out", "o", "--no-cache", *ARGS]
    assert main(argv) == 0, capsys.readouterr().err
    names = sorted(p.name for p in here.iterdir())
    assert names == ["o", "suite"], names  # no o.lock, no temporary
    assert (here / "o" / atomic.MARKER).is_file()
    assert main(argv) == 0  # its own folder: replaced whole
    assert sorted(p.name for p in here.iterdir()) == ["o", "suite"]
    capsys.readouterr()


def test_report_out_on_a_symlink_is_refused_at_the_door(here, capsys):
    (here / "target").mkdir()
    (here / "link").symlink_to("target")
    before = snapshot(here)
    refused(["report", "--quick", "--out", "link"], capsys, "--out 'link' is a symbolic link")
    assert snapshot(here) == before


def test_a_lock_file_is_removed_but_a_users_is_kept(here):
    with atomic.output_lock(here / "out") as lock:
        assert lock.read_text() == atomic.LOCK_TEXT
        with pytest.raises(ValueError, match="--out .* another process"):
            with atomic.output_lock(here / "out"):
                pass
    assert not lock.exists()
    (here / "mine.lock").write_text("my own notes")
    with atomic.output_lock(here / "mine"):
        pass
    assert (here / "mine.lock").read_text() == "my own notes"


def test_rewriting_an_output_keeps_its_mode(here, capsys):
    argv = ["simulate", "-A", "25", "-w", "11", "--csv", "t.csv"]
    assert main(argv) == 0
    os.chmod("t.csv", 0o640)
    assert main(argv) == 0
    assert os.stat("t.csv").st_mode & 0o777 == 0o640
    capsys.readouterr()


def test_a_failed_locked_build_leaves_no_folder(here):
    with pytest.raises(RuntimeError):
        with atomic.output_lock(here / "a" / "b" / "out"):
            assert (here / "a" / "b").is_dir()
            raise RuntimeError("the campaign failed")
    assert list(here.iterdir()) == []
    with pytest.raises(RuntimeError):
        with atomic.report_dir(here / "y" / "r"):
            raise RuntimeError("the report failed")
    assert list(here.iterdir()) == []
    with atomic.report_dir(here / "x" / "r") as tmp:  # success: the folders stay
        (tmp / "f.txt").write_text("1")
    assert (here / "x" / "r" / "f.txt").is_file() and not (here / "x" / "r.lock").exists()


@pytest.mark.parametrize("argv", [["figures", "--quick"], ["bench", "--quick"]])
def test_shared_folders_never_overwrite_a_users_file(argv, tmp_path, capsys):
    folder = make_decoy(tmp_path / "mine")
    (folder / "fig5.png").write_bytes(b"mine")
    (folder / "workprecision.json").write_text("{}")
    before = tree_digest(folder)
    refused([*argv, "--out", str(folder)], capsys, f"--out {str(folder)!r}:")
    assert tree_digest(folder) == before


def test_a_refused_figures_run_creates_no_folder(here, capsys):
    refused(["figures", "--out", "new", "--dpi", "10"], capsys, "--dpi")
    assert list(here.iterdir()) == []


def test_files_recorded_as_ours_are_rewritten(here):
    atomic.record_into(here / "f", ["a.png"])
    (here / "f" / "a.png").write_text("old")
    atomic.check_into(here / "f", ["a.png", "b.png"])  # ours, and a missing one
    (here / "f" / "c.png").write_text("mine")
    with pytest.raises(ValueError, match="--out .*c.png exists and this tool did not"):
        atomic.check_into(here / "f", ["c.png"])


def test_a_whole_output_of_an_older_version_is_rewritten_a_part_is_not(here):
    names = ["a.json", "b.png"]
    (here / "old").mkdir()
    for name in names:
        (here / "old" / name).write_text("from before the manifest")
    atomic.check_into(here / "old", names)  # exactly an earlier output: ours
    (here / "part").mkdir()
    (here / "part" / "b.png").write_text("mine")
    with pytest.raises(ValueError, match="b.png exists"):
        atomic.check_into(here / "part", names)
