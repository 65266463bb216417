"""``trilith fragility`` end to end on small generated records: outputs whole and
consistent (JSON, CSV, PNG), a warm rerun served by the run store, bad input
refused in one line before any work."""
from __future__ import annotations

import json

import numpy as np
import pytest

from trilith_xval.compare.cli.main import main

# Short records (1.5 s at 100 Hz) of two half-sines, so runs are cheap; the
# coarse grid and the no-pendulum scene keep the command to a few seconds.
ARGS = ["--no-pendulum", "--im-range", "2:40", "--rel-step", "0.5", "--rtol", "0.1",
        "--tail", "1", "--workers", "1", "-q"]


def write_suite(folder, n=3):
    folder.mkdir()
    t = np.arange(0.0, 1.5, 0.01)
    for k in range(n):
        w = 6.0 + 3.0 * k
        a = np.where(t <= 2 * np.pi / w, np.sin(w * t), 0.0)
        np.savetxt(folder / f"r{k}.csv", np.column_stack([t, a]), delimiter=",",
                   header="t,a", comments="")
    return folder


def test_fragility_writes_consistent_outputs_and_resumes(tmp_path, capsys):
    suite = write_suite(tmp_path / "suite")
    out, cache = tmp_path / "out", tmp_path / "cache"
    argv = ["fragility", "--records", str(suite), "--out", str(out), "--cache", str(cache),
            *ARGS]
    assert main(argv) == 0
    first = capsys.readouterr().out
    doc = json.loads((out / "fragility.json").read_text())
    recs = doc["backends"]["analytic"]["records"]
    assert [r["label"] for r in recs] == ["r0.csv", "r1.csv", "r2.csv"]
    for r in recs:
        # A bracket of the first overturn, hi - lo <= rtol hi (--rtol 0.1), or censored.
        if not r["censored"] and r["im_safe"] is not None:
            assert 0.0 < r["im_overturn"] - r["im_safe"] <= 0.1 * r["im_overturn"]
    csv_rows = (out / "fragility.csv").read_text().splitlines()
    assert len(csv_rows) == 1 + len(recs)
    assert (out / "fragility.png").stat().st_size > 10_000
    fit = doc["backends"]["analytic"]["fit"]
    assert fit["n"] == 3
    # Warm rerun: every IDA comes from the store, the same numbers come out.
    assert main(argv) == 0
    assert capsys.readouterr().out.splitlines()[:1] == first.splitlines()[:1]
    assert json.loads((out / "fragility.json").read_text())["backends"] == doc["backends"]


@pytest.mark.parametrize("extra, message", [
    (["--im-range", "5"], "error: --im-range expects LO:HI"),
    (["--im-range", "1g:x"], "error: --im-range"),
    (["--engine", "bullet"], "error: --engine: unknown engine 'bullet'"),
    (["--rel-step", "0"], "error: --rel-step must be in"),
    (["--stripes", "0,2"], "error: --stripes must be finite and > 0"),
    (["--stripes=-1g,2g"], "error: --stripes must be finite and > 0"),
    (["--stripes", "5"], "error: --stripes needs 2 to 100 distinct intensities"),
    (["--stripes", "2,x"], "error: --stripes"),
    (["--stripes", "2,nan"], "error: --stripes")])
def test_bad_input_is_one_line(tmp_path, capsys, extra, message):
    suite = write_suite(tmp_path / "suite", n=1)
    argv = ["fragility", "--records", str(suite), "--out", str(tmp_path / "o"), "--no-cache",
            *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1


def test_empty_folder_is_refused(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main(["fragility", "--records", str(tmp_path / "empty"), "--no-cache",
                 "--out", str(tmp_path / "o")]) == 2
    assert "no .AT2 or .csv record" in capsys.readouterr().err


def test_spectrum_record_equals_the_fragility_ida(tmp_path, capsys):
    """``spectrum --record`` is the IDA of one record: the same first overturning
    intensity as ``fragility`` gives that record (same search, same window)."""
    suite = write_suite(tmp_path / "suite", n=2)
    cache = tmp_path / "cache"
    assert main(["fragility", "--records", str(suite), "--out", str(tmp_path / "o"),
                 "--cache", str(cache), *ARGS]) == 0
    capsys.readouterr()
    frag = json.loads((tmp_path / "o" / "fragility.json").read_text())
    assert main(["spectrum", "--record", str(suite / "r0.csv"), "--json", "--cache", str(cache),
                 *ARGS]) == 0
    doc = json.loads(capsys.readouterr().out)
    one = doc["backends"]["analytic"]
    assert one["im_overturn"] == frag["backends"]["analytic"]["records"][0]["im_overturn"]
    assert one["runs"] == frag["backends"]["analytic"]["records"][0]["runs"]


def test_spectrum_record_refuses_pulse_options(tmp_path, capsys):
    suite = write_suite(tmp_path / "suite", n=1)
    assert main(["spectrum", "--record", str(suite / "r0.csv"), "--tol", "0.1"]) == 2
    assert capsys.readouterr().err.startswith("error: --record searches the record's intensity")


def test_one_record_is_refused_at_the_door(tmp_path, capsys):
    suite = write_suite(tmp_path / "suite", n=1)
    for records in (str(suite), str(suite / "r0.csv"), "sample"):
        assert main(["fragility", "--records", records, "--out", str(tmp_path / "o"),
                     "--no-cache", *ARGS]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: --records: 1 record in") and err.count("\n") == 1
        assert not (tmp_path / "o").exists()


def test_msa_beside_ida_counts_the_ida_verdicts(tmp_path, capsys):
    """With --stripes on grid points of the IDA (2 x 1.5^k), each record's
    stripe verdict is the IDA's verdict at that intensity: the same runs."""
    suite = write_suite(tmp_path / "suite", n=3)
    out = tmp_path / "out"
    stripes = [3.0, 6.75, 15.1875, 34.171875]
    assert main(["fragility", "--records", str(suite), "--out", str(out), "--cache",
                 str(tmp_path / "cache"), "--stripes", ",".join(map(str, stripes)),
                 *ARGS]) == 0
    printed = capsys.readouterr().out
    doc = json.loads((out / "fragility.json").read_text())
    body = doc["backends"]["analytic"]
    msa = body["msa"]
    assert msa["stripes"] == stripes and msa["n"] == [3] * 4
    for rec in body["records"]:
        runs = dict((v, o) for v, o in rec["runs"])
        assert msa["verdicts"][rec["label"]] == [runs[x] for x in stripes]
    assert msa["overturned"] == [sum(v[j] for v in msa["verdicts"].values())
                                 for j in range(4)]
    assert "  MSA, 4 stripes of 3 runs, overturned " in printed
    assert set(body["fit"]) >= {"median_ci", "beta_ci", "bootstrap"}
