"""Fragility curves: P(overturn | IM) over a suite of ground motions.

Each motion contributes its first overturning intensity ``IM_i``
(:func:`analytic.ida.first_overturn_intensity`), or is right-censored at the
search's ``im_hi`` when it never overturned.  Then

* the empirical curve ``F(x) = #{IM_i <= x} / N`` (all ``N`` motions, censored
  ones included in ``N``: with a common censoring level it is exact below it);
* a lognormal fit ``F(x) = Phi(ln(x / median) / beta)`` by maximum likelihood
  with the censored motions as such (:class:`scipy.stats.CensoredData`,
  ``scipy.stats.lognorm.fit`` with ``floc=0``: ``s = beta``, ``scale = median``);
* a confidence band: the pointwise percentiles of the fitted curve over a
  bootstrap of the motions (resampled with replacement; default 400 resamples,
  90 %, seed 0), and from the same resamples the percentile intervals of the
  median and of beta (resamples with fewer than two overturns have no fit and
  are left out; their number is kept).

The agreement of two curves (an engine's against the model's): the ratio of
their medians and the largest vertical distance between the fitted curves and
between the empirical ones (the Kolmogorov-Smirnov statistic of the two samples).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

__all__ = ["FragilityFit", "lognormal_cdf", "fit_lognormal", "empirical_curve", "fragility",
           "agreement", "MAX_MOTIONS", "MAX_BOOT", "MAX_GRID"]

# Sizes beyond which an argument is a mistake, not a suite: a record suite has
# tens to hundreds of motions; 1e5 uncensored ones fit in about a second, and
# 400 resamples of them in minutes.
MAX_MOTIONS = 100_000
MAX_BOOT = 100_000
MAX_GRID = 100_000


def _positive(value, name: str, infinite: bool = False) -> float:
    """``value`` as a float > 0 (finite unless ``infinite``), else
    TypeError/ValueError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number, got {value!r} ({type(value).__name__})")
    value = float(value)
    if not ((math.isfinite(value) or infinite and value == math.inf) and value > 0.0):
        raise ValueError(f"{name} must be a {'' if infinite else 'finite '}number > 0, "
                         f"got {value!r}")
    return value


