"""A hostile and careless user: files, options, outputs, the run store, signals, Dask.

Every refusal is checked for its exact exit code (2), a single ``error:`` line
naming the file and key or the option, and that nothing outside the tool's own
outputs changed (a snapshot of the working directory before and after).  Cases
run in process (``compare.cli.main.main``) unless they need a real stdout, a
signal or a mount.
"""
from __future__ import annotations

import os
import pickle
import shutil
import socket
import sqlite3
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.run import atomic, runs
from trilith_xval.compare.run.store import DB_NAME, RunStore

from tests.support.hostile import refused, snapshot
from tests.support.paths import ROOT
TRILITH = [sys.executable, "-m", "trilith_xval.compare.cli.main"]


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A scratch working directory; the test fails if anything in it changes
    that the case did not expect (checked by the cases via :func:`snapshot`)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


# ---------------------------------------------------------------------- files
SCENE_FILES = {
    "huge_int": ("[scene]\nb = " + "9" * 400 + "\n", "key 'b' must be a finite number"),
    "deep": ("[scene]\nb = " + "[" * 200_000 + "]" * 200_000 + "\n", "nesting too deep"),
    "string": ('[scene]\nb = "wide"\n', "key 'b' must be a number"),
    "binary": (b"\xff\xfe\x00[scene]", "not a UTF-8 text file"),
    "two_tables": ("[scene]\nb = 0.6\n[other]\nx = 1\n", "exactly one [scene] table"),
}


@pytest.mark.parametrize("case", sorted(SCENE_FILES))
def test_scene_file_refused(case, here, capsys):
    text, needle = SCENE_FILES[case]
    path = here / f"{case}.toml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    before = snapshot(here)
    refused(["simulate", "-A", "25", "-w", "11", "--scene", str(path)], capsys, needle)
    assert snapshot(here) == before


@pytest.mark.parametrize("scene, needle", [("/proc/self/mem", "cannot be read"),
                                           ("/dev/null", "not a regular file"),
                                           ("x" * 5000, "scene"),
                                           (".", "is a directory")])
def test_special_scene_paths_refused(scene, needle, here, capsys):
    refused(["simulate", "-A", "25", "-w", "11", "--scene", scene], capsys, needle)


CAMPAIGN = '[campaign]\nscenes = ["fig5"]\nengines = ["pymunk"]\nomega = "10"\n'
CAMPAIGN_FILES = {
    "nested_steps": (CAMPAIGN + "steps = [[1e-4]]\n", "campaign.steps must be a number"),
    "text_tol": (CAMPAIGN + 'rel_tol = "small"\n', "campaign.rel_tol must be a number"),
    "huge_tol": (CAMPAIGN + "rel_tol = " + "1" * 400 + "\n", "integer of 400 digits"),
    "omega_table": ('[campaign]\nscenes = ["fig5"]\nengines = ["pymunk"]\nomega = {a = 1}\n',
                    "campaign.omega must be"),
    "escape": (CAMPAIGN + 'name = "x/../../../elsewhere/docs"\n', "campaign.name must be"),
    "hidden": (CAMPAIGN + 'name = ".."\n', "campaign.name must be"),
    "tiny_step": (CAMPAIGN + "steps = [1e-9]\n", "campaign.steps: a pymunk run"),
    "no_table": ("x = 1\n", "a [campaign] table is needed"),
    "huge_workers": (CAMPAIGN + "workers = " + "9" * 400 + "\n", "campaign.workers must be"),
    "bool_workers": (CAMPAIGN + "workers = true\n", "campaign.workers must be"),
}


@pytest.mark.parametrize("case", sorted(CAMPAIGN_FILES))
@pytest.mark.parametrize("estimate", [False, True])
def test_campaign_file_refused(case, estimate, here, capsys):
    text, needle = CAMPAIGN_FILES[case]
    (here / "c.toml").write_text(text)
    before = snapshot(here)
    refused(["campaign", "c.toml", *(["--estimate"] if estimate else [])], capsys, needle)
    assert snapshot(here) == before  # no campaign-* folder, no lock file


@pytest.mark.parametrize("path, needle", [(".", "is not a regular file"),
                                          ("/proc/self/mem", "cannot be read"),
                                          ("missing.toml", "does not exist")])
def test_campaign_path_refused(path, needle, here, capsys):
    refused(["campaign", path], capsys, needle)


def test_record_with_bom_keeps_its_first_sample(here, capsys):
    (here / "r.csv").write_bytes(b"\xef\xbb\xbf0.0,5.0\n0.1,5.0\n0.2,0\n0.3,0\n")
    assert main(["simulate", "--record", "r.csv", "--json"]) == 0
    import json
    doc = json.loads(capsys.readouterr().out)
    assert doc["inputs"]["excitation"]["n_samples"] == 4


