"""A hostile and careless user's input files: devices, FIFOs, sockets, deep and
malformed JSON, stored documents of another schema version.

Every case runs under a deadline (a reader that blocks or reads without end
fails the test instead of hanging it), exits 2 with one ``error:`` line naming
the option or file, and writes nothing (no ``--json`` before the input is
validated).
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
from pathlib import Path

import pytest

from trilith_xval.compare.campaign import summary
from trilith_xval.scenes.safe_read import read_json
from trilith_xval.scenes import load_record, read_toml

from tests.support.hostile import refused, snapshot
from tests.support.paths import ROOT

ATLAS = ROOT / "docs" / "validation" / "atlas.json"


@contextlib.contextmanager
def deadline(seconds: float = 20.0):
    """Fail (never hang) when the body runs longer than ``seconds``."""
    def expired(signum, frame):
        raise TimeoutError(f"still running after {seconds} s: a reader blocked")
    old = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def specials(here):
    """Name -> path of a device, a FIFO and a listening socket."""
    os.mkfifo(here / "fifo")
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(here / "sock"))
    yield {"zero": "/dev/zero", "urandom": "/dev/urandom", "fifo": str(here / "fifo"),
           "socket": str(here / "sock")}
    sock.close()


COMMANDS = {
    "atlas": lambda f: ["atlas", "--from", f, "--json", "out.json"],
    "settings": lambda f: ["spectrum", "--engine", "pymunk", "--omega", "10",
                           "--settings", f, "--json"],
    "record": lambda f: ["simulate", "--record", f],
    "scene": lambda f: ["simulate", "-A", "25", "-w", "11", "--scene", f],
}


@pytest.mark.parametrize("special", ["zero", "urandom", "fifo", "socket"])
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_devices_fifos_and_sockets_are_refused(command, special, specials, here, capsys):
    before = snapshot(here)
    with deadline():
        refused(COMMANDS[command](specials[special]), capsys, "not a regular file")
    assert snapshot(here) == before


@pytest.mark.parametrize("special", ["zero", "fifo"])
def test_library_readers_refuse_specials(special, specials):
    path = specials[special]
    with deadline():
        for read in (lambda: read_json(path, "doc"), lambda: summary.load(path),
                     lambda: read_toml(Path(path), "scene file"),
                     lambda: load_record(path)):
            with pytest.raises(ValueError, match="not a regular file"):
                read()


def _atlas() -> dict:
    return json.loads(ATLAS.read_text())


def _broken(case: str):
    doc = _atlas()
    if case == "deep":
        return "[" * 100_000 + "]" * 100_000
    if case == "schema_999":
        doc["schema_version"] = 999
    elif case == "no_valid":
        del doc["points"][0]["valid"]
    elif case == "steps_string":
        doc["steps"] = "fine"
    elif case == "no_points":
        del doc["points"]
    elif case == "rows_numbers":
        doc["points"][0]["engines"]["pymunk"] = [1, 2]
    elif case == "engines_list":
        doc["points"][1]["engines"] = ["pymunk"]
    elif case == "not_an_object":
        doc = [1, 2, 3]
    elif case == "cost_strings":
        doc["cost"] = ["x"]
    return json.dumps(doc)


ATLAS_CASES = {"deep": "nested deeper", "schema_999": "schema_version 999",
               "no_valid": "points[0].valid", "steps_string": "steps must be",
               "no_points": "no 'points'", "rows_numbers": "engines.pymunk[0]",
               "engines_list": "points[1].engines", "not_an_object": "not a JSON object",
               "cost_strings": "cost[0]"}


@pytest.mark.parametrize("case", sorted(ATLAS_CASES))
def test_malformed_atlas_is_one_line_and_writes_nothing(case, here, capsys):
    (here / "a.json").write_text(_broken(case))
    before = snapshot(here)
    with deadline():
        line = refused(["atlas", "--from", "a.json", "--json", "out.json", "--html",
                        "out.html"], capsys, ATLAS_CASES[case])
    assert "--from 'a.json'" in line
    assert snapshot(here) == before  # no out.json, no out.html, no temporary


def test_oversized_json_is_refused_unread(here):
    (here / "big.json").write_bytes(b"[" + b"0," * 600_000 + b"0]")
    with pytest.raises(ValueError, match="larger than 1000000 bytes"):
        read_json(here / "big.json", "doc", max_bytes=1_000_000)


def test_summary_of_another_schema_is_refused(here):
    (here / "s.json").write_text(json.dumps({"schema_version": 99}))
    with pytest.raises(ValueError, match="schema_version 99"):
        summary.load(here / "s.json")
    (here / "s.json").write_text(json.dumps({"schema_version": 3, "spectra": "x"}))
    with pytest.raises(ValueError, match="not a summary"):
        summary.load(here / "s.json")
