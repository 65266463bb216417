"""``trilith map --record``: intensity x time scale of a record; every cell is
the verdict of one model run in the fixed window, bad grids refused at the door."""
from __future__ import annotations

import json

import numpy as np
import pytest

from trilith_xval.compare.cli.main import main


@pytest.fixture
def short_record(tmp_path):
    t = np.arange(0.0, 1.5, 0.01)
    a = np.where(t <= 2 * np.pi / 9.0, np.sin(9.0 * t), 0.0)
    path = tmp_path / "half_sine.csv"
    np.savetxt(path, np.column_stack([t, a]), delimiter=",", header="t,a", comments="")
    return str(path)


def test_cells_are_the_model_verdicts(short_record, tmp_path, capsys):
    """Each cell against a direct run of the accurate model: the record scaled to
    the PGA, played k times slower, in the window end + tail."""
    from trilith_xval.analytic.ida import scale_to
    from trilith_xval.analytic.simulate import Settings, simulate
    from trilith_xval.scenes import load_record, load_scene
    from trilith_xval.scenes.ground_motion import time_scaled
    argv = ["map", "--record", short_record, "--no-pendulum", "--intensity", "6,12,24",
            "--time-scale", "0.8,1.6", "--tail", "1", "--workers", "1", "--json",
            "--cache", str(tmp_path / "cache")]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    (m,) = doc["maps"]
    scene, rec = load_scene("fig5").without_pendulum(), load_record(short_record)
    for j, k in enumerate(m["omega"]):
        for i, v in enumerate(m["amplitude"]):
            motion = scale_to(time_scaled(rec, k), "pga", v)
            verdict = simulate(scene, motion, Settings(t_max=motion.end_time + 1)).verdict
            assert m["labels"][m["cells"][i][j]].startswith(verdict.status)
    assert m["counts"]["survived"] and sum(n for lab, n in m["counts"].items()
                                           if lab.startswith("overturned"))


@pytest.mark.parametrize("extra, needle", [
    (["--omega", "3:10:1"], "--record maps the record's intensity and time scale: drop --omega"),
    (["--pulse", "ricker"], "drop --pulse"),
    (["--time-scale", "0.5:20:0.5"], "--time-scale"),
    (["--intensity", "1:500:1"], "more than 400"),
    (["--tail", "-1"], "--tail must be in [0, 600] s"),
    (["--engine", "pymunk", "--intensity", "1:10:1", "--time-scale", "0.5:2:0.1",
      "--max-engine-runs", "4"], "more than --max-engine-runs 4")])
def test_bad_record_map_refused(short_record, extra, needle, no_work, capsys):
    assert main(["map", "--record", short_record, *extra]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and needle in err[0], err
