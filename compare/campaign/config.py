"""What the validation campaign (:mod:`compare.campaign.validation`) runs and accepts.

:class:`CampaignConfig` names the scene, engines, grids and budgets; its
:class:`Tolerances` are the acceptance limits of the verdict table, each with its
reason; :func:`campaign_run` is the one place a campaign's run of a backend is
built (:class:`compare.run.spec.RunSpec`: calibrated for threshold searches, then
the config's settings table, then ``engine_dt``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from trilith_xval.analytic.options import MAX_ENGINE_DT
from trilith_xval.engines import ENGINES, configure
from trilith_xval.scenes import POINTS

from trilith_xval.compare.run.jsonable import plain

__all__ = ["Tolerances", "CampaignConfig", "campaign_run"]


@dataclass(frozen=True)
class Tolerances:
    """Acceptance tolerances of the verdict table, each with its reason."""

    restitution: float = 0.005  # acceptance: Eq. 20 within 0.5 %
    restitution_pendulum: float = 0.005  # Eq. 19 at the measured psi: its relative slope in psi
    #   is <= 0.11 /rad on the lam 3-7 grid, so even a 0.01 rad psi error costs < 0.1 %
    threshold: float = 0.02  # acceptance: overturning amplitude within 2 % away from jumps
    theta_rms_first: float = 1e-3  # theta RMS / alpha before the first impact: worst measured
    #   3e-4 with calibrated defaults; grows ~linearly with dt (Pymunk, A: 1.2e-4, 7.6e-4, 1.6e-3,
    #   3.5e-3 at 1e-4, 5e-4, 1e-3, 2e-3 s), so 1e-3 rejects steps >= 1e-3 s
    verdict_mismatches: int = 0  # the paper's A-D verdicts (status and mode) must agree exactly

    def reasons(self) -> dict[str, str]:
        return {
            "restitution": "Eq. 20 within 0.5 %: the rocking energy kept per impact goes "
                           "as the velocity ratio squared, so 0.5 % on the ratio is 1 % of "
                           "the energy per impact, 4 % after the 4 measured impacts",
            "restitution_pendulum": "Eq. 19 at the measured psi: same 0.5 % as Eq. 20, since "
                                    "its relative slope in psi is <= 0.11/rad (a 0.01 rad psi "
                                    "error costs < 0.1 %)",
            "threshold": "2 % of the overturning amplitude, 4x the 0.5 % bracket of the "
                         "robust search (a miss is a measured difference, not bracket noise); "
                         "away from mode jumps, where the threshold is discontinuous in Omega",
            "theta_rms_first": "worst measured 3e-4 of alpha at the calibrated 1e-4 s step; the "
                               "error grows ~linearly with dt (3.5e-3 at 2e-3 s), 1e-3 rejects "
                               "steps >= 1e-3 s",
            "verdict_mismatches": "overturned/survived and the mode must match the model exactly",
        }


@dataclass(frozen=True)
class CampaignConfig:
    """What the campaign runs.  ``quick()`` is the 2-minute variant."""

    scene: str = "fig5"  # the paper's Fig. 5 trilith (lam 5, b 0.6 m, mu 1, gamma 0.3)
    engines: tuple[str, ...] = ENGINES  # the engines under validation
    reference: str = "analytic"  # accurate scipy path for time histories
    spectrum_backend: str = "analytic-fast"  # compiled path: a spectrum costs ~1 s
    points: tuple[str, ...] = ("A", "B", "C", "D")  # the paper's labelled cases
    restitution_lams: tuple[float, ...] = (3.0, 5.0, 7.0)  # lam 3-7 x mu 0.5-2, the paper's range
    restitution_mus: tuple[float, ...] = (0.5, 1.0, 2.0)  # lam 3-7 x mu 0.5-2, the paper's range
    pendulum_lams: tuple[float, ...] = (3.0, 5.0, 7.0)  # Eq. 19 runs (scene's mu, gamma)
    theta0_fraction: float = 0.5  # release tilt / alpha: well inside the well, fast impacts
    n_impacts: int = 4  # per free-rocking run: two of each side, as compare/measure/restitution.py
    spectrum_cases: tuple[str, ...] = ("pendulum", "no_pendulum")  # Fig. 5: both curves
    n_frequencies: int = 6  # engine threshold frequencies per case (away from jumps); 10-min budget
    omega_range: tuple[float, float] = (5.0, 26.0)  # rad/s: most of the Fig. 5 axis (3-30); the
    #   ends cost most (long pulses) or need > 8 g pulses
    spectrum_step: float = 0.5  # rad/s: reference spectrum grid, locates the jumps
    jump_margin: float = 1.5  # rad/s kept between a threshold frequency and a jump
    jump_cases: tuple[str, ...] = ("pendulum",)  # the paper's Omega_1 jump (Fig. 5, circled)
    rel_bracket: float = 0.03  # frequencies are chosen where the model is monotone 2x this above
    rel_tol: float = 5e-3  # robust bracket width (the one search's, compare.measure.thresholds)
    engine_dt: float | None = None  # override every engine's time step (None: calibrated)
    engine_settings: dict = field(default_factory=dict)  # {engine: {field: value}}, a settings
    #   file's tables (compare/campaign/settings_file.py), under engine_dt and each job's own
    long_run_t_max: float = 20.0  # s, fixed window of the long runs (compare/measure/long_runs.py)
    long_runs: bool = True  # the trust table's long-run line (rest, after a pulse)
    workers: int = 2  # the target machine has 2 cores
    tolerances: Tolerances = Tolerances()
    # What the default report takes from a stored full run (compare/campaign/stored_parts.py):
    # None runs everything (report --full); these three choose no number of a job that runs.
    stored: str | None = None  # a stored summary.json: its other threshold points are shown
    stored_jobs: tuple[str, ...] = ()  # job kinds shown from ``stored`` instead of run ("jump", "long_run")
    reverify: bool = False  # re-measure one point of every stored engine spectrum

    # Fields that only choose which jobs run: left out of job keys, so the default
    # report and report --full share the run store.
    SELECTION = ("workers", "stored", "stored_jobs", "reverify")

    def __post_init__(self) -> None:
        for name in self.engines:
            if name not in ENGINES:
                raise ValueError(f"engines: unknown engine {name!r}; allowed: {', '.join(ENGINES)}")
        if not self.engines:
            raise ValueError("engines must name at least one of: " + ", ".join(ENGINES))
        for p in self.points:
            if p not in POINTS:
                raise ValueError(f"points: unknown point {p!r}; allowed: {', '.join(POINTS)}")
        if not 0.05 <= self.theta0_fraction <= 0.9:
            raise ValueError(f"theta0_fraction must be in [0.05, 0.9], got {self.theta0_fraction!r}")
        if self.n_frequencies < 0 or self.n_impacts < 1 or self.workers < 1:
            raise ValueError("n_frequencies must be >= 0, n_impacts >= 1 and workers >= 1")
        if self.engine_dt is not None and not (math.isfinite(self.engine_dt)
                                               and 0.0 < self.engine_dt <= MAX_ENGINE_DT):
            raise ValueError(f"engine_dt must be in (0, {MAX_ENGINE_DT:g}] s, "
                             f"got {self.engine_dt!r}")
        for name, options in self.engine_settings.items():
            if name not in ENGINES:
                raise ValueError(f"engine_settings: unknown engine {name!r}; allowed: "
                                 f"{', '.join(ENGINES)}")
            configure(name, **options)  # refused here, naming the field, not in a worker
        for case in (*self.spectrum_cases, *self.jump_cases):
            if case not in ("pendulum", "no_pendulum"):
                raise ValueError(f"spectrum_cases: unknown case {case!r}; allowed: pendulum, "
                                 "no_pendulum")
        for kind in self.stored_jobs:
            if kind not in ("jump", "long_run"):
                raise ValueError(f"stored_jobs: unknown job kind {kind!r}; allowed: jump, "
                                 "long_run")
        lo, hi = self.omega_range
        if not 0.0 < lo < hi:
            raise ValueError(f"omega_range must satisfy 0 < lo < hi, got {self.omega_range!r}")

    @classmethod
    def quick(cls, **changes) -> "CampaignConfig":
        """Smaller grids for ``--quick`` (< 2 min on 2 cores)."""
        base = dict(restitution_lams=(3.0, 7.0), restitution_mus=(1.0,), pendulum_lams=(5.0,),
                    n_impacts=3, n_frequencies=1, jump_cases=(), long_runs=False)
        base.update(changes)
        return cls(**base)

    @classmethod
    def default_report(cls, **changes) -> "CampaignConfig":
        """What ``trilith report`` runs without ``--full``: the full grids, but the
        threshold points by :func:`compare.campaign.stored_parts.recompute_omegas`,
        the jump shifts and the long runs (20 s windows: a sixth of the report's
        CPU, Drake's most of it) from the stored validation, labelled, and its
        engine spectra re-verified on a sample (minutes on 2 cores instead of ~40)."""
        from trilith_xval.compare.campaign.stored_parts import STORED_SUMMARY
        base = dict(stored=str(STORED_SUMMARY), stored_jobs=("jump", "long_run"), reverify=True)
        base.update(changes)
        return cls(**base)

    def to_dict(self) -> dict:
        return plain(self)

    def job_key(self) -> dict:
        """The config as job keys see it (without :attr:`SELECTION`)."""
        return {k: v for k, v in self.to_dict().items() if k not in self.SELECTION}


def campaign_run(name: str, config: CampaignConfig, scene, excitation=None, *,
                 thresholds: bool = False):
    """Backend ``name``'s run in the campaign, resolved once.

    Parameters
    ----------
    name : str
        A registered backend.
    config : CampaignConfig
    scene, excitation
        The run's scene and ground motion (default
        :class:`~analytic.excitation.Still`); for a threshold search, the
        largest pulse it may try (the friction rule's excitation).
    thresholds : bool
        A threshold search: the engine's calibrated threshold settings first,
        where ``scene`` lies in their domain (:func:`engines.calibration.threshold_choice`).

    Returns
    -------
    compare.run.spec.RunSpec
        Layers, each over the one before: the backend's defaults, the
        calibration (``thresholds``), the config's ``engine_settings`` table, then
        ``engine_dt`` (engines only).
    """
    from trilith_xval.compare.run.spec import RunSpec
    engine = name in ENGINES
    run = RunSpec.resolve(name, scene, excitation, calibrated=thresholds and engine,
                          overrides=config.engine_settings.get(name),
                          overrides_from="the campaign's engine_settings")
    if config.engine_dt is not None and engine:
        run = run.with_options("the campaign's engine_dt", dt=config.engine_dt)
    return run
