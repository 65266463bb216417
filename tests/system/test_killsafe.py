"""Kill safety of ``trilith campaign`` (resume after SIGKILL, no orphan workers,
prompt Ctrl-C) and of ``trilith map``'s own process pools (no orphans, prompt
Ctrl-C).  Each test runs the CLI in a subprocess of its own session (so the
whole process group can be inspected and cleaned up) on a tiny Pymunk study:
coarse 5e-4 s steps, ~0.1 s of CPU per run.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from trilith_xval.compare.run.store import RunStore

from tests.support.paths import ROOT
# Liveness bound for anything we wait on (a kill taking effect, an exit after
# Ctrl-C).  Not a speed claim: cancellation acts within run_many's 0.2 s poll and
# workers are killed at once; the rest is interpreter shutdown, measured at
# 0.5-2 s on the loaded 2-core machine.  10 s leaves room for CI load, and a hang
# (the bug this guards against: Ctrl-C waiting for the whole computation) fails.
LIVENESS_S = 10.0

# A progress line on a pipe (compare.run.progress.Lines): 'desc: done/total unit, N s'.
PROGRESS = re.compile(r"^[\w .-]+: [\d.]+/[\d.]+( [\w .]+)?, \d+ s$")

STUDY = """
[campaign]
name = "tiny"
scenes = ["fig8_lam5_gamma0.3"]
engines = ["pymunk"]
omega = {omega}
steps = [0.0005]
cases = ["pendulum"]
"""


def _study(tmp_path: Path, omega: str = "[10.0, 16.0]") -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(STUDY.format(omega=omega))
    return path


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "trilith_xval.compare.cli.main", *args]


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _sigint_as_a_terminal_gives_it() -> None:
    """In the child before exec: SIGINT at its default and unblocked.  An ignored
    or blocked SIGINT is inherited across exec (and Python keeps an ignored one):
    a non-interactive shell ignores SIGINT in every command it starts with '&', so
    a test suite launched in the background would start a CLI that can never see
    Ctrl-C.  A terminal's foreground job always starts with it default."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _warn_if_this_process_hides_sigint() -> None:
    # E.g. `make test &` from a script: say so in the test log, since the CLI's
    # own reaction to Ctrl-C is then tested only thanks to the restore above.
    ignored = signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    blocked = signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])
    if ignored or blocked:
        import warnings
        warnings.warn(f"SIGINT is {'ignored' if ignored else 'blocked'} in this test process "
                      f"(pid {os.getpid()}); the CLI under test is started with it restored")


def _start(args: list[str]) -> subprocess.Popen:
    _warn_if_this_process_hides_sigint()
    # Own session: its pid is the process group id of everything it starts.
    return subprocess.Popen(_cli(*args), cwd=ROOT, env=_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_sigint_as_a_terminal_gives_it)


def _group(pgid: int) -> list[int]:
    """Live (non-zombie) processes whose process group is ``pgid``."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # after "pid (comm) "
        if int(fields[2]) == pgid and fields[0] != "Z":
            pids.append(int(entry))
    return pids


def _children(pid: int) -> list[int]:
    return [p for p in _group(pid) if p != pid]


def _wait_for(predicate, what: str, timeout: float = 120.0) -> None:
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


def _state(pid: int) -> str:
    """What the kernel says a process is doing (state, where it sleeps, its
    pending, blocked, ignored and caught signals), for a failure message."""
    try:
        status = Path(f"/proc/{pid}/status").read_text().splitlines()
        wchan = Path(f"/proc/{pid}/wchan").read_text()
    except OSError as exc:
        return f"pid {pid}: {exc}"
    keep = ("State", "SigPnd", "ShdPnd", "SigBlk", "SigIgn", "SigCgt", "Threads")
    return f"pid {pid} wchan={wchan} " + " ".join(
        line.replace("\t", "") for line in status if line.split(":")[0] in keep)


def _exit_after_ctrl_c(proc: subprocess.Popen) -> str:
    """Send Ctrl-C to ``proc``'s group as a terminal does; its stderr once it
    exits.  Still running after :data:`LIVENESS_S`: fail with what the kernel
    says the parent and its workers were doing, and the machine's load."""
    os.killpg(proc.pid, signal.SIGINT)
    try:
        return proc.communicate(timeout=LIVENESS_S)[1]
    except subprocess.TimeoutExpired:
        states = "; ".join(_state(pid) for pid in [proc.pid, *_children(proc.pid)])
        raise AssertionError(f"no exit {LIVENESS_S:g} s after Ctrl-C (load average "
                             f"{os.getloadavg()}): {states}") from None


def _runs(cache: Path) -> int:
    db = cache / "runs.sqlite"
    return RunStore(cache).count("run") if db.exists() else 0


def _cleanup(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=LIVENESS_S)
    for pid in _group(proc.pid):
        os.kill(pid, signal.SIGKILL)


