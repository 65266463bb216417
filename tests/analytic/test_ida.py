"""Incremental dynamic analysis: the search on a known verdict function (first
overturn, islands, censoring), and the model's first overturning PGA of a scaled
one-sine pulse against the pulse spectrum's own search (analytic.first_overturn)."""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic.excitation import Pulse, SampledRecord
from trilith_xval.analytic.first_overturn import SpectrumSettings, first_overturn_amplitude, search_run_settings
from trilith_xval.analytic.ida import IDASettings, first_overturn_intensity, model_verdict
from trilith_xval.scenes import load_scene


def windows(*intervals):
    """A verdict function: overturns when the PGA lies in one of ``intervals``."""
    def overturns(motion):
        return any(lo <= motion.pga <= hi for lo, hi in intervals)
    return overturns


def test_first_overturn_islands_and_bracket():
    st = IDASettings(im="pga", im_lo=1.0, im_hi=20.0, rel_step=0.1, rtol=0.001)
    res = first_overturn_intensity(Pulse(1.0, 5.0), windows((2.5, 3.5), (6.0, 1e9)), st)
    assert res.im_overturn == pytest.approx(2.5, rel=0.001)
    assert res.im_safe < 2.5 <= res.im_overturn
    # The grid points between 3.5 and 6 survive: one island, at grid resolution.
    assert len(res.islands) == 1
    lo, hi = res.islands[0]
    assert 3.5 < lo <= 3.5 * 1.1 and 6.0 / 1.1 <= hi < 6.0


def test_censored_when_nothing_overturns():
    st = IDASettings(im="scale", im_lo=0.5, im_hi=2.0, rel_step=0.2, rtol=0.01)
    res = first_overturn_intensity(Pulse(1.0, 5.0), windows((100.0, 200.0)), st)
    assert res.censored and res.describe()["im_overturn"] is None


def test_overturn_at_the_first_grid_point_is_not_a_bracket():
    st = IDASettings(im="pga", im_lo=1.0, im_hi=4.0, rel_step=0.2, rtol=0.01)
    res = first_overturn_intensity(Pulse(1.0, 5.0), windows((0.0, 1e9)), st)
    assert res.im_overturn == 1.0 and math.isnan(res.im_safe)


@pytest.mark.parametrize("bad", [dict(im="pgd"), dict(im_lo=0.0), dict(im_lo=5.0, im_hi=2.0),
                                 dict(rtol=0.2, rel_step=0.1), dict(tail=-1.0)])
def test_bad_settings_name_the_field(bad):
    with pytest.raises(ValueError, match=next(iter(bad)) if "im_hi" not in bad else "im_lo"):
        IDASettings(**bad)


def test_zero_motion_is_refused():
    with pytest.raises(ValueError, match="PGA = 0"):
        first_overturn_intensity(SampledRecord((0.0, 1.0), (0.0, 0.0)), windows(), IDASettings())


def test_model_ida_of_a_pulse_equals_the_spectrum_search():
    """Scaling a one-sine pulse by its PGA is the amplitude axis of the pulse
    spectra: the IDA's first overturning PGA (accurate path) must equal
    first_overturn_amplitude's (compiled path) on the same fixed window."""
    scene = load_scene("fig5").without_pendulum()
    omega, tail = 6.0, 3.0
    pulse = Pulse(1.0, omega)
    st = IDASettings(im="pga", im_lo=2.0, im_hi=30.0, rel_step=0.1, rtol=0.002, tail=tail)
    res = first_overturn_intensity(pulse, model_verdict(scene, tail), st)
    ss = SpectrumSettings(fast=search_run_settings(t_max=pulse.period + tail))
    a_over, a_safe, _mode, _n, _und = first_overturn_amplitude(scene, omega, ss)
    # Both are brackets of the same threshold (tol 0.01 m/s^2; rtol 0.2 %): they
    # overlap unless one search found a window the other's grid stepped over.
    assert res.im_safe < a_over and a_safe < res.im_overturn
    assert res.im_overturn == pytest.approx(a_over, abs=0.01 + 0.002 * a_over)
