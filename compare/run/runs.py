"""The one place compare/ asks for a run, and the one parallel map it uses.

:func:`simulate` looks a backend run up in the active :class:`~compare.run.store.RunStore`
and otherwise runs it and stores it; :func:`memo` does the same for any other
result that costs more than a lookup (an analytic threshold point, a whole
engine threshold bisection).  With no active store (the library default; the CLI
activates one unless ``--no-cache``) both just compute.

:func:`run_many` maps a function over items in local worker processes or on a
Dask distributed cluster; results come back in submission order, so no number
depends on scheduling, and every worker uses the same store as the caller.

Local workers come from :func:`analytic._workers.fork_pool`: forked (they inherit
the imported engines and the compiled numba kernels: no second import of ~1 s
per worker), deaf to SIGINT (Ctrl-C is the parent's to handle, so a terminal
shows one line, not one traceback per worker), dead with their parent (Linux
``prctl(PR_SET_PDEATHSIG, SIGKILL)``; elsewhere a watchdog thread polling the
parent's pid) and killed at once when the caller stops early.
"""
from __future__ import annotations

import contextlib
import time
from collections import Counter
from concurrent.futures import FIRST_COMPLETED, wait

from trilith_xval.compare.run.keys import (CODE_SETS, code_version, digest, project_version, run_code, run_key,
                              source_digest)
from trilith_xval.compare.run.store import RunStore

__all__ = ["simulate", "memo", "lookup", "memo_key", "run_many", "activate", "active", "using", "set_scheduler",
           "check_scheduler", "STATS", "stats_line"]

_ACTIVE: RunStore | None = None
# Default Dask scheduler of run_many (the CLI's --scheduler); None: local processes.
_SCHEDULER: str | None = None
# Hits and computations in this process (plus those reported back by workers).
STATS: Counter = Counter()
# Backends whose runs cost less than a lookup: an analytic-fast trajectory takes
# ~0.15 ms, a store hit ~0.35 ms and a miss ~1.1 ms of store work (68 kB to
# write; benchmarks/bench_store.py), so they are always recomputed.
UNSTORED = frozenset({"analytic-fast"})
# Polling period of the parent's wait: Ctrl-C is acted on within it.
_POLL_S = 0.2
# A Dask scheduler answers a handshake in milliseconds; 15 s covers a loaded
# network.  Past it the address is reported as not being a scheduler.
CONNECT_TIMEOUT_S = 15.0
# How long a cluster may have no worker (none yet, or all gone) before the run is
# stopped with an error: a worker starts in ~2-5 s, a batch system queue may
# take longer, so a minute.
NO_WORKERS_TIMEOUT_S = 60.0


def activate(store: RunStore | None) -> RunStore | None:
    """Make ``store`` the active one (None: no store); returns the previous one."""
    global _ACTIVE
    previous, _ACTIVE = _ACTIVE, store
    return previous


def active() -> RunStore | None:
    return _ACTIVE


def set_scheduler(address: str | None) -> None:
    """The scheduler :func:`run_many` uses when not given one (None: local)."""
    global _SCHEDULER
    _SCHEDULER = address


@contextlib.contextmanager
def using(store: RunStore | None):
    """``with using(store): ...`` -- the active store inside the block."""
    previous = activate(store)
    try:
        yield store
    finally:
        activate(previous)


def _label(backend: str, settings) -> str:
    dt = getattr(settings, "dt", None)
    return backend if dt is None else f"{backend} dt={dt:g}"


def simulate(name: str, scene, excitation, settings=None):
    """``engines.get_backend(name).simulate(scene, excitation, settings)``, through
    the active store: a stored run is returned as stored (bit-identical, with the
    wall time it cost then), a new one is stored."""
    from trilith_xval.engines import get_backend

    backend = get_backend(name)
    store = _ACTIVE
    if store is None or name in UNSTORED:
        return backend.simulate(scene, excitation, settings)
    resolved = backend.Settings() if settings is None else settings
    key = run_key(name, scene, excitation, resolved)
    traj = store.get(key)
    if traj is not None:
        STATS["hits"] += 1
        traj.scene = scene  # the requested one: the key leaves its name (a label) out
        return traj
    t0 = time.perf_counter()
    traj = backend.simulate(scene, excitation, settings)
    store.put(key, traj, kind="run", label=_label(name, resolved),
              cost=time.perf_counter() - t0, code=run_code(name))
    STATS["computed"] += 1
    return traj


MODEL_CODE = CODE_SETS[1]
# Results computed by compare/ itself (campaign jobs, chosen frequencies).
ALL_CODE = CODE_SETS[2]


