"""Settings of the compiled fast path (:mod:`analytic.fast`), in a module of their
own so that describing or validating a run does not import numba (about 0.3 s)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from importlib.metadata import version as _dist_version

from .options import RunOptions, check_restitution_factor

__all__ = ["Settings", "version"]


def version() -> str:
    return f"analytic-fast (numba {_dist_version('numba')}, Dormand-Prince 5(4))"


@dataclass(frozen=True)
class Settings(RunOptions):
    """Numerical settings of the fast path.

    The shared run options are :class:`analytic.options.RunOptions`; the fast
    path starts at rest and decides the verdict exactly, so ``theta0``, ``psi0``
    must be 0 and ``early_stop`` True (use the ``analytic`` backend otherwise).
    ``restitution_factor`` (in (0, 1], default 1) multiplies the rocking
    angular-velocity ratio of every impact, as in the accurate path
    (:func:`analytic.equations.impact_velocities`; docs/model.md).
    """

    # Undecided after pulse end + t_cap [s]: far longer than any decaying rocking.
    t_cap: float = 120.0
    # DP5 tolerances: overturning thresholds agree with the rtol 1e-10 accurate
    # path within 3e-9 relative (Fig. 5, Omega = 10, 11, 18, bisected to 1e-9).
    rtol: float = 1e-8
    atol: float = 1e-10
    # |theta_dot+| below this after an impact ends rocking (same as the accurate path).
    rest_velocity: float = 1e-6
    # Output grid [s] of simulate(); 1 ms resolves the fastest rocking half-cycle.
    sample_dt: float = 1e-3
    # Guard against Zeno chatter; no decided run measured needs 1e5 steps.  A
    # record's run gets one step per sample on top (every sample is a breakpoint).
    max_steps: int = 2_000_000
    # Largest REST step / pulse period (after it: / pendulum period): a dip of the
    # uplift margin shorter than a step could be missed; 1 % costs <= 100 steps.
    rest_step_fraction: float = 0.01
    # Measured over exact impact ratio (Eq. 19/20), in (0, 1]: docs/model.md.
    restitution_factor: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.theta0 != 0.0 or self.psi0 != 0.0 or not self.early_stop:
            raise ValueError("analytic-fast starts at rest and stops when decided: theta0 and "
                             "psi0 must be 0 and early_stop True (the 'analytic' backend "
                             "takes any initial state)")
        for name, lo, hi in (("t_cap", 0.0, 1e5), ("rtol", 1e-14, 1e-2),
                             ("atol", 1e-16, 1e-2), ("rest_velocity", 0.0, 1.0),
                             ("sample_dt", 1e-6, 10.0), ("rest_step_fraction", 0.0, 0.25)):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and lo < v <= hi):
                raise ValueError(f"{name} must be in ({lo:g}, {hi:g}], got {v!r}")
        if not (isinstance(self.max_steps, int) and self.max_steps >= 100):
            raise ValueError(f"max_steps must be an integer >= 100, got {self.max_steps!r}")
        check_restitution_factor(type(self).__name__, self.restitution_factor)