# -------------------------------------------------------------------- options
@pytest.mark.parametrize("argv, needle", [
    (["simulate", "-A", "twenty", "-w", "11"], "-A/--amplitude: 'twenty' is not an acceleration"),
    (["spectrum", "--omega", "10", "--workers", "1.5"], "--workers: invalid int value"),
    (["figures", "--format", "exe"], "--format: invalid choice"),
    (["nonsense"], "invalid choice"),
    (["spectrum", "--omega", "10", "--engine", "pymunk", "--dt", "1e-9"], "--dt: a pymunk run"),
    (["spectrum", "--omega", "0.1", "--engine", "pymunk", "--dt", "5e-5", "--convergence"],
     "--dt (with --convergence: dt/4)"),
    (["report", "--quick", "--dt", "1e-5", "--out", "r"], "--dt: a pybullet run"),
    (["calibrate", "--engine", "pymunk", "--dt", "1e-9"], "--dt: a pymunk run"),
    (["calibrate", "--engine", "pymunk", "--dt", "-1"], "each step must be in (0, 0.1] s"),
    (["calibrate", "--engine", "pymunk", "--omega", ""], "--omega must be a comma-separated"),
    (["calibrate", "--engine", "pymunk", "--tolerance", "5"], "--tolerance must be in (0, 1]"),
    (["fragility", "--records", "sample", "--rel-step", "50"], "--rel-step must be in (0, 10]"),
    (["fragility", "--records", "sample", "--tail", "1000"], "--tail must be in (0, 600]"),
    (["fragility", "--records", "sample", "--rtol", "0.5", "--rel-step", "0.2"],
     "--rtol (0.5) must be below --rel-step"),
    (["spectrum", "--omega", "10", "--cache", ""], "--cache must name a directory"),
])
def test_option_refused_in_one_line(argv, needle, here, capsys):
    before = snapshot(here)
    refused(argv, capsys, needle)
    assert snapshot(here) == before


@pytest.mark.parametrize("argv, step", [
    (["calibrate", "--engine", "pymunk"], "0.09"),
    (["report", "--quick", "--engine", "pymunk", "--out", "r"], "1e-7"),
    (["spectrum", "--engine", "pymunk", "--omega", "10"], "1e-7"),
])
def test_a_step_from_a_settings_file_is_blamed_on_the_file(argv, step, here, capsys):
    (here / "s.toml").write_text(f"[pymunk]\ndt = {step}\n")
    before = snapshot(here)
    line = refused([*argv, "--settings", "s.toml"], capsys, "--settings 's.toml'")
    assert "--dt" not in line
    assert snapshot(here) == before


# -------------------------------------------------------------------- outputs
def test_report_never_deletes_a_users_folder(here, capsys):
    (here / "v" / "src").mkdir(parents=True)
    (here / "v" / "src" / "main.py").write_text("code\n")
    before = snapshot(here)
    refused(["report", "--quick", "--out", "v"], capsys, "holds files this tool did not write")
    assert snapshot(here) == before


@pytest.mark.parametrize("command", [["report", "--quick"], ["campaign", "c.toml"]])
@pytest.mark.parametrize("out", [".", "..", "/"])
def test_working_directory_is_not_an_output(command, out, here, capsys):
    (here / "c.toml").write_text(CAMPAIGN)
    before = snapshot(here)
    needle = "working directory" if out != "/" else "--out"
    refused([*command, "--out", out], capsys, needle)
    assert snapshot(here) == before


def test_campaign_out_on_a_read_only_filesystem(here, capsys, tmp_path_factory):
    (here / "c.toml").write_text(CAMPAIGN)
    refused(["campaign", "c.toml", "--out", "/proc/trilith-out"], capsys, "--out")


@pytest.mark.parametrize("option, suffix", [("--csv", ".csv"), ("--plot", ".png")])
def test_output_name_too_long_for_its_temporary_name(option, suffix, here, capsys):
    name = "x" * (255 - len(suffix)) + suffix  # legal, but .NAME.tmp-XXXXXXXX is not
    refused(["simulate", "-A", "25", "-w", "11", option, name], capsys, "temporary name")
    assert list(here.iterdir()) == []


def test_report_dir_replaces_only_its_own_directories(tmp_path):
    out = tmp_path / "r"
    with atomic.report_dir(out) as tmp:
        (tmp / "a.txt").write_text("1")
    assert (out / atomic.MARKER).is_file()
    with atomic.report_dir(out) as tmp:  # its own: replaced whole
        (tmp / "b.txt").write_text("2")
    assert sorted(p.name for p in out.iterdir()) == sorted([atomic.MARKER, "b.txt",
                                                             ]) and not (out / "a.txt").exists()
    (out / atomic.MARKER).unlink()
    with pytest.raises(ValueError, match="did not write"):
        with atomic.report_dir(out):
            pass
    assert (out / "b.txt").read_text() == "2"


