"""Fragility statistics: the lognormal maximum-likelihood fit (with right
censoring) recovers known parameters within their sampling error; the bootstrap
band covers the truth; the agreement of a curve with itself is exact."""
from __future__ import annotations

import math

import numpy as np
import pytest

from trilith_xval.compare.measure.fragility import agreement, empirical_curve, fit_lognormal, fragility

MEDIAN, BETA, N = 3.0, 0.4, 4000


def sample(seed=1):
    return MEDIAN * np.exp(BETA * np.random.default_rng(seed).standard_normal(N))


def test_fit_recovers_median_and_beta():
    m, b = fit_lognormal(sample(), censored_at=math.inf)
    # Standard errors of the MLE: median * beta / sqrt(N) and beta / sqrt(2N);
    # four of them make a false failure a 6e-5 event.
    assert m == pytest.approx(MEDIAN, abs=4 * MEDIAN * BETA / math.sqrt(N))
    assert b == pytest.approx(BETA, abs=4 * BETA / math.sqrt(2 * N))


def test_censored_fit_is_unbiased_where_dropping_is_not():
    im = sample()
    cut = 3.5  # about 65 % overturn below it
    censored = np.where(im <= cut, im, np.inf)
    m, b = fit_lognormal(censored, censored_at=cut)
    # Censoring costs information: allow six standard errors of the full sample.
    assert m == pytest.approx(MEDIAN, abs=6 * MEDIAN * BETA / math.sqrt(N))
    assert b == pytest.approx(BETA, abs=6 * BETA / math.sqrt(2 * N))
    naive = np.log(im[im <= cut])
    assert math.exp(naive.mean()) < 0.9 * MEDIAN  # the bias the censored fit avoids


def test_band_covers_the_truth_and_empirical_steps():
    im = sample(2)[:60]
    fit = fragility(im, censored_at=50.0, n_boot=300)
    grid, lo, hi = fit.band
    from scipy import stats
    truth = stats.norm.cdf(np.log(grid / MEDIAN) / BETA)
    # A 90 % pointwise band of 60 motions: the truth may leave it at a few points.
    assert np.mean((truth >= lo - 1e-12) & (truth <= hi + 1e-12)) > 0.8
    x, f = empirical_curve(im)
    assert np.all(np.diff(x) >= 0) and f[-1] == 1.0


def test_too_few_overturns_give_no_fit():
    m, b = fit_lognormal(np.array([2.0, np.inf, np.inf]), censored_at=10.0)
    assert math.isnan(m) and math.isnan(b)


def test_agreement():
    a = fragility(sample(3)[:40], censored_at=50.0, n_boot=50)
    assert agreement(a, a) == {"median_ratio": 1.0, "max_distance_fit": 0.0,
                               "max_distance_empirical": 0.0}
    b = fragility(2.0 * np.asarray(a.im), censored_at=100.0, n_boot=50)
    ag = agreement(a, b)
    assert ag["median_ratio"] == pytest.approx(2.0, rel=1e-9)  # the MLE median scales
    assert ag["max_distance_empirical"] > 0.5


# ------------------------------------------------------------ argument checks
@pytest.mark.parametrize("im, exc, needle", [
    ([1.0, float("nan"), 2.0], ValueError, "im must hold intensities > 0.*nan at index 1"),
    ([1.0, -2.0, 3.0], ValueError, "im must hold intensities > 0.*-2.0 at index 1"),
    ([0.0, 1.0], ValueError, "im must hold intensities > 0"),
    ([1.5], ValueError, "im must hold at least 2"),
    ([], ValueError, "im must hold at least 2"),
    ("12", TypeError, "im must be a sequence"),
    ([[1.0, 2.0]], ValueError, "im must be one-dimensional"),
    (["a", "b"], TypeError, "im must be a sequence of numbers"),
])
def test_fragility_refuses_bad_intensities(im, exc, needle):
    with pytest.raises(exc, match=needle):
        fragility(im, censored_at=10.0, n_boot=1)


@pytest.mark.parametrize("kwargs, exc, needle", [
    ({"censored_at": -1.0}, ValueError, "censored_at must be a finite number > 0"),
    ({"censored_at": 0.0}, ValueError, "censored_at must be a finite number > 0"),
    ({"censored_at": float("nan")}, ValueError, "censored_at"),
    ({"censored_at": "10"}, TypeError, "censored_at must be a number"),
    ({"n_boot": -5}, ValueError, r"n_boot must be in \[1, 100000\]"),
    ({"n_boot": 0}, ValueError, "n_boot must be in"),
    ({"n_boot": 2.5}, TypeError, "n_boot must be an integer"),
    ({"level": 1.5}, ValueError, r"level must be in \(0, 1\)"),
    ({"seed": "x"}, TypeError, "seed must be an integer"),
    ({"grid": [1.0, float("inf")]}, ValueError, "grid must hold"),
])
def test_fragility_refuses_bad_settings(kwargs, exc, needle):
    args = {"censored_at": 10.0, "n_boot": 2, **kwargs}
    with pytest.raises(exc, match=needle):
        fragility([1.0, 2.0, math.inf], **args)


def test_sizes_are_capped_before_any_work():
    import time

    from trilith_xval.analytic.spectrum import overturning_spectrum
    from trilith_xval.scenes import load_scene
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="im has 10000000 values, more than 100000"):
        fragility(np.ones(10_000_000), censored_at=10.0)
    with pytest.raises(ValueError, match="omegas has 1000000 frequencies, more than"):
        overturning_spectrum(load_scene("fig5"), np.linspace(1.0, 20.0, 1_000_000))
    assert time.perf_counter() - t0 < 5.0


def test_fit_lognormal_and_empirical_curve_check_their_input():
    with pytest.raises(ValueError, match="censored_at"):
        fit_lognormal([1.0, 2.0], censored_at=-1.0)
    with pytest.raises(ValueError, match="im must hold intensities > 0"):
        empirical_curve([1.0, float("nan")])