def _intensities(im, name: str = "im", least: int = 1) -> np.ndarray:
    """``im`` as a 1-D float array of intensities > 0 (``inf``: censored), with
    ``least`` to :data:`MAX_MOTIONS` entries; TypeError/ValueError naming ``name``."""
    if isinstance(im, (str, bytes)) or not hasattr(im, "__len__"):
        raise TypeError(f"{name} must be a sequence of numbers, got {type(im).__name__}")
    if len(im) > MAX_MOTIONS:
        raise ValueError(f"{name} has {len(im)} values, more than {MAX_MOTIONS}")
    try:
        arr = np.asarray(im, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a sequence of numbers") from None
    if arr.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {arr.shape}")
    if arr.size < least:
        raise ValueError(f"{name} must hold at least {least} intensities (a fragility "
                         f"curve needs two motions), got {arr.size}")
    bad = np.flatnonzero(np.isnan(arr) | (arr <= 0.0) | (arr == -math.inf))
    if bad.size:
        raise ValueError(f"{name} must hold intensities > 0 (inf for a motion that never "
                         f"overturned), got {float(arr[bad[0]])!r} at index {int(bad[0])}")
    return arr


def lognormal_cdf(x, median: float, beta: float) -> np.ndarray:
    """P(overturn | IM = x) of a lognormal fragility: Phi(ln(x / median) / beta);
    NaN everywhere when there is no fit (a median or beta that is not finite)."""
    x = np.asarray(x, dtype=float)
    if not (math.isfinite(median) and math.isfinite(beta)):
        return np.full(x.shape, math.nan)
    return stats.norm.cdf(np.log(x / median) / beta)

@dataclass(frozen=True)
class FragilityFit:
    """A fragility curve of one backend.

    ``median`` [IM unit] and ``beta`` (the lognormal dispersion) of the
    maximum-likelihood fit (NaN when fewer than two motions overturned: no
    dispersion can be fitted); ``band``: ``(im_grid, lower, upper)`` of the
    bootstrap band; ``im`` the sorted first overturning intensities (``inf`` =
    censored); ``median_ci``, ``beta_ci``: the bootstrap percentile intervals at
    ``level`` (NaNs without a fitted resample) from ``n_boot`` resamples with
    ``seed``, ``n_boot_fitted`` of which had a fit."""

    median: float
    beta: float
    n: int
    n_censored: int
    im: tuple
    band: tuple
    level: float
    median_ci: tuple = (math.nan, math.nan)
    beta_ci: tuple = (math.nan, math.nan)
    n_boot: int = 0
    n_boot_fitted: int = 0
    seed: int = 0

    def cdf(self, x) -> np.ndarray:
        return lognormal_cdf(x, self.median, self.beta)

    def describe(self) -> dict:
        grid, lo, hi = self.band
        fin = lambda v: float(v) if math.isfinite(v) else None  # noqa: E731
        return {"median": fin(self.median), "beta": fin(self.beta), "n": self.n,
                "n_censored": self.n_censored, "im": [fin(v) for v in self.im],
                "band_level": self.level,
                "median_ci": [fin(v) for v in self.median_ci],
                "beta_ci": [fin(v) for v in self.beta_ci],
                "bootstrap": {"resamples": self.n_boot, "fitted": self.n_boot_fitted,
                              "seed": self.seed, "level": self.level},
                "band": {"im": [float(v) for v in grid], "lower": [fin(v) for v in lo],
                         "upper": [fin(v) for v in hi]}}


def fit_lognormal(im: np.ndarray, censored_at: float) -> tuple[float, float]:
    """``(median, beta)`` by maximum likelihood; ``inf`` entries of ``im`` are
    right-censored at ``censored_at``.  NaNs when fewer than two are uncensored.
    ``ValueError``/``TypeError`` naming the argument for intensities that are
    not > 0 (NaN included) or a ``censored_at`` that is not a finite number > 0."""
    im = _intensities(im)
    # inf: nothing was censored (a fit of complete data)
    censored_at = _positive(censored_at, "censored_at",
                            infinite=bool(np.all(np.isfinite(im))))
    seen = im[np.isfinite(im)]
    if seen.size < 2 or np.ptp(seen) == 0.0 and seen.size == im.size:
        return math.nan, math.nan
    n_cens = int(np.sum(~np.isfinite(im)))
    if n_cens == 0:
        # The closed form: the MLE of a lognormal is the mean and (biased)
        # standard deviation of ln IM.
        logs = np.log(seen)
        return float(math.exp(logs.mean())), float(logs.std())
    data = stats.CensoredData(uncensored=seen, right=np.full(n_cens, censored_at))
    s, _loc, scale = stats.lognorm.fit(data, floc=0.0)
    return float(scale), float(s)


def empirical_curve(im: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, F)``: the steps of the empirical curve at the uncensored ``IM_i``."""
    im = _intensities(im)
    x = np.sort(im[np.isfinite(im)])
    return x, np.arange(1, x.size + 1) / im.size


def fragility(im, censored_at: float, grid=None, n_boot: int = 400, level: float = 0.9,
              seed: int = 0) -> FragilityFit:
    """The fit and its bootstrap band (module docstring).

    Parameters
    ----------
    im : sequence of float
        First overturning intensities, ``inf`` for a motion that never overturned.
    censored_at : float
        The search's upper end (``IDASettings.im_hi``).
    grid : array, optional
        Intensities of the band (default: 60 points, geometric, over the data).
    n_boot, level, seed
        Bootstrap resamples (1 to :data:`MAX_BOOT`), band level in (0, 1),
        random seed (an integer; results are reproducible).

    Raises
    ------
    ValueError, TypeError
        Naming the parameter and its allowed range: ``im`` with fewer than 2 or
        more than :data:`MAX_MOTIONS` values or a value that is not > 0 (NaN
        included; ``inf`` is a censored motion), ``censored_at`` not a finite
        number > 0, ``grid`` not finite and > 0 or over :data:`MAX_GRID` points,
        ``n_boot``, ``level`` or ``seed`` out of range.
    """
    im = _intensities(im, least=2)
    censored_at = _positive(censored_at, "censored_at")
    if isinstance(n_boot, bool) or not isinstance(n_boot, (int, np.integer)):
        raise TypeError(f"n_boot must be an integer, got {n_boot!r}")
    if not 1 <= n_boot <= MAX_BOOT:
        raise ValueError(f"n_boot must be in [1, {MAX_BOOT}], got {n_boot}")
    if isinstance(level, bool) or not isinstance(level, (int, float, np.floating)):
        raise TypeError(f"level must be a number, got {level!r}")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), got {level!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be an integer, got {seed!r}")
    if grid is not None:
        grid = _intensities(grid, "grid")
        if grid.size > MAX_GRID or not np.all(np.isfinite(grid)):
            raise ValueError(f"grid must hold 1 to {MAX_GRID} finite intensities > 0")
    median, beta = fit_lognormal(im, censored_at)
    seen = im[np.isfinite(im)]
    if grid is None:
        lo = float(seen.min()) / 2.0 if seen.size else censored_at / 10.0
        grid = np.geomspace(lo, censored_at, 60)
    grid = np.asarray(grid, dtype=float)
    rng = np.random.default_rng(seed)
    curves, params = [], []
    for _ in range(n_boot):
        m, b = fit_lognormal(rng.choice(im, size=im.size, replace=True), censored_at)
        if math.isfinite(m) and math.isfinite(b) and b > 0.0:
            curves.append(stats.norm.cdf(np.log(grid / m) / b))
            params.append((m, b))
    q = (1.0 - level) / 2.0
    if curves:
        lower, upper = np.quantile(np.array(curves), [q, 1.0 - q], axis=0)
        (m_lo, b_lo), (m_hi, b_hi) = np.quantile(np.array(params), [q, 1.0 - q], axis=0)
    else:
        lower = upper = np.full(grid.shape, math.nan)
        m_lo = m_hi = b_lo = b_hi = math.nan
    return FragilityFit(median, beta, int(im.size), int(im.size - seen.size),
                        tuple(np.sort(im).tolist()), (grid, lower, upper), level,
                        (float(m_lo), float(m_hi)), (float(b_lo), float(b_hi)),
                        int(n_boot), len(params), int(seed))


def agreement(a: FragilityFit, b: FragilityFit) -> dict:
    """How ``b`` (an engine) departs from ``a`` (the model): ``median_ratio``
    (b / a), ``max_distance_fit`` (largest ``|F_b - F_a|`` of the fitted curves
    on ``a``'s band grid) and ``max_distance_empirical`` (the two-sample
    Kolmogorov-Smirnov statistic of the empirical curves)."""
    grid = np.asarray(a.band[0], dtype=float)
    d_fit = float(np.max(np.abs(b.cdf(grid) - a.cdf(grid))))
    xs = np.unique(np.concatenate([np.asarray(a.im), np.asarray(b.im)]))
    xs = xs[np.isfinite(xs)]

    def steps(fit, x):
        ims = np.asarray(fit.im, dtype=float)
        return np.array([np.sum(ims <= v) / ims.size for v in x])
    d_emp = float(np.max(np.abs(steps(a, xs) - steps(b, xs)))) if xs.size else 0.0
    ratio = b.median / a.median if a.median and math.isfinite(a.median) else math.nan
    fin = lambda v: float(v) if math.isfinite(v) else None  # noqa: E731
    return {"median_ratio": fin(ratio), "max_distance_fit": fin(d_fit),
            "max_distance_empirical": d_emp}
