"""The measured-impact loader (compare/peers/impact_data.py): a synthetic drop
with a known velocity jump, bad files refused, and the user's files when a copy
of the dataset is on the machine.

Tolerances: a synthetic drop's angle is an exact parabola on each side of the
impact, so the fitted rates are exact up to floating point (1e-9 relative: a
least-squares parabola over 4 points at 4 ms spacing loses ~1e-12 per
operation); the rest of the comparisons are exact.
"""
from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from trilith_xval.compare.peers import impact_data as d

MIRROR = Path("/work/.mirror/DAIRLab+ImpactModeling/repo")
MIRROR_FOLDER = "IRB Bound/IRB Square"
A = 0.5 * d.SIDE


def synthetic(ratio: float, rate: float = -8.0, frames: int = 40, j: int = 20,
              offset: float = 0.0, rest: int = 0):
    """A square rocking on its corner 2 (``(-a, -a)``, on the ground at x = 0) onto
    its bottom face, ``th = 0`` exactly at frame ``j``, then turning at
    ``ratio * rate`` about corner 3 (continues) or corner 2 (rebounds); each
    side an exact parabola (gravity's pivot acceleration, 120 rad/s^2, towards
    flat).  ``rest`` frames lying flat follow; ``offset`` is added to ``th``."""
    t = (np.arange(frames) - j) / d.FRAME_RATE
    accel = 120.0
    th = np.where(t < 0.0, rate * t + 0.5 * accel * t * t * np.sign(rate),
                  ratio * rate * t - 0.5 * accel * t * t * np.sign(ratio * rate))
    # each side must not swing back through flat inside the file
    th = np.where(t < 0.0, th, np.where(np.sign(th) == np.sign(ratio * rate), th, 0.0))
    pivot = np.where(th > 0.0, 2, 3)
    ox, oz = d.CORNERS[pivot, 0], d.CORNERS[pivot, 1]
    c, s = np.cos(th), np.sin(th)
    px = np.where(pivot == 2, 0.0, d.SIDE)  # the corners' ground positions
    x = px - (c * ox - s * oz)
    z = -(s * ox + c * oz)
    if rest:
        x = np.concatenate([x, np.full(rest, x[-1])])
        z = np.concatenate([z, np.full(rest, A)])
        th = np.concatenate([th, np.zeros(rest)])
    return d.Trajectory("traj_1.csv", x, z, th + offset)


def write_csv(path: Path, tr: d.Trajectory) -> Path:
    rate = np.diff(np.stack([tr.x, tr.z, tr.th], axis=1), axis=0, prepend=np.nan) * d.FRAME_RATE
    rows = np.column_stack([tr.x, tr.z, tr.th, np.nan_to_num(rate)])
    path.write_text("x,z,th,vx,vz,vth\n" + "\n".join(",".join(repr(float(v)) for v in r)
                                                     for r in rows) + "\n")
    return path


@pytest.mark.parametrize("ratio, outcome, landing", [(0.25, "continues", 3),
                                                     (-0.4, "rebounds", 3)])
def test_synthetic_jump_is_measured(tmp_path, ratio, outcome, landing):
    tr = d.load_trajectory(write_csv(tmp_path / "traj_1.csv", synthetic(ratio)))
    rejected = {}
    (imp,) = d.find_impacts(tr, 0.0, rejected=rejected)
    assert imp.frame == 20
    assert imp.pivot == 2 and imp.landing == landing
    assert imp.rate_before == pytest.approx(-8.0, rel=1e-9)
    assert imp.ratio == pytest.approx(ratio, rel=1e-9)
    assert imp.outcome == outcome
    assert imp.slip == pytest.approx(0.0, abs=1e-9)
    # the replay starts one frame ahead, on the pivot, at the fitted state
    x, z, th, vx, vz, w = imp.state
    assert th == pytest.approx(8.0 / d.FRAME_RATE - 0.5 * 120.0 / d.FRAME_RATE ** 2, rel=1e-9)
    assert w == pytest.approx(-8.0 + 120.0 / d.FRAME_RATE, rel=1e-9)
    assert z == pytest.approx(tr.z[19], rel=1e-9)


def test_offset_from_resting_drops_is_removed():
    offset = math.radians(-1.9)
    trs = [synthetic(0.25, offset=offset, rest=30)]
    assert d.theta_offset(trs) == pytest.approx(offset, abs=1e-12)
    (imp,) = d.find_impacts(trs[0], d.theta_offset(trs))
    assert imp.ratio == pytest.approx(0.25, rel=1e-9)
    assert d.angle_noise(trs) == pytest.approx(0.0, abs=1e-12)