def memo_key(kind: str, description: dict, code: tuple = MODEL_CODE) -> str:
    return digest({"kind": kind, "what": description, "project": project_version(),
                   "code": source_digest(code)})


def lookup(kind: str, description: dict, code: tuple = MODEL_CODE):
    """The stored result of :func:`memo` (counted as a hit), or None."""
    if _ACTIVE is None:
        return None
    value = _ACTIVE.get(memo_key(kind, description, code))
    if value is not None:
        STATS["hits"] += 1
    return value


def memo(kind: str, description: dict, compute, label: str = "",
         code: tuple = MODEL_CODE):
    """``compute()`` through the active store, keyed by ``kind``, ``description``
    (everything that determines the result, as plain data), the project version
    and the sources of the ``code`` packages."""
    store = _ACTIVE
    if store is None:
        return compute()
    key = memo_key(kind, description, code)
    value = store.get(key)
    if value is not None:
        STATS["hits"] += 1
        return value
    t0 = time.perf_counter()
    value = compute()
    store.put(key, value, kind=kind, label=label or kind, cost=time.perf_counter() - t0,
              code=code_version(code))
    STATS["computed"] += 1
    return value


def stats_line() -> str:
    """``'store DIR: N reused, M computed'`` (or that no store was used)."""
    if _ACTIVE is None:
        return "store: not used (--no-cache)"
    return (f"store {_ACTIVE.directory}: {STATS['hits']} reused, {STATS['computed']} "
            f"computed")


# ------------------------------------------------------------------ worker side
_WORKER: dict = {}


def _call(payload):
    """Run ``fn(item)`` in a worker with the caller's store; return the result and
    the worker's hit/compute counts for it."""
    fn, item, store_dir = payload
    global _ACTIVE
    if store_dir is None:
        _ACTIVE = None
    elif _WORKER.get("dir") != store_dir:
        try:
            _WORKER["store"] = RunStore(store_dir)
        except ValueError:  # a remote worker that cannot reach the directory
            _WORKER["store"] = None
        _WORKER["dir"] = store_dir
    if store_dir is not None:
        _ACTIVE = _WORKER["store"]
    before = Counter(STATS)
    out = fn(item)
    return out, dict(STATS - before)


# ------------------------------------------------------------------- the map
def run_many(fn, items, *, workers: int = 1, scheduler: str | None = None,
             on_done=None, lookup=None):
    """``fn(item)`` for every item; yields the results in submission order.

    Parameters
    ----------
    fn : callable
        A picklable (module-level) function of one item.
    items : iterable
    workers : int
        Local processes, >= 1 (1: in this process, no pool).  Ignored with a
        scheduler (the cluster has its own workers).
    scheduler : str, optional
        ``'tcp://host:port'`` of a Dask distributed scheduler; default: the one
        set by :func:`set_scheduler` (the CLI's ``--scheduler``), else local.
    on_done : callable, optional
        ``on_done(index, result)`` in this process as each item finishes (in
        completion order; for progress bars).
    lookup : callable, optional
        ``lookup(item)`` -> the stored ``fn(item)`` or None, tried here first:
        only the items it misses go to workers (a warm rerun starts no pool).

    Ctrl-C (KeyboardInterrupt) cancels what is pending, kills running local
    workers at once and re-raises; so does closing the generator early.
    """
    items = list(items)
    if not (isinstance(workers, int) and workers >= 1):
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    if lookup is not None and _ACTIVE is not None:
        found = [lookup(item) for item in items]
        todo = [i for i, f in enumerate(found) if f is None]
        rest = run_many(fn, [items[i] for i in todo], workers=workers, scheduler=scheduler,
                        on_done=None if on_done is None else
                        (lambda j, out: on_done(todo[j], out)))
        for i, value in enumerate(found):
            if value is None:
                value = next(rest)
            elif on_done is not None:
                on_done(i, value)
            yield value
        return
    scheduler = _SCHEDULER if scheduler is None else scheduler
    store_dir = str(_ACTIVE.directory) if _ACTIVE is not None else None
    if _ACTIVE is not None and (scheduler is not None or (workers > 1 and len(items) > 1)):
        _ACTIVE.create()  # workers will store results: none of them creates the store
    payloads = [(fn, item, store_dir) for item in items]
    if scheduler is not None:
        yield from _run_dask(payloads, scheduler, on_done)
    elif workers == 1 or len(items) <= 1:
        for i, item in enumerate(items):
            out = fn(item)
            if on_done is not None:
                on_done(i, out)
            yield out
    else:
        yield from _run_local(payloads, min(workers, len(items)), on_done)


