"""Overturning spectra (``analytic/spectrum.py``, ``trilith spectrum``): the Fig. 5
spectrum, its points against direct runs of both paths, and the gamma = 0 frame
against its equivalent single block (rocking-frame theory)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from trilith_xval.analytic import _workers
from trilith_xval.analytic import equations as eq
from trilith_xval.analytic import fast
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.parameters import Scene
from trilith_xval.analytic.spectrum import (Spectrum, SpectrumSettings, first_overturn_amplitude,
                               overturning_spectrum)
from trilith_xval.compare.cli.main import main as cli_main
from trilith_xval.compare.cli.options import parse_omega_range

from tests.support.paths import ROOT

FIG5_OMEGA = np.arange(3.0, 31.0, 1.0)  # the paper's Fig. 5 range


@pytest.fixture(scope="module")
def fig5_spectrum(fig5) -> Spectrum:
    # Two workers whatever the machine measures (a fast one would find the
    # work not worth a second process): the pool is what is tested here.
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_workers, "POOL_START_CPU_S", 0.0)
        return overturning_spectrum(fig5, FIG5_OMEGA, workers=2)


def test_fig5_gain_never_negative(fig5_spectrum):
    """Section 5.2 / conclusions: the pendulum never lowers the overturning
    amplitude.  Each amplitude is known within tol (its bisection bracket), so
    Delta may dip below 0 by at most 100 * tol / A_np."""
    sp = fig5_spectrum
    assert np.all(np.isfinite(sp.a_no_pendulum)) and np.all(np.isfinite(sp.a_pendulum))
    slack = 100.0 * sp.tol / sp.a_no_pendulum
    assert np.all(sp.gain_percent >= -slack)


def test_fig5_brackets_and_start(fig5, fig5_spectrum):
    sp = fig5_spectrum
    for a, safe in ((sp.a_no_pendulum, sp.a_no_pendulum_safe),
                    (sp.a_pendulum, sp.a_pendulum_safe)):
        width = a - safe
        assert np.all(width > 0.0) and np.all(width <= sp.tol)
    # Eq. 11: nothing overturns below the bare frame's uplift acceleration.
    assert np.all(sp.a_no_pendulum > fig5.g / fig5.lam)


def test_fig5_matches_paper_shape(fig5_spectrum):
    """Independent of this code: the paper's Fig. 5 reports the gain range between
    Omega_1 ~ 10 and Omega_2, Delta 'almost reaching 140 % for Omega = 11', and a
    mode change on the pendulum curve between C (Omega = 9, after impact) and D
    (Omega = 11, no impact)."""
    sp = fig5_spectrum
    gain = dict(zip(sp.omega.tolist(), sp.gain_percent.tolist()))
    assert max(gain, key=gain.get) == 11.0
    assert 100.0 < gain[11.0] < 200.0  # the paper's 'almost 140 %', read off a plot
    assert all(gain[w] < 50.0 for w in (3.0, 4.0, 5.0, 6.0, 25.0, 30.0))
    modes = dict(zip(sp.omega.tolist(), sp.mode_pendulum))
    assert modes[9.0] == "after-impact" and modes[11.0] == "no-impact"
    jumps = [(j["curve"], j["omega_before"]) for j in sp.mode_jumps()]
    assert ("pendulum", 10.0) in jumps


def test_thresholds_are_those_of_the_reference_commit(fig5_spectrum):
    """Bit for bit the thresholds ``trilith spectrum --omega 3:30:1`` printed
    before its workers were decided by the work (the commit and command are in
    the file, which the spectrum CLI benchmark also reads)."""
    ref = json.loads((ROOT / "benchmarks" / "spectrum_cli_reference.json").read_text())
    got = fig5_spectrum.to_dict()
    for key, values in ref["thresholds"].items():
        assert got[key] == values, key


def test_workers_do_not_change_results(fig5, fig5_spectrum):
    sub = FIG5_OMEGA[[0, 7, 8, 15, 27]]
    one = overturning_spectrum(fig5, sub, workers=1)
    idx = [0, 7, 8, 15, 27]
    assert np.array_equal(one.a_pendulum, fig5_spectrum.a_pendulum[idx])
    assert np.array_equal(one.a_no_pendulum, fig5_spectrum.a_no_pendulum[idx])
    assert one.mode_pendulum == tuple(fig5_spectrum.mode_pendulum[i] for i in idx)


@pytest.mark.parametrize("omega", [5.0, 10.0, 11.0, 17.0, 18.0])
def test_points_agree_with_direct_runs(fig5, fig5_spectrum, run_analytic, omega):
    """At the reported amplitude both paths overturn, in the reported mode; at the
    safe end of the bracket (tol below) neither does.  Omega = 10|11 and 17|18
    straddle the mode jumps of the pendulum and bare curves."""
    sp = fig5_spectrum
    i = int(np.flatnonzero(sp.omega == omega)[0])
    for scene, a, safe, mode in (
            (fig5, sp.a_pendulum[i], sp.a_pendulum_safe[i], sp.mode_pendulum[i]),
            (fig5.without_pendulum(), sp.a_no_pendulum[i], sp.a_no_pendulum_safe[i],
             sp.mode_no_pendulum[i])):
        over_fast = fast.verdict_for(scene, Pulse(a, omega))
        safe_fast = fast.verdict_for(scene, Pulse(safe, omega))
        assert (over_fast.status, over_fast.mode) == ("overturned", mode)
        assert not safe_fast.overturned
        over_acc = run_analytic(scene, a, omega).verdict
        safe_acc = run_analytic(scene, safe, omega).verdict
        assert (over_acc.status, over_acc.mode) == ("overturned", mode)
        assert not safe_acc.overturned


# --- gamma = 0: the rocking frame is a single block ------------------------------------
def _equivalent_block(frame: Scene) -> Scene:
    """Single block (mu = 0) with the frame's equations of motion.

    Eq. 8 with gamma = 0, per m1, with R the columns' half diagonal:
    ``I theta_ddot = -2 R M (g sin(alpha - theta) - xg cos(alpha - theta))``,
    ``M = 1 + mu``, ``I = 2 R^2 (1 + 2 mu) + 2 j``; the impact ratio (Eq. 20) is
    ``(j/(1+2mu) + R^2 cos 2alpha) / (j/(1+2mu) + R^2)``.  A block of the same
    alpha has ``p^2 = g / (R' (1 + j'/R'^2))`` and ratio ``(j' + R'^2 cos 2alpha) /
    (j' + R'^2)``; both match for ``R' = R (1+2mu)/(1+mu)`` and
    ``j' = j (1+2mu)/(1+mu)^2``.  For uniform columns this is Makris & Vassiliou's
    frame: ``p_frame^2 = p^2 (1+mu)/(1+1.5 mu)`` (checked below).
    """
    mu = frame.mu
    scale = (1.0 + 2.0 * mu) / (1.0 + mu)
    j_block = frame.j * (1.0 + 2.0 * mu) / (1.0 + mu) ** 2
    return Scene(b=frame.b * scale, lam=frame.lam, mu=0.0, gamma=0.0, column_mass=1.0,
                 J_G=j_block, g=frame.g, name="equivalent-block")


def test_frame_frequency_parameter_is_makris_vassiliou(fig5):
    for mu in (0.5, 1.0, 3.0):
        frame = fig5.replace(mu=mu, gamma=0.0)
        b, h, _, _, j, _, g = frame.model_args()
        p2 = eq.total_mass(mu, 0.0) * g * math.hypot(b, h) / eq.rocking_inertia(b, h, mu, 0.0, j)
        p2_block = 3.0 * g / (4.0 * frame.R)  # uniform block: p^2 = 3 g / (4 R)
        assert p2 == pytest.approx(p2_block * (1.0 + mu) / (1.0 + 1.5 * mu), rel=1e-12)


@pytest.mark.parametrize("mu", [1.0, 3.0])
def test_bare_frame_spectrum_is_the_equivalent_blocks(fig5, mu):
    frame = fig5.replace(mu=mu, gamma=0.0)
    block = _equivalent_block(frame)
    naive = Scene(b=frame.b, lam=frame.lam, mu=0.0, gamma=0.0)  # same column, no lintel
    fb, bb = frame.model_args(), block.model_args()
    assert eq.restitution_ratio(0.0, 1.0, *fb[:5]) == pytest.approx(
        eq.restitution_ratio(0.0, 1.0, *bb[:5]), rel=1e-12)
    ss = SpectrumSettings()
    moved = 0
    for omega in (5.0, 11.0, 18.0, 25.0):
        a_frame = first_overturn_amplitude(frame, omega, ss)[0]
        a_block = first_overturn_amplitude(block, omega, ss)[0]
        # Same equations up to round-off: the two bisections end within tol.
        assert a_frame == pytest.approx(a_block, abs=ss.tol)
        a_naive = first_overturn_amplitude(naive, omega, ss)[0]
        moved += abs(a_naive - a_frame) > 10 * ss.tol
        # Uplift (Eq. 11) depends on alpha only: the same instant for all three.
        pulse = Pulse(a_frame, omega)
        t_up = [fast.simulate(s, pulse).uplift_time for s in (frame, block, naive)]
        assert t_up[0] == pytest.approx(t_up[1], abs=1e-12)
        assert t_up[0] == pytest.approx(t_up[2], abs=1e-12)
    assert moved >= 3  # the lintel does matter: the check is not vacuous


# --- parsing, output and CLI -------------------------------------------------------------
def test_parse_omega_range():
    assert parse_omega_range("3:30:1").tolist() == list(range(3, 31))
    assert parse_omega_range("3:4:0.1").size == 11
    assert parse_omega_range("5,7.5").tolist() == [5.0, 7.5]
    for bad in ("3:30", "a:b:c", "3:1:1", "0:3:1", "3:4:0", "3:4:-1", "", "1e5"):
        with pytest.raises(ValueError, match="--omega"):
            parse_omega_range(bad)


def test_settings_validation():
    for bad in ({"tol": 0.0}, {"scan_step": -1.0}, {"a_max": math.inf}, {"pulse": "square"},
                {"start_fraction": 1.5}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            SpectrumSettings(**bad)
    with pytest.raises(ValueError, match="tol"):
        SpectrumSettings(tol=0.5, scan_step=0.1)


def test_cli_json(capsys):
    assert cli_main(["spectrum", "--omega", "10,11", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("omega", "a_no_pendulum", "a_pendulum", "gain_percent", "mode_no_pendulum",
                "mode_pendulum", "criterion", "t_max", "tol", "mode_jumps"):
        assert key in out
    assert out["omega"] == [10.0, 11.0] and out["tol"] == 0.01 and out["t_max"] is None
    assert out["mode_pendulum"] == ["after-impact", "no-impact"]


def test_cli_bad_omega(capsys):
    assert cli_main(["spectrum", "--omega", "30:3:1"]) == 2
    assert "--omega" in capsys.readouterr().err
