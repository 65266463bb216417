"""The analytic trilith-pendulum rocking model (Di Egidio et al.), re-derived.

Public API::

    from trilith_xval.analytic import Scene, Pulse, simulate, SimulationSettings
"""
from .excitation import Excitation, Pulse, SampledRecord, Still, check_excitation
from .parameters import Scene
from .trajectory import Event, OverturnCriterion, Trajectory, Verdict

__all__ = ["Scene", "Excitation", "check_excitation", "Pulse", "SampledRecord", "Still",
           "Trajectory", "Event", "Verdict", "OverturnCriterion"]
