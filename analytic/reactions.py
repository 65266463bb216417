"""Ground reaction along an analytic run: is the no-hop, no-slide assumption kept?

The analytic model (Eq. 1, 8, A.1) keeps the rocking columns on their pivot
corners and never lets them slide (the paper's "sufficiently large friction").
Neither is enforced by a force in the model, so it can silently describe a
motion in which the ground would have to *pull* the columns down (they would
hop) or supply more friction than stone on stone has.  This module computes the
ground force that the model implies and reports both.

Linear momentum of the whole system (two columns, the lintel, the pendulum bob),
per unit column mass ``m1``, in an inertial frame: the only external forces are
the weights and the ground reaction ``R`` at the active pivot corners of both
columns (or the full bases at rest).  Accelerations measured in the base frame
``a_i`` add the base acceleration ``xg_ddot e_x`` (the d'Alembert load of Eq. 8)::

    R = sum_i m_i a_i + M_s (xg_ddot, g),        M_s = 2 + mu + gamma

With the Eq. 5 positions (``sb = side*b``, the top corner ``r = R(theta) (sb, h)``
carries the lintel and the hinge; each column centre is ``r/2`` from its pivot)::

    sum_i m_i a_i = (1 + mu + gamma) r_ddot + gamma l (psi_ddot (cos psi, sin psi)
                                                       + psi_dot^2 (-sin psi, cos psi))
    r_ddot = theta_ddot (-(sb sin theta + h cos theta), sb cos theta - h sin theta)
             - theta_dot^2 (sb cos theta - h sin theta, sb sin theta + h cos theta)

``theta_ddot, psi_ddot`` come from :func:`~analytic.equations.rocking_accelerations`
(Eq. 8 / A.1) while rocking and from Eq. 1
(:func:`~analytic.equations.rest_pendulum_acceleration`, ``theta = 0``) at rest.
``R`` is the sum over both columns: how it splits between them (and between the
column tops under the lintel) is statically indeterminate in a rigid model.

The other contact the model takes for granted, the lintel on the column tops,
is computed alike in :mod:`analytic.contact_forces`; :func:`validity_diagnostics`
reports both and :func:`analytic.bounds.check_model` is the single entry point that
runs a pulse and names the first assumption that fails.
"""
from __future__ import annotations

import math
import sys

import numpy as np

from . import equations as eq
from .contact_forces import (lintel_extrema, lintel_force_from_accelerations, lintel_load,
                             top_corner_acceleration)

__all__ = ["system_mass", "reaction_from_accelerations", "ground_reaction", "lintel_force",
           "sample_sides", "reaction_history", "lintel_history", "validity_diagnostics"]


def system_mass(mu: float, gamma: float) -> float:
    """``(2 m1 + m3 + m4)/m1 = 2 + mu + gamma``: all four bodies (Eq. 10 ratios)."""
    return 2.0 + mu + gamma


def reaction_from_accelerations(theta, theta_dot, psi, psi_dot, theta_ddot, psi_ddot,
                                xg_ddot, side, b: float, h: float, mu: float, gamma: float,
                                l: float, g: float):
    """``(R_x, R_y)`` per ``m1`` from a state and its accelerations (the momentum
    balance of the module docstring); scalars or equal-shape arrays.

    ``side = 0`` (rest) needs ``theta = theta_dot = theta_ddot = 0`` and then only
    adds the bodies' weight, the base's inertial load and the bob's motion.
    """
    # The ground carries the lintel and bob (their force on the column tops) plus
    # the two columns, whose centres move with half the top corner r (Eq. 5):
    # 2 m1 (xg_ddot + r_ddot_x / 2, g + r_ddot_y / 2), per m1.
    fx, fy = lintel_force_from_accelerations(theta, theta_dot, psi, psi_dot, theta_ddot,
                                             psi_ddot, xg_ddot, side, b, h, mu, gamma, l, g)
    ax, ay = top_corner_acceleration(theta, theta_dot, theta_ddot, side, b, h)
    return fx + 2.0 * xg_ddot + ax, fy + 2.0 * g + ay


def _accelerations(theta: float, theta_dot: float, psi: float, psi_dot: float,
                   xg_ddot: float, side: float, b: float, h: float, mu: float,
                   gamma: float, j: float, l: float, g: float) -> tuple[float, float]:
    """``(theta_ddot, psi_ddot)``: Eq. 8 / A.1 while rocking, Eq. 1 at rest."""
    if side != 0.0:
        return eq.rocking_accelerations(theta, theta_dot, psi, psi_dot, xg_ddot, side,
                                        b, h, mu, gamma, j, l, g)
    if gamma > 0.0:
        return 0.0, eq.rest_pendulum_acceleration(psi, xg_ddot, l, g)
    return 0.0, 0.0


