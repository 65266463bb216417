"""``trilith map`` on scenes the model does not cover: the engines' own map (each
engine's verdict per cell, its first failure on the grid, the cells where the
engines disagree), marked engine against engine; bad input refused before work."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.cli.map_kinds import BASIS, STATUSES, KindMap

GRID = ["--engine-omega", "6:12:3", "--engine-amplitude", "2:8:3"]


def test_map_on_drums_writes_each_engines_verdicts_whole(tmp_path, capsys):
    out_csv, out_png = tmp_path / "d.csv", tmp_path / "d.png"
    # A 2 s window: the 6 rad/s pulse ends at 1.05 s, every column has fallen or
    # come back by then at these amplitudes (checked below: no 'undecided').
    assert main(["map", "--scene", "drums", "--engine", "pymunk,mujoco", *GRID, "--t-max",
                 "2", "--cache", str(tmp_path / "store"), "--csv", str(out_csv),
                 "--plot", str(out_png), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["model"] is None and doc["kind"] == "drums" and doc["basis"] == BASIS
    cells = {e: np.array(v["cells"]) for e, v in doc["engines"].items()}
    assert set(cells) == {"pymunk", "mujoco"}
    for e, grid in cells.items():
        assert grid.shape == (3, 3) and set(grid.ravel()) <= {"survived", "overturned",
                                                             "collapsed"}
        # 2 m/s^2 barely passes the column's uplift g b / H = 1.96 m/s^2; 8 m/s^2 at
        # 6 rad/s is over twice the engines' 8 rad/s threshold (docs/geometry.md).
        assert list(grid[0]) == ["survived"] * 3 and grid[2, 0] == "overturned"
        first = doc["engines"][e]["first_failure"]
        for j in range(3):
            fails = [i for i in range(3) if grid[i, j] in ("overturned", "collapsed")]
            assert first[j] == (doc["amplitude"][fails[0]] if fails else None)
    differ = cells["pymunk"] != cells["mujoco"]
    assert doc["disagreements"] == int(differ.sum())
    assert np.array_equal(np.array(doc["agree"]), ~differ)
    with open(out_csv, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 18 and all(r["basis"] == BASIS for r in rows)
    assert {(r["engine"], float(r["omega"]), float(r["amplitude"]), r["verdict"]) for r in rows} \
        == {(e, w, a, cells[e][i, j]) for e in cells for j, w in enumerate(doc["omega"])
            for i, a in enumerate(doc["amplitude"])}
    assert out_png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert any((tmp_path / "store").iterdir())  # the cells went through the run store


def test_disagreements_are_counted_and_hatched(tmp_path):
    # Two engines' grids made up to differ in two cells: the count and the first
    # failure curves follow the cells.
    s, o, c = (STATUSES.index(k) for k in ("survived", "overturned", "collapsed"))
    a = np.array([[s, s], [o, s], [o, o]])
    b = np.array([[s, s], [s, s], [o, c]])
    kmap = KindMap([6.0, 9.0], [2.0, 4.0, 6.0], {"pymunk": a, "mujoco": b},
                   {"pymunk": 0.0, "mujoco": 0.0})
    assert kmap.disagreements == 2
    assert kmap.first["pymunk"].tolist() == [4.0, 6.0]
    assert kmap.first["mujoco"].tolist() == [6.0, 6.0]
    doc = kmap.to_dict()
    assert doc["engines"]["mujoco"]["cells"][2] == ["overturned", "collapsed"]
    from trilith_xval.compare.report.kind_map_plot import plot_kind_map
    from trilith_xval.scenes import load_scene
    path = tmp_path / "m.png"
    from trilith_xval.compare.cli.map_kinds import MapAxes
    axes = MapAxes("omega", "amplitude", "Omega", "Omega [rad/s]", "m/s^2", "A [m/s^2]",
                   "2 x 3", "sine pulse")
    plot_kind_map(kmap, path, load_scene("drums"), axes)
    assert path.stat().st_size > 0


BAD = [
    ([], "no analytic map of the drums kind"),
    (["--engine", "pymunk"], "give two or more"),
    (["--engine", "analytic,pymunk"], "--engine analytic: the model does not cover"),
    (["--engine", "pymunk,mujoco", "--restitution-factor", "0.9"], "no model of the drums"),
    (["--engine", "pymunk,mujoco", "--convergence"], "--convergence does not apply"),
    (["--engine", "pymunk,mujoco", "--record", "x.csv", "--consensus"],
     "--consensus with --record does not apply"),
    (["--engine", "pymunk,mujoco", "--record", "missing.csv"], "missing.csv"),
    (["--engine", "pymunk,mujoco", *GRID, "--max-engine-runs", "10"], "--max-engine-runs 10"),
    (["--engine", "pymunk,mujoco", "--engine-omega", "0:2:1"], "--engine-omega"),
]


@pytest.mark.parametrize("extra, message", BAD, ids=[m for _, m in BAD])
def test_bad_input_is_refused_in_one_line_before_work(extra, message, capsys, no_work,
                                                      tmp_path, monkeypatch):
    import trilith_xval.analytic.overturn_map as om
    monkeypatch.setattr(om, "verdict_map", lambda *a, **k: pytest.fail("map started"))
    monkeypatch.chdir(tmp_path)
    assert main(["map", "--scene", "drums", *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and message in err, err


def test_record_map_on_a_kind_is_the_engines_own(tmp_path, capsys):
    path = str(Path(__file__).parents[3] / "scenes" / "records" / "sample.AT2")
    assert main(["map", "--scene", "block_on_block", "--engine", "pymunk,mujoco", "--record",
                 path, "--intensity", "2:8:6", "--time-scale", "1:1.5:0.5", "--tail", "1",
                 "--cache", str(tmp_path / "store"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["model"] is None and doc["basis"] == BASIS
    assert doc["axes"] == {"omega": "time_scale", "amplitude": "pga"}
    assert doc["omega"] == [1.0, 1.5] and doc["amplitude"] == [2.0, 8.0]
    # 2 m/s^2 of PGA is below every static uplift: the upper block's g b/h = 3.27 m/s^2,
    # the lower block's (carrying it) higher.
    for e in ("pymunk", "mujoco"):
        assert doc["engines"][e]["cells"][0] == ["survived", "survived"]
