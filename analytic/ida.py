"""Incremental dynamic analysis: the lowest intensity at which a scaled ground
motion overturns the trilith, with the safe islands above it.

A record (or any ground motion with ``scaled``, ``pga``, ``pgv``) is scaled to an
intensity measure ``im``: the scale factor itself (``'scale'``), the peak ground
acceleration (``'pga'``, m/s^2) or the peak ground velocity (``'pgv'``, m/s).

The search (window-aware, like :mod:`analytic.first_overturn` for pulses)
-------------------------------------------------------------------------
1. Scan a geometric grid ``im_lo (1 + rel_step)^k`` up to ``im_hi``, every point
   (overturning is not monotonic in the intensity: a stronger motion can throw
   the trilith back before it falls, so survival islands lie above the first
   overturn).
2. Bisect the interval below the first overturning grid point down to a
   relative width ``rtol``.
3. Report the surviving grid points above the first overturn as islands
   (intervals of grid points, at the grid's resolution).

Guarantee: the result is the lowest overturning intensity of the grid refined to
``rtol``; an overturning window narrower than one grid step below it can be
missed (as for the pulse spectra's coarse scan; the step is a setting).  A
record that survives every grid point is right-censored at ``im_hi`` (``im =
inf``), which the fragility fit treats as such.

Every run is a function ``overturns(motion) -> bool`` (the model by default,
:func:`model_verdict`: a fixed window ``t_max = end + tail``, the same window an
engine is given, so the two are compared on the same run length; a record runs
in the compiled kernels of :mod:`analytic.fast`, whose verdicts and thresholds
are the accurate path's, ``tests/analytic/test_fast_records.py``).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Callable

__all__ = ["IM_KINDS", "IDASettings", "IDAResult", "scale_to", "intensity_of",
           "first_overturn_intensity", "model_verdict"]

IM_KINDS = ("scale", "pga", "pgv")
IM_UNITS = {"scale": "", "pga": "m/s^2", "pgv": "m/s"}


@dataclass(frozen=True)
class IDASettings:
    """How the first overturning intensity is searched (module docstring).

    Parameters
    ----------
    im : {'scale', 'pga', 'pgv'}, default 'pga'
    im_lo, im_hi : float
        The grid's ends, in the unit of ``im`` (default 0.5 to 20 m/s^2 of PGA:
        0.05 g to 2 g).
    rel_step : float, default 0.15
        Grid ratio minus one (a 15 % step: 26 runs from 0.5 to 20).
    rtol : float, default 0.01
        Relative width of the final bracket.
    tail : float, default 5.0
        Seconds run after the motion ends (``t_max = end_time + tail``): several
        free-pendulum periods of the Fig. 5 scene, where a pendulum can hand
        energy back after the motion.
    """

    im: str = "pga"
    im_lo: float = 0.5
    im_hi: float = 20.0
    rel_step: float = 0.15
    rtol: float = 0.01
    tail: float = 5.0

    def __post_init__(self) -> None:
        if self.im not in IM_KINDS:
            raise ValueError(f"im must be one of {IM_KINDS}, got {self.im!r}")
        for name, lo, hi in (("im_lo", 0.0, 1e4), ("im_hi", 0.0, 1e4), ("rel_step", 0.0, 10.0),
                             ("rtol", 0.0, 1.0), ("tail", 0.0, 600.0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (
                    math.isfinite(v) and lo < v <= hi) and not (name == "tail" and v == 0.0):
                raise ValueError(f"{name} must be in ({lo:g}, {hi:g}], got {v!r}")
        if not self.im_lo < self.im_hi:
            raise ValueError(f"im_lo ({self.im_lo:g}) must be below im_hi ({self.im_hi:g})")
        if self.rtol >= self.rel_step:
            raise ValueError(f"rtol ({self.rtol:g}) must be below rel_step ({self.rel_step:g})")

    def grid(self) -> list[float]:
        out = [self.im_lo]
        while out[-1] * (1.0 + self.rel_step) <= self.im_hi * (1.0 + 1e-12):
            out.append(out[-1] * (1.0 + self.rel_step))
        return out

    def describe(self) -> dict:
        return {**asdict(self), "unit": IM_UNITS[self.im]}


@dataclass(frozen=True)
class IDAResult:
    """The first overturning intensity of one motion.

    ``im_overturn``: lowest intensity found to overturn (``inf``: none up to
    ``im_hi``, right-censored); ``im_safe``: the highest below it found safe
    (``NaN`` when the grid's first point overturns: nothing known below);
    ``islands``: ``(lo, hi)`` runs of surviving grid points above ``im_overturn``;
    ``runs``: every ``(im, overturned)`` tried, in order.
    """

    label: str
    im: str
    im_overturn: float
    im_safe: float
    islands: tuple = ()
    runs: tuple = field(default=(), repr=False)

    @property
    def censored(self) -> bool:
        return math.isinf(self.im_overturn)

    def describe(self) -> dict:
        return {"label": self.label, "im": self.im, "unit": IM_UNITS[self.im],
                "im_overturn": None if self.censored else self.im_overturn,
                "im_safe": None if math.isnan(self.im_safe) else self.im_safe,
                "censored": self.censored, "islands": [list(x) for x in self.islands],
                "n_runs": len(self.runs)}


def intensity_of(motion, im: str) -> float:
    """The motion's intensity: 1 for ``'scale'``, else its ``pga`` / ``pgv``."""
    return 1.0 if im == "scale" else float(getattr(motion, im))


def scale_to(motion, im: str, value: float):
    """``motion`` scaled so its intensity ``im`` equals ``value``."""
    return motion.scaled(value / intensity_of(motion, im))


def model_verdict(scene, tail: float, compiled: bool = True) -> Callable[[object], bool]:
    """``overturns(motion)`` for the model with ``t_max = end + tail`` [s].

    ``compiled`` True: a motion the compiled kernels integrate (a sampled
    record, a one-sine or one-cosine pulse: ``compiled_form()`` not None) runs
    there (:func:`analytic.fast.verdict_for`, verdict only), any other in the
    accurate path (:func:`analytic.simulate.simulate`); False: always the
    accurate path."""
    from . import simulate as accurate

    def overturns(motion) -> bool:
        window = motion.end_time + tail
        if compiled and motion.compiled_form() is not None:
            from . import fast  # numba: imported when a compiled run is made
            return fast.verdict_for(scene, motion, fast.Settings(t_max=window)).overturned
        return accurate.simulate(scene, motion,
                                 accurate.Settings(t_max=window)).verdict.overturned
    return overturns


def first_overturn_intensity(motion, overturns: Callable[[object], bool],
                             settings: IDASettings = IDASettings(),
                             label: str | None = None) -> IDAResult:
    """Search the lowest intensity at which ``overturns(scaled motion)`` is True.

    Parameters
    ----------
    motion
        A ground motion with ``scaled``, ``pga``, ``pgv`` (a record or a pulse).
    overturns : callable
        The verdict of one run (:func:`model_verdict`, or an engine's).
    settings : IDASettings
    label : str, optional
        Defaults to the motion's ``label`` attribute.

    Returns
    -------
    IDAResult
    """
    if intensity_of(motion, settings.im) <= 0.0:
        raise ValueError(f"the motion has {settings.im.upper()} = 0: it cannot be scaled")
    runs: list[tuple[float, bool]] = []

    def run(value: float) -> bool:
        over = bool(overturns(scale_to(motion, settings.im, value)))
        runs.append((value, over))
        return over

    grid = settings.grid()
    verdicts = [run(v) for v in grid]
    name = label if label is not None else motion.label
    if not any(verdicts):
        return IDAResult(name, settings.im, math.inf, grid[-1], (), tuple(runs))
    k = verdicts.index(True)
    if k == 0:
        hi, lo = grid[0], math.nan
    else:
        lo, hi = grid[k - 1], grid[k]
        while hi - lo > settings.rtol * hi:
            mid = math.sqrt(lo * hi)
            if run(mid):
                hi = mid
            else:
                lo = mid
    islands, start = [], None
    for v, over in zip(grid[k:], verdicts[k:]):
        if not over and start is None:
            start = v
        if over and start is not None:
            islands.append((start, prev))
            start = None
        prev = v
    if start is not None:
        islands.append((start, grid[-1]))
    return IDAResult(name, settings.im, hi, lo, tuple(islands), tuple(runs))