def ground_reaction(theta: float, theta_dot: float, psi: float, psi_dot: float,
                    xg_ddot: float, side: float, b: float, h: float, mu: float,
                    gamma: float, j: float, l: float, g: float) -> tuple[float, float]:
    """Total ground reaction ``(R_x, R_y)`` per unit ``m1`` [N/kg] on both columns.

    Parameters
    ----------
    theta, theta_dot, psi, psi_dot : float
        State (rad, rad/s).  ``side = 0`` (rest, Eq. 1) needs ``theta =
        theta_dot = 0``.
    xg_ddot : float
        Ground acceleration [m/s^2] at that instant.
    side : float
        +1 rocking about the left corners (Eq. 8), -1 the right ones (A.1), 0 at rest.
    b, h, mu, gamma, j, l, g : float
        ``Scene.model_args()``.

    Returns
    -------
    (R_x, R_y) : tuple of float
        ``R_y > 0`` pushes the columns up (no hop); ``|R_x|/R_y`` is the
        Coulomb coefficient needed for no sliding.  At rest with the pendulum
        hanging still ``R = (M_s xg_ddot, M_s g)``, ``M_s = 2 + mu + gamma``.
    """
    theta_ddot, psi_ddot = _accelerations(theta, theta_dot, psi, psi_dot, xg_ddot, side,
                                          b, h, mu, gamma, j, l, g)
    rx, ry = reaction_from_accelerations(theta, theta_dot, psi, psi_dot, theta_ddot, psi_ddot,
                                         xg_ddot, side, b, h, mu, gamma, l, g)
    return float(rx), float(ry)


def lintel_force(theta: float, theta_dot: float, psi: float, psi_dot: float,
                 xg_ddot: float, side: float, b: float, h: float, mu: float,
                 gamma: float, j: float, l: float, g: float) -> tuple[float, float]:
    """Force ``(F_x, F_y)`` per unit ``m1`` [N/kg] of both column tops on the
    lintel and bob (:mod:`analytic.contact_forces`); arguments as in
    :func:`ground_reaction`.

    Returns
    -------
    (F_x, F_y) : tuple of float
        ``F_y > 0``: the lintel stays on the columns; ``|F_x|/F_y``: the
        Coulomb coefficient it needs there.  At rest with the pendulum hanging
        still ``F = (mu xg_ddot, (mu + gamma) g)`` (the bob lags, Eq. 1).
    """
    theta_ddot, psi_ddot = _accelerations(theta, theta_dot, psi, psi_dot, xg_ddot, side,
                                          b, h, mu, gamma, j, l, g)
    fx, fy = lintel_force_from_accelerations(theta, theta_dot, psi, psi_dot, theta_ddot,
                                             psi_ddot, xg_ddot, side, b, h, mu, gamma, l, g)
    return float(fx), float(fy)


def sample_sides(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray) -> np.ndarray:
    """Phase of each sample of an analytic trajectory: +1, -1 (rocking) or 0 (rest).

    ``sign(theta)`` away from ``theta = 0``.  At ``theta = 0`` with ``theta_dot
    != 0`` the sample is an impact or the start of rocking: the simulator stores
    an impact as two samples at one instant (before, then after), so the first of
    a pair belongs to the old side ``-sign(theta_dot)`` and any other to
    ``sign(theta_dot)``.  ``theta = theta_dot = 0`` is rest (also the uplift
    instant, where both phases give the same reaction: the margin is 0).
    """
    t = np.asarray(t, dtype=float)
    theta = np.asarray(theta, dtype=float)
    theta_dot = np.asarray(theta_dot, dtype=float)
    sides = np.sign(theta)
    at_zero = (theta == 0.0) & (theta_dot != 0.0)
    before = np.zeros(len(t), dtype=bool)
    if len(t) > 1:
        before[:-1] = t[1:] == t[:-1]
    sides[at_zero] = np.sign(theta_dot[at_zero])
    pre = at_zero & before
    sides[pre] = -np.sign(theta_dot[pre])
    return sides


def _compiled_accelerations():
    """The fast path's compiled per-sample accelerations
    (:func:`analytic._fast_steps.sample_accelerations`) when this process has
    already run its kernels (a spectrum): numba is then set up and one more
    cached kernel loads in milliseconds.  None otherwise: setting numba up for
    this alone costs about 0.5 CPU s, more than the scalar loop of a few runs."""
    kernels = sys.modules.get("trilith_xval.analytic._fast_kernels")
    if kernels is None or not (kernels.verdicts.signatures or kernels.run.signatures):
        return None
    return sys.modules["trilith_xval.analytic._fast_steps"].sample_accelerations


