"""The project's fragility fits against an independent maximum-likelihood fit of
the same data, written here from the likelihoods and maximised by
``scipy.optimize`` (Nelder-Mead, a method neither fit uses): the IDA fit
(lognormal with right censoring, ``compare.measure.fragility.fit_lognormal``)
and the MSA fit (binomial counts per stripe, ``compare.measure.msa``, Baker
2015), agreeing to 1e-3 (relative) in the median and beta, on generated data
and on the model's results for the shipped synthetic suite.  One test shows
the tolerance is tight enough to catch a plausible mistake."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize, stats

from trilith_xval.compare.measure.fragility import fit_lognormal, fragility
from trilith_xval.compare.measure.msa import fit_stripes, msa_fragility

TOL = 1e-3


def independent_censored(im: np.ndarray, censored_at: float) -> tuple[float, float]:
    """Maximise sum log f(x_i) over the overturns + n_c log(1 - F(c)): the
    lognormal density and survival written out, in (ln median, ln beta)."""
    seen = im[np.isfinite(im)]
    n_cens = int(np.sum(~np.isfinite(im)))

    def nll(p):
        mu, beta = p[0], math.exp(p[1])
        zs = (np.log(seen) - mu) / beta
        ll = np.sum(-0.5 * zs ** 2 - math.log(beta) - np.log(seen) - 0.5 * math.log(2 * math.pi))
        if n_cens:
            ll += n_cens * stats.norm.logsf((math.log(censored_at) - mu) / beta)
        return -ll
    start = [float(np.log(seen).mean()), math.log(max(float(np.log(seen).std()), 0.05))]
    res = optimize.minimize(nll, start, method="Nelder-Mead",
                            options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20_000})
    assert res.success, res.message
    return math.exp(res.x[0]), math.exp(res.x[1])


def independent_binomial(stripes, n, z) -> tuple[float, float]:
    """Maximise sum log Binom(z_j; n_j, Phi(ln(x_j / median) / beta))."""
    x, n, z = (np.asarray(v, dtype=float) for v in (stripes, n, z))

    def nll(p):
        prob = stats.norm.cdf((np.log(x) - p[0]) / math.exp(p[1]))
        return -np.sum(stats.binom.logpmf(z, n, np.clip(prob, 1e-300, 1 - 1e-16)))
    res = optimize.minimize(nll, [float(np.log(x).mean()), math.log(0.5)],
                            method="Nelder-Mead",
                            options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20_000})
    assert res.success, res.message
    return math.exp(res.x[0]), math.exp(res.x[1])


def _lognormal(seed: int, n: int, median=8.0, beta=0.35) -> np.ndarray:
    return median * np.exp(beta * np.random.default_rng(seed).standard_normal(n))


@pytest.mark.parametrize("seed, n, cut", [(1, 12, math.inf), (2, 12, 9.0), (3, 30, 7.0),
                                          (4, 6, 10.0)])
def test_ida_fit_equals_an_independent_censored_mle(seed, n, cut):
    im = _lognormal(seed, n)
    im = np.where(im <= cut, im, math.inf)
    assert np.sum(np.isfinite(im)) >= 2
    censored_at = cut if math.isfinite(cut) else math.inf
    m, b = fit_lognormal(im, censored_at)
    m_ref, b_ref = independent_censored(im, cut)
    assert m == pytest.approx(m_ref, rel=TOL)
    assert b == pytest.approx(b_ref, rel=TOL)
    # fragility() reports the same fit it bootstraps.
    if math.isfinite(cut):
        fit = fragility(im, censored_at=cut, n_boot=20)
        assert (fit.median, fit.beta) == (m, b)
        assert fit.median_ci[0] <= fit.median_ci[1] and fit.beta_ci[0] <= fit.beta_ci[1]


@pytest.mark.parametrize("seed, records, stripes", [
    (5, 12, (2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 15.0)),
    (6, 40, (3.0, 5.0, 7.0, 9.0, 11.0)),
    (7, 10, (1.0, 6.0, 8.0, 9.5, 20.0))])
def test_msa_fit_equals_an_independent_binomial_mle(seed, records, stripes):
    rng = np.random.default_rng(seed)
    p = stats.norm.cdf(np.log(np.array(stripes) / 8.0) / 0.4)
    verdicts = rng.random((records, len(stripes))) < p
    fit = msa_fragility(verdicts, stripes, n_boot=50)
    assert math.isfinite(fit.median), fit
    m_ref, b_ref = independent_binomial(stripes, fit.n, fit.overturned)
    assert fit.median == pytest.approx(m_ref, rel=TOL)
    assert fit.beta == pytest.approx(b_ref, rel=TOL)
    assert sum(fit.overturned) == int(verdicts.sum())
    assert fit.median_ci[0] <= fit.median <= fit.median_ci[1]


def test_msa_without_a_finite_maximum_has_no_fit():
    # Every run below 6 survives, every one above overturns: beta -> 0.
    assert all(math.isnan(v) for v in fit_stripes([2, 4, 6, 8], [5] * 4, [0, 0, 5, 5]))
    assert all(math.isnan(v) for v in fit_stripes([2, 4], [5, 5], [0, 0]))


def test_the_tolerance_catches_a_plausible_mistake():
    """The unbiased standard deviation (ddof=1) in place of the MLE's is a small,
    plausible slip: on twelve motions it moves beta by 4 %, forty times the
    tolerance; so is a fit that drops the censored motions."""
    im = _lognormal(1, 12)
    _, b_ref = independent_censored(im, math.inf)
    wrong = float(np.log(im).std(ddof=1))
    assert abs(wrong / b_ref - 1.0) > 10 * TOL
    cut = 9.0
    cens = np.where(im <= cut, im, math.inf)
    m_ref, _ = independent_censored(cens, cut)
    dropped = math.exp(float(np.log(cens[np.isfinite(cens)]).mean()))
    assert abs(dropped / m_ref - 1.0) > 10 * TOL


# The model's results on the shipped suite (trilith fragility --records synthetic
# --no-pendulum --stripes 0.2g,0.3g,0.4g,0.5g,0.6g,0.8g,1g, fragility.json): each
# motion's first overturning PGA [m/s^2], and the overturns at each stripe.
SUITE_IDA = [9.745387487932174, 5.820708166324371, 2.560802077516948, 4.6381184430960625,
             4.719859436922727, 2.970759323818459, 12.123820210630777, 4.033146472257445,
             2.408910742248223, 5.9232908140354406, 6.0805645141863796, 2.843802251582252]
SUITE_STRIPES_G = [0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0]
SUITE_OVERTURNED = [0, 2, 4, 7, 9, 9, 11]


def test_the_suites_fits_equal_the_independent_mle():
    im = np.array(SUITE_IDA)
    m, b = fit_lognormal(im, censored_at=20.0)
    m_ref, b_ref = independent_censored(im, 20.0)
    assert (m, b) == (pytest.approx(m_ref, rel=TOL), pytest.approx(b_ref, rel=TOL))
    stripes = [9.80665 * s for s in SUITE_STRIPES_G]
    m, b = fit_stripes(stripes, [12] * 7, SUITE_OVERTURNED)
    m_ref, b_ref = independent_binomial(stripes, [12] * 7, SUITE_OVERTURNED)
    assert (m, b) == (pytest.approx(m_ref, rel=TOL), pytest.approx(b_ref, rel=TOL))
    # The printed fits of docs/earthquakes.md.
    assert m == pytest.approx(4.81, abs=0.005) and b == pytest.approx(0.490, abs=0.0005)