def test_killed_build_is_cleaned_by_the_next(tmp_path):
    """kill -9 inside the build leaves .r.tmp-*; the next build of r removes it, and
    leaves a user's look-alike folder (no marker, not empty) alone."""
    code = ("import os, sys\nfrom trilith_xval.compare.run import atomic\n"
            "with atomic.report_dir(sys.argv[1]) as tmp:\n"
            "    (tmp / 'half.txt').write_text('x')\n    os.kill(os.getpid(), 9)\n")
    out = tmp_path / "r"
    proc = subprocess.run([sys.executable, "-c", code, str(out)], cwd=ROOT)
    assert proc.returncode == -9
    stale = list(tmp_path.glob(".r.tmp-*"))
    assert len(stale) == 1 and (stale[0] / "half.txt").exists()
    users = tmp_path / ".r.tmp-mine"
    users.mkdir()
    (users / "keep.txt").write_text("mine")
    with atomic.report_dir(out) as tmp:
        (tmp / "whole.txt").write_text("y")
    assert not stale[0].exists() and (users / "keep.txt").read_text() == "mine"
    assert (out / "whole.txt").exists()


def _trilith(args: str, tmp_path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(["sh", "-c", f"{sys.executable} -m compare.cli.main {args}"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("redirect, needle", [("> /dev/full", "No space left on device"),
                                              (">&-", "standard output is closed")])
def test_full_or_closed_stdout(redirect, needle, tmp_path):
    proc = _trilith(f"scenes {redirect}", tmp_path)
    lines = proc.stderr.splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and needle in lines[0], proc.stderr


def fill(path: Path) -> None:
    """Write zeros to ``path`` until the filesystem is full."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND)
    try:
        for size in (4096, 512, 1):
            try:
                while True:
                    os.write(fd, b"\0" * size)
            except OSError:
                pass
    finally:
        os.close(fd)


@pytest.fixture
def full_disk(tmp_path):
    """A 64 kB tmpfs filled to the last byte (root only)."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if os.geteuid() != 0 or subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=64k,mode=0700", "tmpfs", str(mnt)],
            capture_output=True).returncode != 0:
        pytest.skip("needs root to mount a small tmpfs")
    try:
        fill(mnt / "filler")
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], check=True)


@pytest.mark.parametrize("option, name", [("--csv", "t.csv"), ("--plot", "t.png")])
def test_full_disk_while_writing(option, name, full_disk, here, capsys):
    """The door's probe may pass (a file of zero bytes fits); the write then fails:
    one line, exit 2, and no half-written or temporary file left."""
    before = snapshot(full_disk)
    try:
        code = main(["simulate", "-A", "25", "-w", "11", option, str(full_disk / name)])
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: "), err
    assert snapshot(full_disk) == before


# ---------------------------------------------------------------------- store
class _Planted:
    def __reduce__(self):
        return (os.system, (f"touch {self.flag}",))


def test_a_pickled_row_is_never_run(tmp_path, fig5):
    store = RunStore(tmp_path / "c")
    store.put("k", 1, kind="demo", label="demo", cost=0.0)  # creates the database
    planted = _Planted()
    planted.flag = tmp_path / "ran"
    store.put_blob("evil", pickle.dumps(planted), kind="demo", label="demo", cost=0.0)
    assert store.get("evil") is None and not planted.flag.exists()
    store.put("evil", {"x": 2.0}, kind="demo", label="demo", cost=0.0)  # replaced
    assert store.get("evil") == {"x": 2.0}
    store.close()


