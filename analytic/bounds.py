"""Bounds and checks of the analytic model that engines and studies read.

:func:`required_friction` is the Coulomb coefficient an engine needs for the
columns to rock without sliding, :func:`peak_acceleration` the largest base
acceleration of an excitation, and :func:`check_model` runs one accurate
analytic pulse and names the first model assumption (no hop, no slide, the
lintel pressed onto the columns) that fails.  They sit above
:mod:`analytic.reactions` and :mod:`analytic.simulate`, which they both use.
"""
from __future__ import annotations

import math
import numbers

from . import equations as eq
from .contact_forces import violations
from .simulate import simulate

__all__ = ["required_friction", "peak_acceleration", "check_model"]


def required_friction(scene, excitation) -> float:
    """Conservative Coulomb coefficient needed for rocking without sliding
    (one rule for every engine; ``analytic.reactions`` gives the exact demand
    along an analytic run, and this bound exceeded it at A-D).

    The largest of three ratios of horizontal to vertical ground reaction:

    * at rest up to uplift the trilith moves with the ground: ``|a_up| / g``
      (Eq. 9, pendulum hanging still) and, for a sampled or pulse excitation,
      ``peak |xg_ddot| / g`` (the rigid-body bound if the trilith were carried
      along for the whole pulse; it over-estimates the rocking phase, where the
      columns' rotation absorbs most of the horizontal acceleration);
    * at an impact, the plastic impulse at the new corners of every body in the
      rocking mechanism has the ratio ``lam (1 - e) / (1 + e)`` with ``e`` the
      velocity ratio of Eq. 20 (Eq. 19 at ``psi = 0`` with the pendulum): the
      columns' centres and the lintel move on circles of the same shape.
    """
    b, h, mu, gamma, j, l, g = scene.model_args()
    a_up = abs(eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu, gamma, l, g))
    e = eq.restitution_ratio(0.0, 1.0, b, h, mu, gamma, j)
    impact = (h / b) * (1.0 - e) / (1.0 + e)
    return max(a_up / g, peak_acceleration(excitation) / g, impact)


def peak_acceleration(excitation) -> float:
    """``max |xg_ddot|`` [m/s^2] of an excitation (0 for :class:`Still`): its
    ``acceleration_bound()`` (exact for a pulse and a record, sampled otherwise)."""
    return excitation.acceleration_bound()


def check_model(scene, pulse, friction: float | None = None) -> dict:
    """Does the analytic model hold for ``pulse``?  One accurate run
    (:func:`analytic.simulate.simulate`, default Settings) and its contact checks.

    Parameters
    ----------
    scene : Scene
    pulse : Pulse or SampledRecord
    friction : float, optional
        An engine's Coulomb coefficient (> 0), compared against both friction
        demands; None checks the normal forces only.

    Returns
    -------
    dict
        ``ground_min_normal`` (fraction of the total weight),
        ``ground_max_friction``, ``lintel_min_normal`` (fraction of the lintel
        and bob's weight), ``lintel_max_friction`` (None without lintel and
        pendulum), ``valid`` (no pull at either contact and, if ``friction`` is
        given, no demand above it), ``reason`` (the first of
        :func:`~analytic.contact_forces.violations`, "" when valid),
        ``violations`` (all of them), ``verdict`` (the run's status) and
        ``friction``.  The window is the verdict's (:func:`validity_diagnostics`):
        up to the last ``|theta| <= alpha`` of an overturning run, past which the
        fall is beyond the model.

    Examples
    --------
    >>> from trilith_xval.analytic.excitation import Pulse
    >>> from trilith_xval.scenes import load_scene
    >>> check_model(load_scene("fig5"), Pulse(64.0, 24.0))["reason"]  # doctest: +ELLIPSIS
    'lintel normal force -0.26 of its weight (lintel + bob) at t = ...'
    """
    if friction is not None:
        if isinstance(friction, bool) or not isinstance(friction, numbers.Real):
            raise TypeError(f"friction must be a real number or None, "
                            f"got {type(friction).__name__}")
        if not (math.isfinite(friction) and friction > 0.0):
            raise ValueError(f"friction must be finite and > 0, got {friction!r}")
        friction = float(friction)
    tr = simulate(scene, pulse)
    d = tr.diagnostics
    if "model_valid" not in d:  # non-finite samples: nothing to judge
        raise ValueError(f"the analytic run ended {tr.verdict.status!r} with non-finite "
                         f"samples; its contact forces cannot be computed")
    found = violations(d, friction)
    return {"ground_min_normal": d["min_vertical_reaction"],
            "ground_max_friction": d["max_friction_demand"],
            "lintel_min_normal": d["min_lintel_normal"],
            "lintel_max_friction": d["max_lintel_friction_demand"],
            "valid": not found, "reason": found[0] if found else "",
            "violations": found, "verdict": tr.verdict.status, "friction": friction}
