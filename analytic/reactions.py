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
"""
from __future__ import annotations

import math

import numpy as np

from . import equations as eq

__all__ = ["system_mass", "reaction_from_accelerations", "ground_reaction", "sample_sides",
           "reaction_history", "validity_diagnostics"]


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
    sb = side * b
    st, ct = np.sin(theta), np.cos(theta)
    px = sb * ct - h * st  # top corner relative to the pivot (Eq. 5)
    py = sb * st + h * ct
    w2 = theta_dot * theta_dot
    big_m = eq.total_mass(mu, gamma)  # lintel + bob ride on r; two columns at r/2
    m_s = system_mass(mu, gamma)
    rx = m_s * xg_ddot + big_m * (-theta_ddot * py - w2 * px)
    ry = m_s * g + big_m * (theta_ddot * px - w2 * py)
    if gamma > 0.0:
        sp, cp = np.sin(psi), np.cos(psi)
        v2 = psi_dot * psi_dot
        rx = rx + gamma * l * (psi_ddot * cp - v2 * sp)
        ry = ry + gamma * l * (psi_ddot * sp + v2 * cp)
    return rx, ry


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


def reaction_history(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray,
                     psi: np.ndarray, psi_dot: np.ndarray, excitation,
                     model_args: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(R_x, R_y, side)`` at every sample of a run (:func:`ground_reaction`).

    ``excitation`` is the run's Pulse or SampledRecord (its vectorised
    ``acceleration_array`` is used when it has one, else ``acceleration(t)``);
    ``model_args`` is ``Scene.model_args()``.  Only the accelerations are
    evaluated sample by sample (the scalar Eq. 8 / Eq. 1): the rest is vectorised.
    """
    t = np.asarray(t, dtype=float)
    theta, theta_dot, psi, psi_dot = (np.asarray(a, dtype=float)
                                      for a in (theta, theta_dot, psi, psi_dot))
    sides = sample_sides(t, theta, theta_dot)
    if hasattr(excitation, "acceleration_array"):
        xg = np.asarray(excitation.acceleration_array(t), dtype=float)
    else:
        xg = np.array([excitation.acceleration(float(x)) for x in t])
    b, h, mu, gamma, j, l, g = model_args
    acc = [_accelerations(*row, b, h, mu, gamma, j, l, g)
           for row in zip(theta.tolist(), theta_dot.tolist(), psi.tolist(), psi_dot.tolist(),
                          xg.tolist(), sides.tolist())]
    acc = np.array(acc, dtype=float).reshape(len(t), 2)
    rx, ry = reaction_from_accelerations(theta, theta_dot, psi, psi_dot, acc[:, 0], acc[:, 1],
                                         xg, sides, b, h, mu, gamma, l, g)
    return rx, ry, sides


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


def validity_diagnostics(t: np.ndarray, theta: np.ndarray, theta_dot: np.ndarray,
                         psi: np.ndarray, psi_dot: np.ndarray, excitation,
                         model_args: tuple, alpha: float, overturned: bool) -> dict:
    """Whether the model's contact assumptions hold along a sampled run.

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
        assumes.  ``model_valid``: ``min_vertical_reaction > 0``.
        ``reaction_window_end`` [s], ``min_vertical_reaction_to_verdict`` and
        ``max_friction_demand_to_verdict`` (whole run).  Values are taken at
        the samples only (the ``sample_dt`` grid plus event instants), so an
        extremum between two samples can be missed by up to one grid step.
    """
    b, h, mu, gamma, j, l, g = model_args
    if len(t) == 0:
        raise ValueError("t must hold at least one sample, got an empty trajectory")
    rx, ry, sides = reaction_history(t, theta, theta_dot, psi, psi_dot, excitation, model_args)
    weight = system_mass(mu, gamma) * g
    end = len(t)
    if overturned:
        inside = np.flatnonzero(np.abs(np.asarray(theta)) <= alpha)
        end = int(inside[-1]) + 1 if inside.size else 1
    min_ry, demand = _extrema(rx[:end], ry[:end], sides[:end], weight)
    min_all, demand_all = _extrema(rx, ry, sides, weight)
    return {"min_vertical_reaction": min_ry, "max_friction_demand": demand,
            "model_valid": bool(min_ry > 0.0), "reaction_window_end": float(t[end - 1]),
            "min_vertical_reaction_to_verdict": min_all,
            "max_friction_demand_to_verdict": demand_all}
