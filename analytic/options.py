"""The run options every backend's ``Settings`` shares (the contract's common part).

Defined here, in :mod:`analytic`, so that the analytic model can use them without
importing :mod:`engines`; every backend's ``Settings`` is a subclass of
:class:`RunOptions` (``engines.base.EngineSettings`` adds what every *engine* shares:
a time step, the base-motion method, the sampling and the run monitor).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from .trajectory import OverturnCriterion

__all__ = ["RunOptions", "check_real", "check_restitution_factor", "MAX_RUN_STEPS",
           "MAX_ENGINE_DT", "KEY_NEUTRAL"]

# Largest run any backend accepts: engine steps (length / dt) or analytic output
# samples (length / sample_dt).  5e6 steps is about 3 min of PyBullet and 1 min
# of Pymunk on the reference machine (30 and 90 thousand steps/s, README), 200 MB
# of analytic samples; the default runs need at most 1.3e6 (62.8 s pulse + 60 s).
MAX_RUN_STEPS = 5_000_000
# Largest engine time step [s], the one range of every --dt, campaign step and
# engine Settings.  Steps this coarse no longer simulate rocking (an engine spreads
# an impact over a few steps; a 30 rad/s pulse lasts 0.2 s), but every engine still
# ends such a run with a verdict ('unstable' when it blows up), which the stress
# grid checks; the calibrated steps are 1e-4 s.
MAX_ENGINE_DT = 0.1
# Fields added after runs were stored, with the value that reproduces those runs:
# describe() leaves a field out at that value, so the settings part of every run
# key made before the field existed stays the same.
KEY_NEUTRAL = {"restitution_factor": 1.0}


def check_real(owner: str, name: str, value, lo: float, hi: float, lo_open: bool = True,
               hi_open: bool = False) -> float:
    """``float(value)`` if it is a finite real number in the interval, else
    ``TypeError``/``ValueError`` naming ``owner.name`` and the allowed range.
    Booleans are refused (``True`` is an ``int``, never a length or a time)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{owner}: {name} must be a real number, got {value!r}")
    v = float(value)
    ok = (math.isfinite(v) and (v > lo if lo_open else v >= lo)
          and (v < hi if hi_open else v <= hi))
    if not ok:
        left, right = ("(" if lo_open else "["), (")" if hi_open else "]")
        raise ValueError(f"{owner}: {name} must be finite in {left}{lo:g}, {hi:g}{right}, "
                         f"got {value!r}")
    return v


def check_restitution_factor(owner: str, value) -> float:
    """``value`` as a float if it is a restitution factor in (0, 1], else
    ``TypeError``/``ValueError`` naming ``owner.restitution_factor`` and the range.

    The factor scales the model's impact ratio (Eq. 19, Eq. 20 without pendulum):
    1 is the exact impulse-momentum impact, below 1 a measured, lossier one; 0
    would stop every rocking at its first impact and above 1 would create energy.
    """
    return check_real(owner, "restitution_factor", value, 0.0, 1.0)


@dataclass(frozen=True)
class RunOptions:
    """What every backend's ``Settings`` has, with the same meaning everywhere.

    Parameters
    ----------
    criterion : OverturnCriterion
        How overturning is decided (default: the columns topple, ``|theta|`` reaches
        1.5 rad; ``docs/overturning.md``).
    t_max : float or None
        Fixed run length [s] in (0, 1e5]; ``None`` (default) runs until the verdict
        is certain.
    theta0 : float
        Initial rocking angle [rad], released at rest; ``> 0`` leans on the left
        corners.  Default 0 (upright, at rest).  Checked against the scene's
        ``alpha`` when the run starts.
    psi0 : float
        Initial pendulum angle [rad] in [-pi, pi], released at rest.  Default 0.
    early_stop : bool
        Stop as soon as the verdict is certain (default True: a threshold probe
        needs only the verdict).  False keeps running (until ``t_max``, rest or
        the backend's cap): free-rocking experiments need the impacts after the
        energy has fallen below the overturning barrier.
    verdict_only : bool
        Also stop as soon as an overturn is certain (default False): after the
        pulse, past ``alpha`` with the energy below the overturning barrier the
        trilith can never return (the same exact rule as the analytic survival
        rule, mirrored).  The verdict's time is then when it became certain, not
        when the columns topple, the trajectory ends there and engines do not
        measure impact velocities (they count the impacts): for threshold probes,
        which need only the verdict.

    Examples
    --------
    >>> from trilith_xval.analytic.options import RunOptions
    >>> RunOptions(t_max=2.0).t_max
    2.0
    >>> RunOptions(t_max=-1.0)
    Traceback (most recent call last):
    ...
    ValueError: RunOptions: t_max must be finite in (0, 100000], got -1.0
    """

    criterion: OverturnCriterion = field(default_factory=OverturnCriterion)
    t_max: float | None = None
    theta0: float = 0.0
    psi0: float = 0.0
    early_stop: bool = True
    verdict_only: bool = False

    def __post_init__(self) -> None:
        owner = type(self).__name__
        if not isinstance(self.criterion, OverturnCriterion):
            raise TypeError(f"{owner}: criterion must be an OverturnCriterion, "
                            f"got {type(self.criterion).__name__}")
        if self.t_max is not None:
            check_real(owner, "t_max", self.t_max, 0.0, 1e5)
        check_real(owner, "theta0", self.theta0, -0.5 * math.pi, 0.5 * math.pi, lo_open=True,
                   hi_open=True)
        check_real(owner, "psi0", self.psi0, -math.pi, math.pi, lo_open=False)
        for name in ("early_stop", "verdict_only"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"{owner}: {name} must be True or False, "
                                f"got {getattr(self, name)!r}")

    def check_scene(self, scene) -> None:
        """Checks that need the scene (before any stepping): ``|theta0| < alpha``."""
        if abs(self.theta0) >= scene.alpha:
            raise ValueError(f"{type(self).__name__}: theta0 must be in (-alpha, alpha) = "
                             f"(-{scene.alpha:.4g}, {scene.alpha:.4g}) rad for this scene, "
                             f"got {self.theta0!r}")

    def describe(self) -> dict:
        """A plain dict of every field (the criterion as a dict): what a result carries
        and what a run key hashes.  A field of :data:`KEY_NEUTRAL` at its neutral
        value is left out (runs stored before it existed keep their keys)."""
        from dataclasses import asdict
        out = asdict(self)
        out["criterion"] = self.criterion.describe()
        for name, neutral in KEY_NEUTRAL.items():
            if name in out and out[name] == neutral:
                del out[name]
        return out
