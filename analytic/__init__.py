"""The analytic trilith-pendulum rocking model (Di Egidio et al.), re-derived.

Public API::

    from trilith_xval.analytic import Scene, Pulse, simulate, SimulationSettings
"""
from .excitation import Pulse, SampledRecord, Still
from .parameters import Scene
from .trajectory import Event, OverturnCriterion, Trajectory, Verdict

__all__ = ["Scene", "Pulse", "SampledRecord", "Still", "Trajectory", "Event", "Verdict",
           "OverturnCriterion"]
