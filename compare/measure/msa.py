"""Multiple-stripe analysis (MSA): a fragility curve from overturn counts at a few
intensity levels.

Baker (2015), "Efficient analytical fragility function fitting using dynamic
structural analysis", *Earthquake Spectra* 31(1), 579-599: at each stripe
``x_j`` every motion of the suite is scaled to ``x_j`` and run once; ``z_j`` of
the ``n_j`` runs overturn.  The lognormal curve ``P(x) = Phi(ln(x / median) /
beta)`` is fitted by maximising the binomial likelihood

    ``L = prod_j C(n_j, z_j) P(x_j)^z_j (1 - P(x_j))^(n_j - z_j)``

(Baker's eq. 11).  Unlike incremental dynamic analysis (:mod:`analytic.ida`),
which keeps each motion's *first* overturning intensity, a stripe counts the
verdict at that intensity: a motion inside a survival island above its first
overturn counts as survived.  Where the response is monotonic in the intensity
the two estimate the same curve.

The fit is a probit regression on ``ln x`` (``Phi(a + b ln x)``, ``beta = 1 /
b``, ``median = exp(-a / b)``), solved by Newton's method with step halving:
the probit log-likelihood is concave in ``(a, b)``, so the iteration converges
whenever a finite maximum exists.  None exists (no fit, NaNs) when no run or
every run overturned, or when the stripes separate the outcomes completely
(all survive below some level, all overturn above it: the likelihood grows as
``beta -> 0``), or when the fitted curve would fall with the intensity.

Uncertainty: a bootstrap over the motions (each motion keeps its verdicts at
every stripe; default 400 resamples, seed 0), percentile intervals of the
median and beta at ``level`` (default 90 %).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special, stats

__all__ = ["MSAFit", "fit_stripes", "msa_fragility", "check_stripes", "MAX_STRIPES"]

MAX_STRIPES = 100  # stripes per analysis: Baker uses about ten


def check_stripes(stripes, name: str = "stripes") -> tuple[float, ...]:
    """``stripes`` sorted, as floats: at least two distinct finite values > 0,
    at most :data:`MAX_STRIPES`; ``ValueError`` naming ``name`` otherwise."""
    try:
        values = [float(v) for v in stripes]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers, got {stripes!r}") from None
    bad = [v for v in values if not (math.isfinite(v) and v > 0.0)]
    if bad:
        raise ValueError(f"{name} must be finite and > 0, got {bad[0]!r}")
    values = sorted(set(values))
    if not 2 <= len(values) <= MAX_STRIPES:
        raise ValueError(f"{name} needs 2 to {MAX_STRIPES} distinct intensities, "
                         f"got {len(values)}")
    return tuple(values)


def _separated(z: np.ndarray, n: np.ndarray) -> bool:
    """True when some level splits the stripes into all-survived below and
    all-overturned above: the binomial likelihood then has no finite maximum."""
    none, every = z == 0, z == n
    return any(np.all(none[:k]) and np.all(every[k:]) for k in range(len(z) + 1))


def _loglik(a: float, b: float, x, z, n) -> float:
    eta = a + b * x
    return float(np.sum(z * special.log_ndtr(eta) + (n - z) * special.log_ndtr(-eta)))


def fit_stripes(stripes, n, overturned) -> tuple[float, float]:
    """``(median, beta)`` maximising the binomial likelihood of ``overturned``
    out of ``n`` runs at each of ``stripes`` (module docstring); NaNs when no
    finite maximum exists.

    Parameters
    ----------
    stripes : sequence of float
        The intensities, > 0, in any order (at least two distinct).
    n, overturned : sequence of int
        Runs and overturns per stripe, ``0 <= overturned <= n``.
    """
    x = np.log(np.asarray(stripes, dtype=float))
    n = np.asarray(n, dtype=float)
    z = np.asarray(overturned, dtype=float)
    if not (x.shape == n.shape == z.shape and x.ndim == 1):
        raise ValueError("stripes, n and overturned must be sequences of one length")
    if np.any(n < 0) or np.any(z < 0) or np.any(z > n):
        raise ValueError("each stripe needs 0 <= overturned <= n")
    keep = n > 0
    x, n, z = x[keep], n[keep], z[keep]
    order = np.argsort(x)
    x, n, z = x[order], n[order], z[order]
    if np.unique(x).size < 2 or _separated(z, n):
        return math.nan, math.nan
    # Start at beta 0.5 about the geometric middle of the stripes: any start
    # converges on a concave likelihood; this one is a few steps from typical fits.
    b = 2.0
    a = -b * float(np.mean(x))
    ll = _loglik(a, b, x, z, n)
    for _ in range(200):
        eta = a + b * x
        # d/d eta of log Phi(eta) and log Phi(-eta), written with log_ndtr so
        # that far tails neither overflow nor divide by zero.
        r1 = np.exp(stats.norm.logpdf(eta) - special.log_ndtr(eta))
        r0 = np.exp(stats.norm.logpdf(eta) - special.log_ndtr(-eta))
        g_eta = z * r1 - (n - z) * r0
        # The exact Hessian of the probit log-likelihood (negative definite).
        h_eta = -z * r1 * (eta + r1) - (n - z) * r0 * (r0 - eta)
        grad = np.array([g_eta.sum(), (g_eta * x).sum()])
        hess = np.array([[h_eta.sum(), (h_eta * x).sum()],
                         [(h_eta * x).sum(), (h_eta * x * x).sum()]])
        try:
            step = np.linalg.solve(hess, -grad)
        except np.linalg.LinAlgError:
            return math.nan, math.nan
        t = 1.0
        while t > 1e-12:
            a1, b1 = a + t * step[0], b + t * step[1]
            ll1 = _loglik(a1, b1, x, z, n)
            if ll1 >= ll - 1e-12 * abs(ll):
                break
            t /= 2.0
        a, b, ll = a1, b1, ll1
        if np.max(np.abs(t * step)) < 1e-12 * (1.0 + abs(a) + abs(b)):
            break
    if not (math.isfinite(a) and math.isfinite(b)) or b <= 0.0:
        return math.nan, math.nan
    return float(math.exp(-a / b)), float(1.0 / b)


@dataclass(frozen=True)
class MSAFit:
    """A multiple-stripe fragility curve of one backend: ``stripes`` [IM unit],
    ``n`` and ``overturned`` per stripe, the maximum-likelihood ``median`` and
    ``beta`` (NaN: no fit), their bootstrap percentile intervals at ``level``
    from ``n_boot`` resamples of the motions with ``seed`` (``n_boot_fitted`` of
    which had a fit)."""

    stripes: tuple
    n: tuple
    overturned: tuple
    median: float
    beta: float
    median_ci: tuple
    beta_ci: tuple
    level: float
    n_boot: int
    n_boot_fitted: int
    seed: int

    def cdf(self, x) -> np.ndarray:
        from trilith_xval.compare.measure.fragility import lognormal_cdf
        return lognormal_cdf(x, self.median, self.beta)

    def describe(self) -> dict:
        fin = lambda v: float(v) if math.isfinite(v) else None  # noqa: E731
        return {"stripes": list(self.stripes), "n": list(self.n),
                "overturned": list(self.overturned), "median": fin(self.median),
                "beta": fin(self.beta), "median_ci": [fin(v) for v in self.median_ci],
                "beta_ci": [fin(v) for v in self.beta_ci],
                "bootstrap": {"resamples": self.n_boot, "fitted": self.n_boot_fitted,
                              "seed": self.seed, "level": self.level}}


def msa_fragility(verdicts, stripes, n_boot: int = 400, level: float = 0.9,
                  seed: int = 0) -> MSAFit:
    """The MSA fit of a suite and its bootstrap intervals.

    Parameters
    ----------
    verdicts : array of bool, shape (motions, stripes)
        ``verdicts[i, j]``: motion ``i`` scaled to ``stripes[j]`` overturned.
    stripes : sequence of float
        Increasing intensities > 0 (:func:`check_stripes`).
    n_boot, level, seed
        Resamples of the motions (1 to 100000), interval level in (0, 1), seed.
    """
    stripes = check_stripes(stripes)
    v = np.asarray(verdicts, dtype=bool)
    if v.ndim != 2 or v.shape[1] != len(stripes) or v.shape[0] < 2:
        raise ValueError(f"verdicts must have shape (motions >= 2, {len(stripes)}), "
                         f"got {v.shape}")
    if isinstance(n_boot, bool) or not isinstance(n_boot, (int, np.integer)) or not (
            1 <= n_boot <= 100_000):
        raise ValueError(f"n_boot must be an integer in [1, 100000], got {n_boot!r}")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), got {level!r}")
    n = np.full(len(stripes), v.shape[0])
    z = v.sum(axis=0)
    median, beta = fit_stripes(stripes, n, z)
    rng = np.random.default_rng(seed)
    params = []
    for _ in range(n_boot):
        pick = v[rng.integers(0, v.shape[0], v.shape[0])]
        m, b = fit_stripes(stripes, n, pick.sum(axis=0))
        if math.isfinite(m) and math.isfinite(b):
            params.append((m, b))
    q = (1.0 - level) / 2.0
    if params:
        (m_lo, b_lo), (m_hi, b_hi) = np.quantile(np.array(params), [q, 1.0 - q], axis=0)
    else:
        m_lo = m_hi = b_lo = b_hi = math.nan
    return MSAFit(stripes, tuple(int(k) for k in n), tuple(int(k) for k in z), median, beta,
                  (float(m_lo), float(m_hi)), (float(b_lo), float(b_hi)), float(level),
                  int(n_boot), len(params), int(seed))