def _ordered(futures, result_of, on_done, poll):
    """Yield results in order while reporting completions as they come."""
    index = {f: i for i, f in enumerate(futures)}
    pending, nxt, results = set(futures), 0, {}
    while nxt < len(futures):
        done, pending = poll(pending)
        for f in done:
            out, delta = result_of(f)
            STATS.update(delta)
            results[index[f]] = out
            if on_done is not None:
                on_done(index[f], out)
        while nxt in results:
            yield results.pop(nxt)
            nxt += 1


def _run_local(payloads, workers: int, on_done):
    from trilith_xval.analytic._workers import fork_pool

    with fork_pool(workers) as ex:
        futures = [ex.submit(_call, p) for p in payloads]
        yield from _ordered(futures, lambda f: f.result(), on_done,
                            lambda pending: wait(pending, timeout=_POLL_S,
                                                 return_when=FIRST_COMPLETED))


def _connect(address: str):
    """A Dask client of ``address``; ``ValueError`` when no scheduler answers within
    :data:`CONNECT_TIMEOUT_S` (something else listening there can hold a
    connection open without ever answering, so the wait is bounded here)."""
    import socket
    import threading
    from urllib.parse import urlsplit

    from distributed import Client

    # A refused TCP connection is final: say so at once rather than after the
    # client's retries have used up the timeout.
    where = urlsplit(address)
    if where.scheme in ("tcp", "") and where.hostname and where.port:
        try:
            socket.create_connection((where.hostname, where.port), timeout=2.0).close()
        except ConnectionRefusedError as exc:
            raise ValueError(f"--scheduler: no Dask scheduler at {address!r} "
                             f"(connection refused: {exc.strerror})") from None
        except OSError:  # unreachable or slow: the client's bounded wait decides
            pass
    box: dict = {}

    def connect():
        try:
            box["client"] = Client(address, timeout=f"{CONNECT_TIMEOUT_S:g}s")
        except Exception as exc:  # noqa: BLE001 - reported below as one line
            box["error"] = exc

    thread = threading.Thread(target=connect, daemon=True)
    thread.start()
    thread.join(CONNECT_TIMEOUT_S + 5.0)
    if "client" in box:
        return box["client"]
    why = (f"{type(box['error']).__name__}: {box['error']}" if "error" in box
           else f"no answer within {CONNECT_TIMEOUT_S:g} s")
    raise ValueError(f"--scheduler: no Dask scheduler at {address!r} ({why})")


def check_scheduler(address: str) -> None:
    """``ValueError`` unless a Dask scheduler answers at ``address`` (see :func:`_connect`)."""
    _connect(address).close()


def parallel_slots(workers: int) -> int:
    """How many jobs run at once: the cluster's worker threads when a scheduler is
    set (:func:`set_scheduler`; at least 1, it may have none yet), else ``workers``.

    For sizing batches so that every slot has work; not for correctness.
    """
    if _SCHEDULER is None:
        return workers
    client = _connect(_SCHEDULER)
    try:
        return max(1, sum(client.nthreads().values()))
    finally:
        client.close()


class NoWorkers(ValueError):
    """The cluster had no worker for :data:`NO_WORKERS_TIMEOUT_S`."""


def _run_dask(payloads, address: str, on_done):
    try:
        from distributed import wait as dwait
    except ImportError:  # pragma: no cover - dask[distributed] is a dependency
        raise ValueError("--scheduler needs dask[distributed] installed") from None
    client = _connect(address)
    futures = []
    # Since when the cluster has had no worker (None: it has some).
    idle = {"since": None, "checked": 0.0}

    def check_workers():
        now = time.monotonic()
        if now - idle["checked"] < 1.0:
            return
        idle["checked"] = now
        if client.nthreads():
            idle["since"] = None
        elif idle["since"] is None:
            idle["since"] = now
        elif now - idle["since"] > NO_WORKERS_TIMEOUT_S:
            raise NoWorkers(f"--scheduler {address!r}: the cluster has had no worker for "
                            f"{NO_WORKERS_TIMEOUT_S:g} s; start some (dask worker "
                            f"{address}) and rerun: finished runs are in the store")
    try:
        # pure=False: every payload is a task of its own (no deduplication by hash).
        futures = [client.submit(_call, p, pure=False, priority=-i)
                   for i, p in enumerate(payloads)]

        def poll(pending):
            res = dwait(list(pending), timeout=_POLL_S, return_when="FIRST_COMPLETED") \
                if pending else None
            if res is None:
                return set(), pending
            return set(res.done), set(res.not_done)

        def poll_safe(pending):
            try:
                done, pending = poll(pending)
            except TimeoutError:  # nothing finished within the poll period
                done = set()
            if not done:
                check_workers()
            return done, pending
        yield from _ordered(futures, lambda f: f.result(), on_done, poll_safe)
    finally:
        if futures:
            client.cancel(futures)
        client.close()
