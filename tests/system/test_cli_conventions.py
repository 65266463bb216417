"""The CLI behaves like the tools users know: --version, a quiet closed
pipe, --strict, one --engine spelling, --workers -1, -q/-v, JSON that echoes its
inputs and reruns byte-identically, `trilith scenes`, recorded ground motions."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.cli.options import SCHEMA_VERSION, resolve_workers
from trilith_xval.scenes import load_record, load_scene, scene_names

from tests.support.paths import ROOT
SAMPLE_CSV = ROOT / "scenes" / "records" / "sample.csv"
SAMPLE_AT2 = ROOT / "scenes" / "records" / "sample.AT2"


def _cli(*args, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "trilith_xval.compare.cli.main", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith("trilith ")


def test_closed_pipe_is_quiet():
    # The reader is gone before the first write (the import takes far longer):
    # like `trilith simulate ... --json | head -0`.
    proc = _cli("simulate", "-A", "25", "-w", "11", "--json")
    proc.stdout.close()
    err = proc.stderr.read()
    proc.wait(timeout=120)
    assert "Traceback" not in err and "BrokenPipe" not in err, err
    assert proc.returncode == 1


def test_pybullet_banner_silenced():
    proc = _cli("simulate", "-A", "25", "-w", "11", "--engine", "pybullet", "--json")
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0
    assert err == ""  # no "pybullet build time" line
    assert json.loads(out)["engine"] == "pybullet"


def _strip_timings(text: str) -> str:
    doc = json.loads(text)
    assert list(doc)[-1] == "timings"  # last, so the text before it can be compared
    return text[:text.index('"timings"')]


@pytest.mark.parametrize("argv", [
    ["simulate", "-A", "25", "-w", "11", "--json"],
    ["simulate", "-A", "19", "-w", "15", "--engine", "pymunk", "--json"],
    ["simulate", "--record", str(SAMPLE_CSV), "--engine", "analytic-fast", "--json"],
    ["spectrum", "--omega", "10,11", "--json", "--workers", "1"],
    ["restitution", "--engine", "analytic", "--n-impacts", "2", "--json"],
    ["scenes", "--json"],
])
def test_json_echoes_inputs_and_reruns_byte_identical(argv, capsys):
    texts = []
    for _ in range(2):
        assert main(argv) == 0
        texts.append(capsys.readouterr().out)
    assert _strip_timings(texts[0]) == _strip_timings(texts[1])
    doc = json.loads(texts[0])
    assert doc["schema_version"] == SCHEMA_VERSION and doc["command"] == argv[0]
    assert "backend" not in doc and "wall_time" not in json.dumps(
        {k: v for k, v in doc.items() if k != "timings"})
    if argv[0] != "scenes":
        assert doc["engine"] and doc["engine_version"]
        assert doc["inputs"]["scene"]["lam"] == 5.0


def test_simulate_json_inputs(capsys):
    assert main(["simulate", "-A", "25", "-w", "11", "--pulse", "cosine", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    exc = doc["inputs"]["excitation"]
    assert (exc["kind"], exc["amplitude"], exc["omega"]) == ("cosine", 25.0, 11.0)
    assert doc["inputs"]["scene"]["name"] == "fig5" and doc["inputs"]["engine"] == "analytic"


@pytest.mark.parametrize("command", ["report", "bench", "spectrum", "map", "fragility"])
def test_engine_all_names_every_registered_engine(command, capsys):
    import argparse

    from trilith_xval.compare.cli.main import build_parser
    from trilith_xval.compare.cli.options import parse_engine_list
    from trilith_xval.engines import engine_names
    parser, _ = build_parser()
    args = parser.parse_args([command, "--engine", "all"] +
                             (["--records", "sample"] if command == "fragility" else []))
    assert parse_engine_list(args.engine) == engine_names()


def _point(family, error, time, default=False):
    return SimpleNamespace(family=family, metric="theta", error=error, time=time,
                           default=default)


@pytest.mark.parametrize("strict", [False, True])
def test_bench_strict(monkeypatch, capsys, strict):
    import benchmarks.bench_workprecision as real
    import trilith_xval.compare.cli.bench as bench_cmd
    # The default (error 1e-3 in 1 s) is dominated by 1e-4 in 0.5 s.
    points = [_point("pymunk dt", 1e-3, 1.0, default=True), _point("pymunk dt", 1e-4, 0.5)]
    fake = SimpleNamespace(run=lambda **kw: {"points": points}, _dominates=real._dominates)
    monkeypatch.setattr(bench_cmd, "_load_bench", lambda: fake)
    argv = ["bench", "--engine", "pymunk", "--no-analytic"] + (["--strict"] if strict else [])
    assert main(argv) == (1 if strict else 0)
    assert "FAIL pymunk / theta: default dominated" in capsys.readouterr().out


@pytest.mark.parametrize("strict", [False, True])
def test_report_strict_and_formatted_fail_lines(monkeypatch, capsys, tmp_path, strict):
    import trilith_xval.compare.campaign.validation
    import trilith_xval.compare.report.html
    from trilith_xval import compare
    verdicts = [{"metric": "restitution vs Eq. 20", "backend": "pymunk",
                 "value": 0.012007074700878338, "tolerance": 0.005, "passed": False,
                 "unit": "relative"},
                {"metric": "verdicts", "backend": "pymunk", "value": 0, "tolerance": 0,
                 "passed": True, "unit": "count"}]
    monkeypatch.setattr(compare.campaign.validation, "run_campaign",
                        lambda config, progress=False: SimpleNamespace(verdicts=verdicts, versions={}))
    monkeypatch.setattr(compare.report.html, "write_report",
                        lambda result, out, provenance=None, extra=None:
                        {"html": Path(out) / "index.html"})
    argv = ["report", "--quick", "--out", str(tmp_path / "r")] + (["--strict"] if strict else [])
    assert main(argv) == (1 if strict else 0)
    out = capsys.readouterr().out
    assert "FAIL pymunk: restitution vs Eq. 20 = 1.2 % (tolerance 0.5 %)" in out
    assert (tmp_path / "r").is_dir()  # --out created at the door


def test_a_piped_report_says_how_far_it_is(tmp_path, capsys):
    """stderr is no terminal here: one line per tenth of the jobs, with the count
    and the elapsed time; -q keeps it silent."""
    import re

    from trilith_xval.compare.campaign.validation import CampaignConfig, run_campaign
    config = CampaignConfig.quick(engines=("pymunk",), n_frequencies=0, points=("A",),
                                  restitution_lams=(5.0,))
    run_campaign(config, progress=True)
    err = capsys.readouterr().err
    counts = [(int(a), int(b)) for a, b in re.findall(r"report: (\d+)/(\d+) jobs", err)]
    assert "report: reference spectra done" in err
    assert counts and counts[-1][0] == counts[-1][1] and len(counts) <= 11
    assert [a for a, _ in counts] == sorted(a for a, _ in counts)
    run_campaign(config)  # progress off (the CLI's -q): nothing on stderr
    assert "report:" not in capsys.readouterr().err


def test_workers_like_n_jobs():
    cores = os.cpu_count()
    assert resolve_workers(-1) == cores and resolve_workers(3) == 3
    assert resolve_workers(-cores) == 1
    for bad in (0, 257, -cores - 1):
        with pytest.raises(ValueError, match="--workers"):
            resolve_workers(bad)


def test_quiet_and_verbose(tmp_path, capsys):
    csv = tmp_path / "x.csv"
    assert main(["simulate", "-A", "4", "-w", "9", "--csv", str(csv), "-q"]) == 0
    out = capsys.readouterr().out
    assert "verdict:" in out and "wrote" not in out and csv.is_file()
    assert main(["simulate", "-A", "4", "-w", "9", "-v"]) == 0
    assert "wall time" in capsys.readouterr().out


def test_help_shows_defaults_without_markup(capsys):
    import re
    for command in ("simulate", "spectrum", "report", "bench", "record", "figures", "map",
                    "atlas", "calibrate", "campaign"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        # Whitespace joined: argparse may wrap a line right after "(default:"
        # (the engine list in the defaults grows with the registry).
        text = " ".join(capsys.readouterr().out.split())
        assert "``" not in text and "(default: " in text
        # A default written in the help text and added by the formatter shows twice.
        assert not re.search(r"(\(default: [^)]*\)) \1", text), command
    with pytest.raises(SystemExit):
        main(["report", "--help"])
    assert "(default: -1)" in capsys.readouterr().out  # one --workers default


def test_scenes_lists_every_scene_with_its_values(capsys):
    assert main(["scenes"]) == 0
    lines = capsys.readouterr().out.split("\n\n")[0].splitlines()  # the table, not the words
    assert "lam" in lines[0] and "alpha [rad]" in lines[0] and "source" in lines[0]
    rows = {line.split()[0]: line for line in lines[1:]}
    assert set(rows) == set(scene_names())
    fig5 = load_scene("fig5")
    assert f"{fig5.alpha:.4g}" in rows["fig5"] and "Fig. 5" in rows["fig5"]


def test_sample_record_both_formats_agree_and_regenerate():
    from trilith_xval.scenes.records.make_sample import synthetic_record

    csv, at2 = load_record(SAMPLE_CSV), load_record(SAMPLE_AT2)
    assert len(csv.times) == len(at2.times) == 1001 and csv.end_time == at2.end_time == 10.0
    # .AT2 holds 8 significant digits in g: 4 m/s^2 x 1e-7 relative.
    assert np.max(np.abs(np.subtract(csv.accelerations, at2.accelerations))) < 1e-6
    t, a = synthetic_record()  # the committed file is the script's output
    assert np.allclose(csv.times, t) and np.max(np.abs(np.asarray(csv.accelerations) - a)) < 1e-6


def test_simulate_with_a_record(capsys):
    assert main(["simulate", "--record", str(SAMPLE_CSV)]) == 0
    out = capsys.readouterr().out
    assert "record sample.csv (1001 samples, 10 s, PGA 4 m/s^2 (0.408 g)" in out
    assert "verdict: " in out


def test_record_line_numbers_are_file_lines(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("# comment\nt,a\n0,0\n0.5,1\n0.4,0\n")
    with pytest.raises(ValueError, match=r"r.csv, line 5: time 0.4 s does not increase"):
        load_record(path)


def test_stored_spectrum_needs_no_numba(tmp_path):
    """A rerun served by the run store looks its frequencies up in the calling
    process: numba (about 0.6 s of start-up with the kernels) is never imported,
    and the output is the first run's.  (One worker: the first run computes in
    this process, so it must import numba.)"""
    argv = ["spectrum", "--omega", "9:11:1", "--workers", "1", "--cache", str(tmp_path), "--json"]
    code = (f"import sys; from trilith_xval.compare.cli.main import main; main({argv!r}); "
            "print('numba' in sys.modules, file=sys.stderr)")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    first, again = (subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env,
                                   capture_output=True, text=True, timeout=300)
                    for _ in range(2))
    assert first.stderr.strip().endswith("True")  # it computed
    assert again.stderr.strip().endswith("False")  # it did not load numba
    strip = lambda out: {k: v for k, v in json.loads(out).items() if k != "timings"}  # noqa: E731
    assert strip(first.stdout) == strip(again.stdout)
