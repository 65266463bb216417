"""`trilith spectrum --record FILE` gives the first overturning scale factor of the
file's record and the PGA it means (text and JSON), the same whatever --scale."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from trilith_xval.analytic.excitation import G_STANDARD
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_record

# A short record (one sine cycle of 0.5 m/s^2 at 8 rad/s, 1.5 s) and a coarse
# search keep each IDA to a second.
SEARCH = ["--no-pendulum", "--no-cache", "--im-range", "1:40", "--rel-step", "0.5",
          "--rtol", "0.1", "--tail", "1", "--workers", "1"]


@pytest.fixture
def record(tmp_path) -> str:
    t = np.arange(0.0, 1.5, 0.01)
    a = np.where(t <= 2 * np.pi / 8.0, 0.5 * np.sin(8.0 * t), 0.0)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([t, a]), delimiter=",", header="t,a", comments="")
    return str(path)


def _json(capsys, record, *extra) -> dict:
    assert main(["spectrum", "--record", record, *SEARCH, "--json", *extra]) == 0
    return json.loads(capsys.readouterr().out)["backends"]["analytic"]


def test_scale_factor_and_its_pga(capsys, record):
    pga_file = load_record(record).pga
    r = _json(capsys, record)
    assert r["im"] == "pga"
    # The PGA searched is the factor's PGA: two routes to one number (rounding only).
    assert r["pga_overturn"] == pytest.approx(r["im_overturn"], rel=1e-12)
    assert r["scale_overturn"] == pytest.approx(r["im_overturn"] / pga_file, rel=1e-12)
    # Scaled on the command line, the factor still refers to the file's record.
    assert _json(capsys, record, "--scale", "2")["scale_overturn"] == pytest.approx(
        r["scale_overturn"], rel=1e-9)
    assert r["scale_overturn"] > 1.5  # the search found a factor, not the record itself
    assert main(["spectrum", "--record", record, *SEARCH]) == 0
    out = capsys.readouterr().out
    m = re.search(r"analytic: scale factor (\S+) \(PGA (\S+) m/s\^2, (\S+) g\)", out)
    assert m, out
    assert float(m.group(1)) == pytest.approx(r["scale_overturn"], rel=1e-3)  # 4 digits
    assert float(m.group(2)) == pytest.approx(r["pga_overturn"], rel=1e-3)
    assert float(m.group(3)) == pytest.approx(r["pga_overturn"] / G_STANDARD, rel=1e-2)
