"""Fragility statistics: the lognormal maximum-likelihood fit (with right
censoring) recovers known parameters within their sampling error; the bootstrap
band covers the truth; the agreement of a curve with itself is exact."""
from __future__ import annotations

import math

import numpy as np
import pytest

from compare.measure.fragility import agreement, empirical_curve, fit_lognormal, fragility

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
