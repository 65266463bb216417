"""The run store (compare/run/store.py, compare/run/runs.py) and atomic outputs (compare/run/atomic.py).

Every store here lives in ``tmp_path``: tests never touch the user's cache.
"""
from __future__ import annotations

import dataclasses
import multiprocessing as mp
import os
import struct

import numpy as np
import pytest

from trilith_xval.analytic.excitation import Pulse, SampledRecord, Still
from trilith_xval.compare.run import atomic
from trilith_xval.compare.run import runs
from trilith_xval.compare.run.keys import run_key
from trilith_xval.compare.run.store import RunStore, default_cache_dir
from trilith_xval.engines import get_backend
from tests.support.trajectories import TIMINGS, assert_same_trajectory, same

# Short pymunk run (0.3 s of simulated time at 5e-4 s steps): milliseconds.
SHORT = dict(t_max=0.3, dt=5e-4)


def _pymunk_settings(**changes):
    return dataclasses.replace(get_backend("pymunk").Settings(), **{**SHORT, **changes})


@pytest.fixture()
def store(tmp_path):
    s = RunStore(tmp_path / "cache")
    with runs.using(s):
        yield s
    s.close()


@pytest.mark.parametrize("backend", ["analytic", "pymunk"])
def test_hit_is_bit_identical_to_fresh(store, fig5, backend):
    settings = (_pymunk_settings() if backend == "pymunk"
                else get_backend("analytic").Settings(t_max=1.0))
    pulse = Pulse(25.0, 11.0)
    first = runs.simulate(backend, fig5, pulse, settings)
    assert store.count() == 1
    hit = runs.simulate(backend, fig5, pulse, settings)
    assert store.count() == 1 and runs.STATS["hits"] >= 1
    assert_same_trajectory(first, hit)  # the stored one, wall time included
    fresh = get_backend(backend).simulate(fig5, pulse, settings)
    assert_same_trajectory(fresh, hit, timings=False)  # a new run: only its cost differs


def test_key_covers_everything_but_the_scene_name(fig5):
    settings = get_backend("pymunk").Settings()
    base = run_key("pymunk", fig5, Pulse(10.0, 9.0), settings)
    assert run_key("pymunk", fig5.replace(name="other"), Pulse(10.0, 9.0), settings) == base
    changed = [run_key("pymunk", fig5.replace(mu=1.5), Pulse(10.0, 9.0), settings),
               run_key("pymunk", fig5, Pulse(10.0, 9.0, "cosine"), settings),
               run_key("pymunk", fig5, Pulse(np.nextafter(10.0, 11.0), 9.0), settings),
               run_key("pymunk", fig5, Still(), settings),
               run_key("pymunk", fig5, Pulse(10.0, 9.0), dataclasses.replace(settings, dt=2e-4)),
               run_key("pybullet", fig5, Pulse(10.0, 9.0), get_backend("pybullet").Settings())]
    assert len({base, *changed}) == 1 + len(changed)
    rec = SampledRecord((0.0, 0.1, 0.2), (0.0, 1.0, 0.0))
    rec2 = SampledRecord((0.0, 0.1, 0.2), (0.0, 1.0 + 1e-15, 0.0))  # same summary, other samples
    assert run_key("pymunk", fig5, rec, settings) != run_key("pymunk", fig5, rec2, settings)


def test_memo_and_no_store(tmp_path):
    calls = []

    def compute():
        calls.append(1)
        return {"a": np.arange(3.0)}
    assert runs.active() is None  # the library default: no store
    runs.memo("demo", {"x": 1}, compute)
    runs.memo("demo", {"x": 1}, compute)
    assert len(calls) == 2
    with runs.using(RunStore(tmp_path)):
        first = runs.memo("demo", {"x": 1}, compute)
        again = runs.memo("demo", {"x": 1}, compute)
        runs.memo("demo", {"x": 2}, compute)
    assert len(calls) == 4 and np.array_equal(first["a"], again["a"])