def test_filter_refuses_a_block_in_flight():
    tr = synthetic(0.25)
    lifted = d.Trajectory(tr.name, tr.x, tr.z + 0.01, tr.th)  # 10 mm above the ground
    rejected = {}
    assert d.find_impacts(lifted, rejected=rejected) == []
    assert rejected == {"no pivot on the ground before": 1}


def test_housner_ratio_is_the_projects_eq20():
    assert d.housner_ratio() == pytest.approx(0.25, rel=1e-15)
    assert d.square_scene().alpha == pytest.approx(math.pi / 4, rel=1e-15)


@pytest.mark.parametrize("text, message", [
    ("x,z,th,vx,vz\n" + "0,0,0,0,0\n" * 10, "column 'vth' is missing"),
    ("x,z,vx,th,vz,vth\n" + "0,0,0,0,0,0\n" * 10, "out of order"),
    ("x,z,th,vx,vz,vth\n" + "0,0,0,0,0,0\n" * 3 + "0,0,abc,0,0,0\n" + "0,0,0,0,0,0\n" * 6,
     "line 5: column 'th' holds 'abc'"),
    ("x,z,th,vx,vz,vth\n" + "0,nan,0,0,0,0\n" * 10, "column 'z' holds 'nan', not a finite"),
    ("x,z,th,vx,vz,vth\n" + "0,0,0,0,0\n" * 10, "line 2: 5 values, expected 6"),
    ("x,z,th,vx,vz,vth\n" + "0,0,0,0,0,0\n" * 3, "3 rows, at least 8"),
    ("", "is empty"),
], ids=["missing-column", "column-order", "not-a-number", "nan", "short-row", "few-rows",
        "empty"])
def test_bad_files_are_refused_naming_file_and_column(tmp_path, text, message):
    path = tmp_path / "traj_7.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match="traj_7.csv") as err:
        d.load_trajectory(path)
    assert message in str(err.value)


def test_bad_folders_are_refused(tmp_path):
    with pytest.raises(ValueError, match="holds no traj_<n>.csv"):
        d.load_folder(tmp_path)
    with pytest.raises(ValueError, match="is not a folder"):
        d.load_folder(tmp_path / "missing")
    (tmp_path / "traj_2.csv").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match="traj_2.csv.*not a UTF-8"):
        d.load_folder(tmp_path)


@pytest.fixture(scope="module")
def mirror_copy(tmp_path_factory):
    """Twenty drop files extracted from a local snapshot of DAIRLab/ImpactModeling."""
    if not (MIRROR / "HEAD").exists() or shutil.which("git") is None:
        pytest.skip(f"no local snapshot of DAIRLab/ImpactModeling at {MIRROR} (or no git)")
    out = tmp_path_factory.mktemp("mcube")
    for n in range(1, 21):
        blob = subprocess.run(["git", "-C", str(MIRROR), "show",
                               f"HEAD:{MIRROR_FOLDER}/traj_{n}.csv"],
                              check=True, capture_output=True).stdout
        (out / f"traj_{n}.csv").write_bytes(blob)
    return out


def test_loader_reads_the_datasets_files(mirror_copy):
    trs = d.load_folder(mirror_copy)
    assert [t.name for t in trs] == [f"traj_{n}.csv" for n in range(1, 21)]
    assert all(len(t.z) == 200 for t in trs)
    # the rate columns are backward differences at 250 Hz from the third row on
    # (module docstring); 1e-9: the files' 16 digits
    raw = np.loadtxt(mirror_copy / "traj_1.csv", delimiter=",", skiprows=1)
    for col in (3, 4, 5):
        back = np.diff(raw[:, col - 3]) * d.FRAME_RATE
        assert np.max(np.abs(raw[2:, col] - back[1:])) < 1e-9
    offset = d.theta_offset(trs)
    assert math.radians(-3.0) < offset < math.radians(-1.0)  # -1.9 deg on all 500 drops
    impacts = [imp for tr in trs for imp in d.find_impacts(tr, offset)]
    assert impacts, "some rocking-like impacts among the first 20 drops"
    for imp in impacts:
        assert abs(imp.phi) <= d.Filter().flat_tol
        assert abs(imp.rate_before) >= d.Filter().min_rate
        assert imp.landing in ((imp.pivot + 1) % 4, (imp.pivot + 3) % 4)
