"""Local worker processes for parallel maps (spectra, overturn maps, the run store's
``compare.run.runs.run_many``): forked, so they inherit the loaded kernels and engines;
deaf to Ctrl-C, which the parent handles; dead with their parent, even after a
``kill -9`` of it; and killed at once when the caller stops early.

Workers are started only when the work pays for them (:func:`pool_size`):
:func:`map_measured` runs the first item in the calling process, which loads
what the work needs before any fork and measures what one item costs.

Notes
-----
A worker forked from a process that has loaded everything costs about 14 ms
of CPU, its own and the parent's (fork, initializer, its share of the task
traffic, exit: ``pool_start_cpu_s`` of ``python -m benchmarks.bench_cli_cost``,
2 cores, load average 9); a worker that has to load the compiled kernels
itself costs 0.5-0.6 s (numba's import and its cache load).
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import resource
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed

__all__ = ["fork_pool", "init_worker", "pool_size", "map_measured", "cpu_seconds",
           "POOL_START_CPU_S", "PAYOFF"]

# CPU seconds one forked worker adds (child and parent) when the parent has loaded
# everything the work needs (module docstring, Notes).
POOL_START_CPU_S = 0.015
# A worker is started only for work worth this many times its start cost: the
# pool then adds at most 1/PAYOFF to the CPU time while it divides the wall time.
PAYOFF = 10.0


def cpu_seconds() -> float:
    """User + system CPU time of this process and its reaped children [s].

    A pool's workers are reaped when it shuts down, so the difference of two calls
    around a pooled map is the map's whole CPU, whatever the number of workers.
    """
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(
        resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


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


def pool_size(n_items: int, item_cpu_s: float, requested: int) -> int:
    """How many processes ``n_items`` items of ``item_cpu_s`` CPU seconds each are worth.

    ``w = floor(n_items * item_cpu_s / (PAYOFF * POOL_START_CPU_S))``, clipped to
    ``[1, min(requested, n_items)]``: each worker must take over at least
    ``PAYOFF`` times the CPU its start costs (:data:`POOL_START_CPU_S`), so the
    pool costs at most ``1/PAYOFF`` more CPU than one process would.  1 means
    no pool.  The number of workers never changes a result (callers place
    results by index).
    """
    if n_items <= 1 or requested <= 1:
        return 1
    work, start = n_items * max(item_cpu_s, 0.0), PAYOFF * POOL_START_CPU_S
    worth = n_items if start <= 0.0 else int(work / start)
    return max(1, min(requested, n_items, worth))


def map_measured(fn, items, workers: int, *, on_done=None) -> list:
    """``[fn(item) for item in items]``, in parallel when the work pays for it.

    Parameters
    ----------
    fn : callable
        A module-level function of one item (it is sent to forked workers).
    items : sequence
        In the order to run them; put the costliest first (e.g. the highest
        frequency of a spectrum).  ``items[0]`` runs here, before any fork: it
        loads whatever ``fn`` needs (compiled kernels, scipy), so the workers
        inherit it, and its CPU time is the cost per item that
        :func:`pool_size` turns into a number of workers (the costliest item
        makes that estimate err towards more workers; loading the caller did
        not do beforehand counts as cost too).
    workers : int
        The most processes to use (>= 1).
    on_done : callable, optional
        ``on_done(index, result)`` as each item finishes (in completion order).

    Returns
    -------
    list
        The results in the order of ``items``, whatever the number of workers.
    """
    items = list(items)
    out: list = [None] * len(items)
    if not items:
        return out
    t0 = time.process_time()
    out[0] = fn(items[0])
    cost = time.process_time() - t0
    if on_done is not None:
        on_done(0, out[0])
    n = pool_size(len(items) - 1, cost, workers)
    if n == 1:
        for i in range(1, len(items)):
            out[i] = fn(items[i])
            if on_done is not None:
                on_done(i, out[i])
        return out
    with fork_pool(n) as ex:
        futures = {ex.submit(fn, items[i]): i for i in range(1, len(items))}
        for fut in as_completed(futures):
            i = futures[fut]
            out[i] = fut.result()
            if on_done is not None:
                on_done(i, out[i])
    return out