def test_the_store_is_created_private_and_only_when_used(tmp_path, capsys, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv("TRILITH_CACHE", str(cache))
    with pytest.raises(SystemExit):
        main(["spectrum", "--help"])
    assert main(["spectrum", "--omega", "-1"]) == 2
    assert not cache.exists()
    assert main(["spectrum", "--omega", "10"]) == 0
    assert cache.stat().st_mode & 0o777 == 0o700
    capsys.readouterr()


def test_a_store_others_may_write_is_refused(tmp_path, capsys):
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    refused(["spectrum", "--omega", "10", "--cache", str(shared)], capsys,
            "writable by other users")
    if os.geteuid() == 0:
        theirs = tmp_path / "theirs"
        theirs.mkdir(mode=0o700)
        os.chown(theirs, 65534, 65534)
        refused(["spectrum", "--omega", "10", "--cache", str(theirs)], capsys,
                "belongs to another user")


def _filled_store(directory: Path) -> Path:
    store = RunStore(directory)
    for i in range(200):
        store.put(f"k{i}", {"i": i, "pad": "x" * 500}, kind="demo", label="demo", cost=0.0)
    store.close()
    return directory / DB_NAME


def test_a_damaged_store_is_refused_in_one_line(tmp_path, capsys):
    db = _filled_store(tmp_path / "c")
    con = sqlite3.connect(db)
    con.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    con.close()
    data = bytearray(db.read_bytes())
    data[4096:4096 * 8] = b"\xa5" * (4096 * 7)  # every page after the first
    db.write_bytes(bytes(data))
    refused(["spectrum", "--omega", "10", "--cache", str(tmp_path / "c")], capsys,
            "trilith cache clear")
    assert main(["cache", "clear", "--cache", str(tmp_path / "c")]) == 0  # the cure works
    assert not db.exists()


def test_a_foreign_runs_table_is_refused(tmp_path, capsys):
    (tmp_path / "c").mkdir(mode=0o700)
    con = sqlite3.connect(tmp_path / "c" / DB_NAME)
    con.execute("CREATE TABLE runs (id INTEGER, payload TEXT)")
    con.commit()
    con.close()
    refused(["spectrum", "--omega", "10", "--cache", str(tmp_path / "c")], capsys,
            "not a run store's")


def test_full_disk_under_the_store_still_returns_results(full_disk, capsys):
    store_dir = full_disk / "store"
    (full_disk / "filler").unlink()
    store_dir.mkdir(mode=0o700)
    fill(full_disk / "filler")  # no room left for the database
    code = main(["spectrum", "--omega", "10", "--cache", str(store_dir), "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert '"a_pendulum"' in captured.out
    warnings = [line for line in captured.err.splitlines() if "disk is full" in line]
    assert len(warnings) <= 1  # at most once, however many results were not kept


def test_cache_info_prune_clear(tmp_path, capsys):
    directory = tmp_path / "c"
    _filled_store(directory)
    (directory / "notes.txt").write_text("mine")
    assert main(["cache", "info", "--cache", str(directory)]) == 0
    assert "200 entries" in capsys.readouterr().out
    assert main(["cache", "prune", "--cache", str(directory)]) == 0  # code '' is old
    assert "200 entries removed" in capsys.readouterr().out
    assert RunStore(directory).count() == 0
    assert main(["cache", "clear", "--cache", str(directory)]) == 0
    assert sorted(p.name for p in directory.iterdir()) == ["notes.txt"]


# -------------------------------------------------------------------- signals
def test_ctrl_c_is_one_line(monkeypatch, capsys, here):
    import trilith_xval.compare.cli.scenes as scenes_cli

    def interrupted(args):
        raise KeyboardInterrupt
    monkeypatch.setattr(scenes_cli, "run", interrupted)
    assert main(["scenes"]) == 130
    assert capsys.readouterr().err.splitlines() == ["interrupted: cancelled"]


# ----------------------------------------------------------------------- Dask
def test_scheduler_address_that_is_not_a_scheduler(monkeypatch, capsys, here):
    """A listener that accepts and never answers: refused within the stated wait."""
    monkeypatch.setattr(runs, "CONNECT_TIMEOUT_S", 2.0)
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(8)
    port = server.getsockname()[1]
    held = []
    stop = threading.Event()

    def accept():
        server.settimeout(0.2)
        while not stop.is_set():
            try:
                held.append(server.accept()[0])
            except OSError:
                pass
    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    try:
        refused(["spectrum", "--omega", "10", "--scheduler", f"tcp://127.0.0.1:{port}"],
                capsys, "no Dask scheduler")
    finally:
        stop.set()
        thread.join()
        for conn in held:
            conn.close()
        server.close()


def test_a_cluster_without_workers_is_reported(monkeypatch):
    distributed = pytest.importorskip("distributed")
    monkeypatch.setattr(runs, "NO_WORKERS_TIMEOUT_S", 3.0)
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=":0",
                                  silence_logs=40) as cluster:
        with pytest.raises(runs.NoWorkers, match="no worker for 3 s"):
            list(runs.run_many(abs, [-1, -2], scheduler=cluster.scheduler_address))


def test_a_report_from_before_the_marker_is_replaced_but_not_a_look_alike(tmp_path):
    old = tmp_path / "old"
    old.mkdir()
    for name in ("index.html", "summary.json", "summary.md"):
        (old / name).write_text("earlier report")
    atomic.check_replaceable(old)  # exactly what an earlier report wrote
    (old / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="did not write"):
        atomic.check_replaceable(old)