def _history(t, theta, theta_dot, psi, psi_dot, excitation, model_args):
    """State arrays, ``xg_ddot``, sides and ``(theta_ddot, psi_ddot)`` at every sample.

    Only the accelerations are evaluated sample by sample (the scalar Eq. 8 /
    Eq. 1), once for both contacts; by the fast path's compiled equations when
    a spectrum has run them (:func:`_compiled_accelerations`; bit for bit the
    same numbers)."""
    t = np.asarray(t, dtype=float)
    theta, theta_dot, psi, psi_dot = (np.asarray(a, dtype=float)
                                      for a in (theta, theta_dot, psi, psi_dot))
    sides = sample_sides(t, theta, theta_dot)
    xg = np.asarray(excitation.acceleration_array(t), dtype=float)
    b, h, mu, gamma, j, l, g = model_args
    compiled = _compiled_accelerations()
    if compiled is not None:  # the same numbers, ~50x faster
        acc = compiled(theta, theta_dot, psi, psi_dot, xg, np.asarray(sides, dtype=float),
                       *model_args)
    else:
        acc = [_accelerations(*row, b, h, mu, gamma, j, l, g)
               for row in zip(theta.tolist(), theta_dot.tolist(), psi.tolist(),
                              psi_dot.tolist(), xg.tolist(), sides.tolist())]
        acc = np.array(acc, dtype=float).reshape(len(t), 2)
    state = (theta, theta_dot, psi, psi_dot, acc[:, 0], acc[:, 1], xg, sides)
    return state


def reaction_history(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray,
                     psi: np.ndarray, psi_dot: np.ndarray, excitation,
                     model_args: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(R_x, R_y, side)`` at every sample of a run (:func:`ground_reaction`).

    ``excitation`` is the run's Pulse or SampledRecord (its vectorised
    ``acceleration_array`` is used when it has one, else ``acceleration(t)``);
    ``model_args`` is ``Scene.model_args()``.  Only the accelerations are
    evaluated sample by sample (the scalar Eq. 8 / Eq. 1): the rest is vectorised.
    """
    b, h, mu, gamma, j, l, g = model_args
    state = _history(t, theta, theta_dot, psi, psi_dot, excitation, model_args)
    rx, ry = reaction_from_accelerations(*state, b, h, mu, gamma, l, g)
    return rx, ry, state[-1]


def lintel_history(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray,
                   psi: np.ndarray, psi_dot: np.ndarray, excitation,
                   model_args: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(F_x, F_y, side)`` at every sample of a run (:func:`lintel_force`);
    arguments as in :func:`reaction_history`."""
    b, h, mu, gamma, j, l, g = model_args
    state = _history(t, theta, theta_dot, psi, psi_dot, excitation, model_args)
    fx, fy = lintel_force_from_accelerations(*state, b, h, mu, gamma, l, g)
    return fx, fy, state[-1]


def _extrema(rx: np.ndarray, ry: np.ndarray, sides: np.ndarray, weight: float
             ) -> tuple[float, float]:
    """``(min R_y / weight, max |R_x|/R_y over rocking samples)``."""
    min_ry = float(np.min(ry)) / weight
    rocking = sides != 0.0
    if not np.any(rocking):
        return min_ry, 0.0
    rx_r, ry_r = rx[rocking], ry[rocking]
    if np.any(ry_r <= 0.0):
        return min_ry, math.inf  # no friction coefficient holds a hopping column
    return min_ry, float(np.max(np.abs(rx_r) / ry_r))


def _first_pull(t: np.ndarray, normal: np.ndarray) -> float | None:
    """Time of the first sample with ``normal <= 0`` (None if there is none)."""
    hit = np.flatnonzero(normal <= 0.0)
    return float(t[hit[0]]) if hit.size else None


