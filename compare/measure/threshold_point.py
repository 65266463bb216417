"""The result of the one engine threshold search (:mod:`compare.measure.thresholds`):
each run it made (:class:`Probe`) and the robust first-overturning bracket at one
frequency (:class:`ThresholdPoint`), with what a report reads from them (the
error, its resolution, perturbed runs that flipped, collapses below the
threshold, cost per simulated second).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from trilith_xval.compare.measure.trajectories import Provenance

__all__ = ["Probe", "ThresholdPoint"]


@dataclass(frozen=True)
class Probe:
    """One run of a search: its verdict and cost.

    ``perturbation`` is '' for a probe of the search, else a key of
    :data:`~compare.measure.thresholds.PERTURBATIONS`; ``cpu_s`` the CPU seconds
    the run cost when it was computed (NaN if the backend does not report it);
    ``from_store`` True when the run store served it (then it cost nothing now);
    ``sim_s`` the simulated time [s] (a verdict-only run stops when its verdict
    is certain).
    """

    amplitude: float
    status: str
    mode: str | None
    perturbation: str = ""
    cpu_s: float = math.nan
    from_store: bool = False
    sim_s: float = math.nan

    @property
    def overturned(self) -> bool:
        return self.status == "overturned"

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class ThresholdPoint:
    """A backend's first overturning amplitude at one frequency.

    The engine survives robustly at ``a_survives`` and overturns robustly at
    ``a_engine`` (``a_engine - a_survives <= rel_tol * a_reference``); both NaN
    when no robust bracket was found.  ``isolated``: overturns (amplitude,
    perturbation, the neighbours' verdicts) that were not reproduced.
    ``cpu_s``: CPU seconds of every probe when computed; ``cpu_s_spent``: spent
    now (0 when the store served every probe).
    """

    omega: float
    kind: str
    a_reference: float
    a_engine: float
    a_survives: float
    mode_reference: str | None
    mode_engine: str | None
    n_runs: int
    irregular_runs: int
    rel_tol: float
    provenance: Provenance
    probes: tuple = ()  # Probe, in order
    isolated: tuple = ()  # dicts: amplitude, mode, perturbation, neighbours
    cpu_s: float = math.nan
    cpu_s_spent: float = math.nan

    @property
    def collapsed_below(self) -> bool:
        """True when a search run below ``a_engine`` ended 'collapsed': the engine's
        frame broke before it overturned (the threshold is then that of a broken
        frame).  Perturbed runs count in :attr:`flips` instead."""
        top = self.a_engine if self.bracketed else math.inf
        return any(p.status == "collapsed" and p.amplitude < top and not p.perturbation
                   for p in self.probes)

    @property
    def flips(self) -> tuple:
        """Perturbed runs of the final ends whose verdict differs from their end's:
        not 'overturned' above ``a_engine``, not 'survived' below ``a_survives``
        (e.g. PyBullet's frame collapsing after a 1e-6 rad tilt)."""
        if not self.bracketed:
            return ()
        return tuple(p for p in self.probes if p.perturbation and (
            (p.amplitude > self.a_engine and p.status != "overturned")
            or (p.amplitude < self.a_survives and p.status != "survived")))

    @property
    def bracketed(self) -> bool:
        return math.isfinite(self.a_engine)

    @property
    def rel_error(self) -> float:
        """``(A_engine - A_analytic)/A_analytic``."""
        return (self.a_engine - self.a_reference) / self.a_reference

    @property
    def rel_resolution(self) -> float:
        """Width of the robust bracket over ``A_analytic``: ``rel_error``'s resolution."""
        return (self.a_engine - self.a_survives) / self.a_reference

    @property
    def from_store(self) -> bool:
        return bool(self.probes) and all(p.from_store for p in self.probes)

    @property
    def sim_s(self) -> float:
        """Simulated seconds of every probe."""
        return math.fsum(p.sim_s for p in self.probes)

    @property
    def cpu_per_sim_s(self) -> float:
        """Real-time factor: CPU seconds per simulated second (when computed)."""
        return self.cpu_s / self.sim_s if self.sim_s > 0 else math.nan

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out.update(provenance=self.provenance.to_dict(), rel_error=self.rel_error,
                   rel_resolution=self.rel_resolution, bracketed=self.bracketed,
                   collapsed_below=self.collapsed_below, from_store=self.from_store,
                   sim_s=self.sim_s, cpu_per_sim_s=self.cpu_per_sim_s,
                   flips=[p.to_dict() for p in self.flips],
                   probes=[p.to_dict() for p in self.probes], isolated=list(self.isolated))
        return out