def _strip(obj):
    """campaign.json without its costs (the only numbers a rerun may change: wall and
    CPU seconds, and whether the run store served a row)."""
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items()
                if k not in ("wall_time", "cpu_s", "cpu_s_spent", "from_store")}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_resume_after_sigkill(tmp_path):
    study = _study(tmp_path)
    # The uninterrupted run: reference output and the number of runs it stores.
    cold = subprocess.run(_cli("campaign", str(study), "--workers", "1", "--cache",
                               str(tmp_path / "c1"), "--out", str(tmp_path / "o1")),
                          cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=600)
    assert cold.returncode == 0, cold.stderr
    n_total = RunStore(tmp_path / "c1").count()
    # The same, killed once a few engine runs are stored.
    cache = tmp_path / "c2"
    proc = _start(["campaign", str(study), "--workers", "1", "--cache", str(cache),
                   "--out", str(tmp_path / "o2")])
    try:
        _wait_for(lambda: _runs(cache) >= 3 or proc.poll() is not None, "3 stored runs")
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate(timeout=LIVENESS_S)
    finally:
        _cleanup(proc)
    assert proc.returncode == -signal.SIGKILL
    before = RunStore(cache).created()
    assert 0 < len(before) < n_total, "killed mid-run: some runs done, not all"
    assert not (tmp_path / "o2").exists()  # no half report
    rerun = subprocess.run(_cli("campaign", str(study), "--workers", "1", "--cache",
                                str(cache), "--out", str(tmp_path / "o2")),
                           cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=600)
    assert rerun.returncode == 0, rerun.stderr
    computed = int(re.search(r"(\d+) computed", rerun.stderr).group(1))
    after = RunStore(cache).created()
    assert computed == n_total - len(before) == len(after) - len(before)
    assert all(after[k] == t for k, t in before.items())  # finished runs not redone
    out1 = json.loads((tmp_path / "o1" / "campaign.json").read_text())
    out2 = json.loads((tmp_path / "o2" / "campaign.json").read_text())
    assert _strip(out1) == _strip(out2)


def _start_busy_campaign(tmp_path: Path, cache: Path) -> subprocess.Popen:
    """A two-worker campaign, returned once both workers exist and a run is stored."""
    proc = _start(["campaign", str(_study(tmp_path, '"6:26:1"')), "--workers", "2",
                   "--cache", str(cache), "--out", str(tmp_path / "o")])
    try:
        _wait_for(lambda: len(_children(proc.pid)) >= 2 and _runs(cache) >= 1
                  or proc.poll() is not None, "two busy workers")
    except BaseException:
        _cleanup(proc)
        raise
    return proc


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_die_with_their_parent(tmp_path):
    cache = tmp_path / "c"
    proc = _start_busy_campaign(tmp_path, cache)
    try:
        assert proc.poll() is None, "finished before it could be killed"
        os.kill(proc.pid, signal.SIGKILL)  # the parent only, as the OOM killer would
        proc.communicate(timeout=LIVENESS_S)
        _wait_for(lambda: not _group(proc.pid), "the orphaned workers to exit",
                  timeout=LIVENESS_S)
    finally:
        _cleanup(proc)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_ctrl_c_cancels_promptly_with_one_line(tmp_path):
    cache = tmp_path / "c"
    proc = _start_busy_campaign(tmp_path, cache)
    try:
        assert proc.poll() is None, "finished before Ctrl-C"
        n_runs = _runs(cache)
        t0 = time.monotonic()
        err = _exit_after_ctrl_c(proc)
        took = time.monotonic() - t0
        assert proc.returncode == 130
        # The plan line printed at the start, then exactly one line: no traceback.
        lines = [ln for ln in err.splitlines() if ln.strip() and not PROGRESS.match(ln)]
        assert lines[0].startswith("campaign tiny:"), err
        assert len(lines) == 2 and lines[1].startswith("interrupted"), err
        # Killed workers may take a moment to be reaped after the parent exits.
        _wait_for(lambda: not _group(proc.pid), "the killed workers to exit",
                  timeout=LIVENESS_S)
        assert took < LIVENESS_S
        # The work was cancelled, not finished: far fewer runs than the study needs
        # (21 frequencies x ~6 runs).
        assert _runs(cache) < n_runs + 10
    finally:
        _cleanup(proc)


# An engine map long enough to be interrupted: 9 x 10 Pymunk cells (~0.1 s each).
MAP = ["map", "--omega", "3:20:1", "--amplitude", "1:40:1", "--engine", "pymunk",
       "--engine-omega", "4:20:2", "--engine-amplitude", "2:38:4", "--max-engine-runs", "300",
       "--workers", "2"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("how", ["kill -9 of the parent", "Ctrl-C"])
def test_map_workers_stop_with_the_parent(how):
    proc = _start(MAP)
    try:
        _wait_for(lambda: len(_children(proc.pid)) >= 2 or proc.poll() is not None,
                  "two map workers")
        assert proc.poll() is None, "finished before it could be stopped"
        t0 = time.monotonic()
        if how == "Ctrl-C":
            err = _exit_after_ctrl_c(proc)
            assert proc.returncode == 130
            lines = [ln for ln in err.splitlines() if ln.strip() and not PROGRESS.match(ln)]
            assert len(lines) == 1 and lines[0].startswith("interrupted"), err
        else:
            os.kill(proc.pid, signal.SIGKILL)
            proc.communicate(timeout=LIVENESS_S)
        _wait_for(lambda: not _group(proc.pid), "the map workers to exit", timeout=LIVENESS_S)
        assert time.monotonic() - t0 < LIVENESS_S
    finally:
        _cleanup(proc)
