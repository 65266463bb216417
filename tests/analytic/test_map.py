"""``trilith map`` and :mod:`analytic.overturn_map`: cells against direct runs,
the first-overturning curve against the map's own columns, outputs, bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest

from trilith_xval.analytic import fast
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.overturn_map import analytic_map, verdict_label, verdict_map
from trilith_xval.compare.cli.main import main as cli_main

OMEGAS = np.array([7.0, 11.0, 18.0])
AMPS = np.arange(1.0, 45.0, 1.5)


@pytest.fixture(scope="module")
def fig5_map(fig5):
    return analytic_map(fig5, OMEGAS, AMPS, workers=2)


def test_cells_match_direct_verdicts(fig5, fig5_map):
    for j, w in enumerate(OMEGAS):
        for i, a in enumerate(AMPS):
            v = fast.verdict_for(fig5, Pulse(float(a), float(w)))
            assert fig5_map.labels[fig5_map.cells[i, j]] == verdict_label(v.status, v.mode)


def test_first_curve_is_below_every_overturning_cell(fig5_map):
    """The first overturning amplitude is the lowest that overturns: no cell of
    the column below it overturns (up to the search's tol), one at or above does."""
    m = fig5_map
    over = np.isin(m.cells, [1, 2])
    for j in range(m.omega.size):
        lowest = m.amplitude[over[:, j]].min()
        assert m.first[j] <= lowest + 0.01


def test_verdict_map_generic_runner(fig5):
    m = verdict_map(lambda a, w: fast.verdict_for(fig5, Pulse(a, w)), fig5, [11.0],
                    [5.0, 30.0], backend="analytic-fast")
    assert [m.labels[c] for c in m.cells[:, 0]] == ["survived", "overturned (no-impact)"]


def test_cli_json_csv_plot(tmp_path, capsys):
    csv, png = tmp_path / "m.csv", tmp_path / "m.png"
    assert cli_main(["map", "--omega", "9:11:1", "--amplitude", "2:20:2", "--json",
                     "--csv", str(csv), "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    m = out["maps"][0]
    assert m["omega"] == [9.0, 10.0, 11.0] and len(m["cells"]) == 10
    assert len(m["first_overturn"]) == 3 and png.stat().st_size > 0
    assert len(csv.read_text().splitlines()) == 1 + 30


@pytest.mark.parametrize("argv,needle", [
    (["map", "--amplitude", "5:1:1"], "--amplitude"),
    (["map", "--omega", "0:3:1"], "--omega"),
    (["map", "--workers", "0"], "--workers"),
    (["map", "--engine", "nope"], "engine"),
    (["map", "--engine", "pymunk", "--max-engine-runs", "3"], "--max-engine-runs"),
    # two engines share the budget: 2 x 2 x (2 cells + 7 threshold runs) = 36 runs > 35
    (["map", "--engine", "pymunk,mujoco", "--engine-omega", "9:10:1", "--engine-amplitude",
      "5:6:1", "--max-engine-runs", "35"], "at least 36 runs"),
    (["map", "--plot", "m.txt"], "--plot"),
])
def test_cli_bad_input(argv, needle, capsys):
    assert cli_main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and needle in err and len(err.strip().splitlines()) == 1


def test_cli_engines_beside_the_analytic_map(tmp_path, capsys):
    """--engine takes a list: one map per engine on its coarser grid, in the JSON,
    the CSV and the plot (one panel each); every engine cell has a verdict."""
    csv, png = tmp_path / "m.csv", tmp_path / "m.png"
    assert cli_main(["map", "--omega", "9:11:1", "--amplitude", "2:20:2", "--engine",
                     "pymunk,mujoco", "--engine-omega", "9:11:2", "--engine-amplitude", "4:16:12",
                     "--workers", "2", "--json", "--csv", str(csv), "--plot", str(png)]) == 0
    maps = json.loads(capsys.readouterr().out)["maps"]
    assert [m["backend"] for m in maps] == ["analytic-fast", "pymunk", "mujoco"]
    for m in maps[1:]:
        assert m["omega"] == [9.0, 11.0] and m["amplitude"] == [4.0, 16.0]
        # One robust threshold per engine frequency, the EnginePoint of spectrum --engine.
        assert [p["omega"] for p in m["thresholds"]] == [9.0, 11.0]
        for p in m["thresholds"]:
            for key in ("a_engine", "a_survives", "isolated", "rel_error", "rel_resolution",
                        "cause", "causes", "valid", "cpu_s"):
                assert key in p, key
            assert p["a_survives"] < p["a_engine"]
            assert p["a_engine"] - p["a_survives"] <= 0.005 * p["a_reference"] * (1 + 1e-9)
        assert m["threshold_cost"]["runs"] >= 7 * 2
    rows = csv.read_text().splitlines()
    assert rows[0].split(",")[:4] == ["backend", "omega", "amplitude", "verdict"]
    cells = [r for r in rows[1:] if "(robust)" not in r]
    brackets = [r.split(",") for r in rows[1:] if "(robust)" in r]
    assert len(cells) == 30 + 2 * 4 and len(brackets) == 2 * 2
    assert {r.split(",")[0] for r in cells} == {"analytic-fast", "pymunk", "mujoco"}
    assert all(len(r) == len(rows[0].split(",")) for r in brackets)
    assert png.stat().st_size > 0