def test_default_cache_dir(tmp_path):
    assert default_cache_dir({"TRILITH_CACHE": str(tmp_path / "c")}) == tmp_path / "c"
    assert default_cache_dir({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "trilith-xval"
    assert default_cache_dir({"HOME": str(tmp_path)}) == tmp_path / ".cache" / "trilith-xval"
    # CI with an unusable HOME (a file, so nothing can be created under it): temp dir.
    (tmp_path / "file").write_text("")
    fallback = default_cache_dir({"HOME": str(tmp_path / "file"), "CI": "true"})
    assert fallback.parent == default_cache_dir({"HOME": "relative"}).parent
    RunStore(fallback)  # and it works


def test_not_a_store_is_a_clear_error(tmp_path):
    (tmp_path / "runs.sqlite").write_bytes(b"not sqlite" * 100)
    with pytest.raises(ValueError, match="not a trilith-xval run store.*left untouched"):
        RunStore(tmp_path)
    with pytest.raises(ValueError, match="left untouched"):  # not proven ours: kept
        RunStore(tmp_path, check_database=False).clear()
    assert (tmp_path / "runs.sqlite").read_bytes() == b"not sqlite" * 100
    (tmp_path / "file").write_text("")
    with pytest.raises(ValueError, match="cannot create"):
        RunStore(tmp_path / "file" / "sub")


def _writer(directory, start, n):
    s = RunStore(directory)
    for i in range(start, start + n):
        s.put(f"k{i % 150}", i % 150, kind="demo", label="demo", cost=0.0)


def test_two_processes_share_a_store(tmp_path):
    """Overlapping keys from two processes at once: no error, one entry each."""
    ctx = mp.get_context("fork")
    procs = [ctx.Process(target=_writer, args=(tmp_path, s, 200)) for s in (0, 100)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    s = RunStore(tmp_path)
    assert s.count() == 150 and all(s.get(f"k{i}") == i for i in range(150))


def _square(x):
    return x * x, os.getpid()


def test_run_many_order_and_workers():
    out = list(runs.run_many(_square, range(12), workers=2))
    assert [o[0] for o in out] == [i * i for i in range(12)]
    assert os.getpid() not in {o[1] for o in out}
    seen = []
    list(runs.run_many(_square, range(5), workers=1, on_done=lambda i, r: seen.append(i)))
    assert seen == list(range(5))
    with pytest.raises(ValueError, match="workers"):
        list(runs.run_many(_square, range(3), workers=0))


# ------------------------------------------------------------------ atomic outputs
def test_atomic_write_keeps_old_file_on_failure(tmp_path):
    path = tmp_path / "out.csv"
    atomic.write_text(path, "old\n")
    with pytest.raises(RuntimeError):
        with atomic.atomic_path(path) as tmp:
            tmp.write_text("half")
            raise RuntimeError("killed mid-write")
    assert path.read_text() == "old\n"
    assert os.listdir(tmp_path) == ["out.csv"]  # no temporary left behind
    atomic.savetxt(path, np.eye(2), delimiter=",")
    assert np.array_equal(np.loadtxt(path, delimiter=","), np.eye(2))


def test_report_dir_is_swapped_whole(tmp_path):
    out = tmp_path / "report"
    with atomic.report_dir(out) as d:
        (d / "index.html").write_text("old")
        (d / "stale.md").write_text("old only")
    with pytest.raises(RuntimeError):  # a build that dies halfway leaves the old report
        with atomic.report_dir(out) as d:
            (d / "index.html").write_text("new")
            raise RuntimeError
    assert sorted(os.listdir(out)) == [atomic.MARKER, "index.html", "stale.md"]
    assert (out / "index.html").read_text() == "old"
    with atomic.report_dir(out) as d:
        (d / "index.html").write_text("new")
        (d / "summary.json").write_text("{}")
    assert sorted(os.listdir(out)) == [atomic.MARKER, "index.html", "summary.json"]  # nothing old mixed in
    leftovers = [n for n in os.listdir(tmp_path) if n.startswith(".report.")]
    assert leftovers == []


def test_second_writer_of_an_output_gets_a_clear_error(tmp_path):
    out = tmp_path / "report"
    with atomic.output_lock(out):
        with pytest.raises(ValueError, match="being written by another process"):
            with atomic.report_dir(out):
                pass
    with atomic.report_dir(out):  # released: fine again
        pass


def test_run_many_lookup_sends_only_missing_items(store):
    calls = []

    def fn(x):
        calls.append(x)
        return runs.memo("demo", {"x": x}, lambda: x * 10)
    assert list(runs.run_many(fn, [1, 2], workers=1)) == [10, 20]
    calls.clear()
    seen = []
    out = list(runs.run_many(fn, [1, 2, 3], workers=1, on_done=lambda i, r: seen.append(i),
                             lookup=lambda x: runs.lookup("demo", {"x": x})))
    assert out == [10, 20, 30] and calls == [3] and sorted(seen) == [0, 1, 2]


# ------------------------------------------------------ the data-only value format
def test_every_trajectory_field_round_trips_through_the_format(fig5):
    """A record-driven pymunk run (events, verdict, settings, diagnostics, scene and a
    SampledRecord excitation) comes back field for field, bit for bit."""
    from trilith_xval.compare.run.codec import decode, encode

    rec = SampledRecord(tuple(np.linspace(0.0, 1.0, 11)), (0.0, 30.0, -30.0, 30.0, -1e-300,
                                                           -0.0, 5e-324, 2.0, 1.0, 0.5, 0.0))
    traj = get_backend("pymunk").simulate(fig5, rec, _pymunk_settings(t_max=1.0))
    assert traj.events and traj.diagnostics and traj.settings
    back = decode(encode(traj))
    assert_same_trajectory(traj, back)
    assert back.theta.flags.writeable and back.excitation == rec


def test_format_keeps_types_and_special_floats():
    from trilith_xval.compare.measure.thresholds import ThresholdPoint
    from trilith_xval.compare.measure.trajectories import Provenance
    from trilith_xval.compare.run.codec import decode, encode

    prov_fields = {f.name: 0.5 if f.type in ("float", float) else None
                   for f in dataclasses.fields(Provenance)}
    prov = Provenance(**{**prov_fields, **{f.name: "x" for f in dataclasses.fields(Provenance)
                                           if f.type in ("str", str)}})
    value = {"nan": float("nan"), "inf": -float("inf"), "zero": -0.0, "tiny": 5e-324,
             "tuple": (1, "a", None, True), "list": [np.float64(2.5), np.int32(-3)],
             (1.5, "k"): np.arange(6, dtype=np.int16).reshape(2, 3)[:, ::2],
             "complex": np.array([1 + 2j]), "big": 10 ** 40,
             "point": ThresholdPoint(9.0, "sine", 8.0, float("nan"), 7.5, "no-impact", None,
                                     6, 0, 4e-3, prov, ((7.5, "survived", None),))}
    back = decode(encode(value))
    assert same(value, back)
    assert type(back["list"][1]) is np.int32 and back[(1.5, "k")].dtype == np.int16


@pytest.mark.parametrize("value", [object(), {1, 2}, np.array(["a"], dtype=object),
                                   b"bytes"])
def test_format_refuses_what_is_not_data(value):
    from trilith_xval.compare.run.codec import encode
    with pytest.raises(TypeError, match="store"):
        encode(value)


def test_format_reads_nothing_foreign():
    """Decoding refuses (never runs, never imports outside the project) a pickle,
    a class of another package, a non-dataclass of the project, a truncated value."""
    import json
    import struct

    from trilith_xval.compare.run.codec import MAGIC, ForeignValue, decode, encode

    def blob(tree) -> bytes:
        header = json.dumps(tree).encode()
        return MAGIC + struct.pack("<Q", len(header)) + header

    good = encode({"a": np.ones(3)})
    for bad in (b"\x80\x05K\x01.",  # pickle.dumps(1)
                blob({"~": "class", "cls": "os:system", "v": {}}),
                blob({"~": "class", "cls": "compare.run.store:RunStore", "v": {}}),
                blob({"~": "class", "cls": "analytic.nothing_here:X", "v": {}}),
                blob({"~": "array", "dtype": "|O", "shape": [1], "at": 0, "n": 8}),
                blob({"~": "array", "dtype": "<f8", "shape": [10], "at": 0, "n": 80}),
                blob({"~": "eval", "v": "1"}),
                good[:len(good) - 5], good[:10]):
        with pytest.raises(ForeignValue):
            decode(bad)


def test_a_value_the_format_cannot_hold_is_not_stored_but_not_lost(tmp_path, capsys):
    s = RunStore(tmp_path / "c")
    s.put("k", {1, 2}, kind="demo", label="demo", cost=0.0)
    assert s.get("k") is None and "'demo' result is not stored" in capsys.readouterr().err
    s.close()


def test_a_store_of_pickles_is_read_as_empty_and_pruned(tmp_path):
    """A store written before the data-only format (no code column, pickled values)
    opens, is never unpickled, and ``prune`` removes its rows."""
    import pickle
    import sqlite3

    d = tmp_path / "old"
    d.mkdir(mode=0o700)
    con = sqlite3.connect(d / "runs.sqlite")
    con.execute("CREATE TABLE runs (key TEXT PRIMARY KEY, kind TEXT NOT NULL, label TEXT NOT "
                "NULL, cost REAL NOT NULL, created REAL NOT NULL, value BLOB NOT NULL)")
    con.execute("INSERT INTO runs VALUES ('k', 'demo', 'demo', 0, 0, ?)", (pickle.dumps(1.5),))
    con.commit()
    con.close()
    s = RunStore(d)
    assert s.get("k") is None and s.by_code() == [("foreign", 1, len(pickle.dumps(1.5)))]
    assert s.prune(set()) == 1 and s.count() == 0
    s.close()