def validity_diagnostics(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray,
                         psi: np.ndarray, psi_dot: np.ndarray, excitation,
                         model_args: tuple, alpha: float, overturned: bool) -> dict:
    """Whether the model's contact assumptions hold along a sampled run: the
    columns on the ground (this module) and the lintel on the column tops
    (:mod:`analytic.contact_forces`).

    The window is the part of the run that decides the verdict: all of it,
    except that an overturned run is cut at its last sample with ``|theta| <=
    alpha``.  After that the trilith is past its tipping angle for good and is
    falling; a falling column loses contact of itself (for a thin rod hinged at
    its foot ``R_y`` touches 0 some 70 deg from upright, and the Fig. 5 trilith's
    turns negative near ``|theta| = 1.23`` rad), which would change the
    'topple' criterion's time of fall but not the verdict.  The whole run is
    reported as well (``*_to_verdict``).

    Parameters
    ----------
    t, theta, theta_dot, psi, psi_dot : ndarray
        The trajectory's samples (an impact is two samples at one instant).
    excitation : Pulse or SampledRecord
        The run's excitation (anything with ``acceleration(t)``).
    model_args : tuple
        ``Scene.model_args()``.
    alpha : float
        ``Scene.alpha`` [rad].
    overturned : bool
        The run's verdict.

    Returns
    -------
    dict
        ``min_vertical_reaction``: least ``R_y`` over the window, in units of
        the total weight ``(2 + mu + gamma) g`` (1 at rest with the pendulum
        still; <= 0: the columns would hop).  ``max_friction_demand``: largest
        ``|R_x|/R_y`` over the window's rocking samples (0 if none rocks, inf if
        one has ``R_y <= 0``): the Coulomb coefficient the model silently
        assumes.  ``min_lintel_normal``: least ``F_y`` of the column tops on the
        lintel, in units of the lintel and bob's weight ``(mu + gamma) g`` (1 at
        rest with the pendulum still; <= 0: the lintel would be thrown off).
        ``max_lintel_friction_demand``: largest ``|F_x|/F_y`` over all the
        window's samples, rest included (inf if one has ``F_y <= 0``); both are
        None without a lintel and pendulum (``mu + gamma = 0``: no load on the
        tops).  ``model_valid``: no pull at either contact
        (``min_vertical_reaction > 0`` and ``min_lintel_normal > 0``); the
        friction demands are left to the caller, who knows the coefficient
        (:func:`~analytic.contact_forces.violations`, :func:`analytic.bounds.check_model`).
        ``ground_pull_time`` and ``lintel_pull_time`` [s]: first sample of the
        window with a normal force ``<= 0`` (None if none).  ``reaction_window_end`` [s],
        ``min_vertical_reaction_to_verdict``, ``max_friction_demand_to_verdict``,
        ``min_lintel_normal_to_verdict`` and ``max_lintel_friction_demand_to_verdict``
        (whole run).  Values are taken at the samples only (the ``sample_dt``
        grid plus event instants), so an extremum between two samples can be
        missed by up to one grid step.
    """
    b, h, mu, gamma, j, l, g = model_args
    if len(t) == 0:
        raise ValueError("t must hold at least one sample, got an empty trajectory")
    t = np.asarray(t, dtype=float)
    state = _history(t, theta, theta_dot, psi, psi_dot, excitation, model_args)
    rx, ry = reaction_from_accelerations(*state, b, h, mu, gamma, l, g)
    sides = state[-1]
    weight = system_mass(mu, gamma) * g
    end = len(t)
    if overturned:
        inside = np.flatnonzero(np.abs(np.asarray(theta)) <= alpha)
        end = int(inside[-1]) + 1 if inside.size else 1
    min_ry, demand = _extrema(rx[:end], ry[:end], sides[:end], weight)
    min_all, demand_all = _extrema(rx, ry, sides, weight)
    out = {"min_vertical_reaction": min_ry, "max_friction_demand": demand,
           "reaction_window_end": float(t[end - 1]),
           "min_vertical_reaction_to_verdict": min_all,
           "max_friction_demand_to_verdict": demand_all,
           "ground_pull_time": _first_pull(t[:end], ry[:end])}
    lintel = {"min_lintel_normal": None, "max_lintel_friction_demand": None,
              "min_lintel_normal_to_verdict": None,
              "max_lintel_friction_demand_to_verdict": None, "lintel_pull_time": None}
    if lintel_load(mu, gamma) > 0.0:
        fx, fy = lintel_force_from_accelerations(*state, b, h, mu, gamma, l, g)
        top_weight = lintel_load(mu, gamma) * g
        lintel["min_lintel_normal"], lintel["max_lintel_friction_demand"] = lintel_extrema(
            fx[:end], fy[:end], top_weight)
        (lintel["min_lintel_normal_to_verdict"],
         lintel["max_lintel_friction_demand_to_verdict"]) = lintel_extrema(fx, fy, top_weight)
        lintel["lintel_pull_time"] = _first_pull(t[:end], fy[:end])
    out.update(lintel)
    out["model_valid"] = bool(min_ry > 0.0 and (lintel["min_lintel_normal"] is None
                                                 or lintel["min_lintel_normal"] > 0.0))
    return out
