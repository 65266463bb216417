"""Local worker processes for parallel maps (spectra, overturn maps, the run store's
``compare.run.runs.run_many``): forked, so they inherit the loaded kernels and engines;
deaf to Ctrl-C, which the parent handles; dead with their parent, even after a
``kill -9`` of it; and killed at once when the caller stops early."""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor

__all__ = ["fork_pool", "init_worker"]


def _die_with_parent(parent_pid: int) -> None:
    if sys.platform.startswith("linux"):
        try:
            import ctypes
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(1, int(signal.SIGKILL), 0, 0, 0) == 0:  # 1 = PR_SET_PDEATHSIG
                if os.getppid() != parent_pid:  # the parent died before prctl
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="parent-watchdog").start()


def init_worker(parent_pid: int) -> None:
    """Process-pool initializer: ignore SIGINT, die with ``parent_pid``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent(parent_pid)


class _ForkPool(ProcessPoolExecutor):
    """Forks its workers with SIGINT blocked.  A Ctrl-C that lands during a fork
    would otherwise raise inside an at-fork handler (logging's lock release), where
    Python reports it as "Exception ignored" and drops it: the command ran on.
    Blocked, it stays pending and is raised in the caller once the fork is done."""

    def submit(self, *args, **kwargs):
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            return super().submit(*args, **kwargs)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def fork_pool(workers: int):
    """A forked :class:`ProcessPoolExecutor` of ``workers`` processes (see the module
    docstring).  Leaving the block normally waits for the work; leaving it by an
    exception (Ctrl-C, an error, a generator closed early) kills the workers now."""
    ex = _ForkPool(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                   initializer=init_worker, initargs=(os.getpid(),))
    finished = False
    try:
        yield ex
        finished = True
    finally:
        if finished:
            ex.shutdown(wait=True)
        else:
            # The executor has no public kill (3.14's terminate_workers); take its
            # processes before shutdown() forgets them, else exit waits for them.
            procs = list((getattr(ex, "_processes", None) or {}).values())
            for proc in procs:
                proc.kill()
            ex.shutdown(wait=False, cancel_futures=True)
            for proc in procs:
                proc.join(timeout=1.0)
