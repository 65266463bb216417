"""The jobs of the validation campaign (:mod:`compare.campaign.validation`), each one
frozen value holding its run (:class:`compare.run.spec.RunSpec`).

A job is called to compute its result; :meth:`args` are what describes it in the
run store's key and in an error record (the backend and scene, then its own
numbers), as the campaign has always written them, so an error record of
``summary.json`` keeps its form.  Every run of a job comes from
:func:`compare.campaign.config.campaign_run`: the one place the campaign's
settings are layered.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from trilith_xval.compare.campaign.config import CampaignConfig, campaign_run
from trilith_xval.compare.run.spec import RunSpec

__all__ = ["HistoryJob", "RestitutionJob", "ThresholdPointJob", "JumpJob", "LongRunJob",
           "ReverifyJob", "free_rocking_restitution", "history_job", "long_run_job"]


def free_rocking_restitution(run: RunSpec, config: CampaignConfig | None = None):
    """Release ``run``'s scene at rest from ``theta0_fraction * alpha`` in its backend
    (no base motion) and measure the first ``n_impacts`` impacts against Eq. 19/20
    (:func:`compare.measure.restitution.free_rocking`)."""
    from trilith_xval.compare.measure.restitution import free_rocking
    config = config or CampaignConfig()
    return free_rocking(run, config.theta0_fraction * run.scene.alpha,
                        n_impacts=config.n_impacts)


@dataclass(frozen=True)
class HistoryJob:
    """A time history of ``run`` (its backend at the paper's ``point``)."""

    kind: ClassVar[str] = "history"
    run: RunSpec
    point: str
    config: CampaignConfig

    def args(self) -> tuple:
        return self.run.backend, self.run.scene, self.point

    def __call__(self):
        from trilith_xval.compare.run import runs
        r = self.run
        return runs.simulate(r.backend, r.scene, r.excitation, r.settings)


def history_job(name: str, scene, point: str, config: CampaignConfig) -> HistoryJob:
    """Backend ``name`` at the paper's ``point`` (:data:`scenes.POINTS`) on ``scene``."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.scenes import POINTS
    amplitude, omega = POINTS[point]
    return HistoryJob(campaign_run(name, config, scene, Pulse(amplitude, omega)), point, config)


@dataclass(frozen=True)
class RestitutionJob:
    """Free rocking of ``run``'s scene (:func:`free_rocking_restitution`)."""

    kind: ClassVar[str] = "restitution"
    run: RunSpec
    config: CampaignConfig

    def args(self) -> tuple:
        return self.run.backend, self.run.scene

    def __call__(self):
        return free_rocking_restitution(self.run, self.config)


@dataclass(frozen=True)
class ThresholdPointJob:
    """One threshold measurement (:func:`compare.measure.engine_spectrum.measure_point`);
    ``run`` is resolved at the largest pulse its search may try."""

    kind: ClassVar[str] = "threshold"
    run: RunSpec
    case: str
    omega: float
    a_reference: float
    mode_reference: str | None
    config: CampaignConfig

    @classmethod
    def at(cls, name: str, scene, case: str, omega: float, a_reference: float,
           mode_reference, config: CampaignConfig) -> "ThresholdPointJob":
        """The job of backend ``name`` at one point of ``scene``'s curve ``case``."""
        from trilith_xval.compare.measure.engine_spectrum import point_spec
        template = campaign_run(name, config, scene, thresholds=True)
        return cls(point_spec(template, scene, omega, a_reference), case, omega, a_reference,
                   mode_reference, config)

    def args(self) -> tuple:
        return (self.run.backend, self.run.scene, self.case, self.omega, self.a_reference,
                self.mode_reference)

    def __call__(self):
        from trilith_xval.compare.measure.engine_spectrum import measure_point
        c = self.config
        return measure_point(self.run, self.omega, self.a_reference, self.mode_reference,
                             case=self.case, tol=c.tolerances.threshold, rel_tol=c.rel_tol,
                             convergence=True)


@dataclass(frozen=True)
class JumpJob:
    """The engine's jump frequency between ``omega_lo`` and ``omega_hi`` at
    ``amplitude`` (:func:`compare.measure.jump_shift.engine_jump_frequency`);
    ``run`` is resolved at the largest pulse of the job (``amplitude`` at
    ``omega_hi``)."""

    kind: ClassVar[str] = "jump"
    run: RunSpec
    amplitude: float
    omega_lo: float
    omega_hi: float
    config: CampaignConfig

    @classmethod
    def at(cls, name: str, scene, amplitude: float, omega_lo: float, omega_hi: float,
           config: CampaignConfig) -> "JumpJob":
        from trilith_xval.analytic.pulses import pulse_of
        return cls(campaign_run(name, config, scene, pulse_of("sine", amplitude, omega_hi)),
                   amplitude, omega_lo, omega_hi, config)

    def args(self) -> tuple:
        return self.run.backend, self.run.scene, self.amplitude, self.omega_lo, self.omega_hi

    def __call__(self):
        from trilith_xval.compare.measure.jump_shift import engine_jump_frequency
        r = self.run
        return engine_jump_frequency(r.backend, r.scene, self.amplitude, self.omega_lo,
                                     self.omega_hi, r.settings,
                                     reference_backend=self.config.spectrum_backend)


@dataclass(frozen=True)
class LongRunJob:
    """One fixed-window run (:func:`compare.measure.long_runs.long_run`) of the
    labelled case ``label`` (:data:`compare.measure.long_runs.LONG_RUNS`)."""

    kind: ClassVar[str] = "long_run"
    run: RunSpec
    label: str
    scene_name: str
    amplitude: float
    omega: float
    config: CampaignConfig

    def args(self) -> tuple:
        return self.run.backend, self.label, self.scene_name, self.amplitude, self.omega

    def __call__(self):
        from trilith_xval.compare.measure.long_runs import long_run
        return long_run(self.run, self.label, self.scene_name, self.config.long_run_t_max)


def long_run_job(name: str, label: str, scene_name: str, amplitude: float, omega: float,
                 config: CampaignConfig) -> LongRunJob:
    """Backend ``name``'s long run of one :data:`~compare.measure.long_runs.LONG_RUNS` case."""
    from trilith_xval.compare.measure.long_runs import long_run_excitation
    from trilith_xval.scenes import load_scene
    run = campaign_run(name, config, load_scene(scene_name),
                       long_run_excitation(amplitude, omega))
    return LongRunJob(run, label, scene_name, amplitude, omega, config)


@dataclass(frozen=True)
class ReverifyJob:
    """One stored spectrum point measured again
    (:func:`compare.campaign.stored_parts.reverify_one`, which resolves its run as
    the stored command did)."""

    kind: ClassVar[str] = "reverify"
    engine: str
    scene: object
    point: dict
    source: object
    config: ClassVar[None] = None  # nothing of the campaign's config changes it

    def args(self) -> tuple:
        return self.engine, self.scene, self.point, self.source

    def __call__(self):
        from trilith_xval.compare.campaign.stored_parts import reverify_one
        return reverify_one(self.engine, self.scene, self.point, self.source)
