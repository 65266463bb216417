"""Force of the column tops on the lintel along an analytic run: does it stay on?

The analytic model (Eq. 5) carries the lintel on the two column tops without
rotating or sliding: it translates with the top corner ``r(theta)`` of the
columns, and the pendulum hangs from a hinge fixed to it.  Like the ground
contact (:mod:`analytic.reactions`), this contact is not enforced by a force
in the model, so a strong pulse can make the model describe a lintel that the
columns would have to *pull* down (it would be thrown off) or hold with more
friction than the contact has.  This module computes the force that the model
implies.

Linear momentum of the lintel and the bob (the subsystem above the column
tops), per unit column mass ``m1``, in the base frame with the d'Alembert load
``-xg_ddot e_x`` of Eq. 8.  The external forces on it are the weights and the
force ``F`` of both column tops::

    F = (mu + gamma) (r_ddot + (xg_ddot, g))
        + gamma l (psi_ddot (cos psi, sin psi) + psi_dot^2 (-sin psi, cos psi))
    r_ddot = theta_ddot (-(sb sin theta + h cos theta), sb cos theta - h sin theta)
             - theta_dot^2 (sb cos theta - h sin theta, sb sin theta + h cos theta)

with ``sb = side*b`` and the bob at ``hinge + l (sin psi, -cos psi)`` (Eq. 5).
It is the ground reaction of :mod:`analytic.reactions` minus the two columns'
share ``r_ddot + 2 (xg_ddot, g)`` (each column's centre is at ``r/2``).

The lintel does not rotate, so its underside stays horizontal and rests on the
column-top corners that rise (Eq. 5): ``F_y`` is the contact's total normal
force and ``F_x`` its total friction.  How they split between the two columns
depends on the lintel's own moment balance (its shape and the hinge position,
which the model leaves out); ``F_y > 0`` is therefore necessary for both tops
to push, and ``|F_x|/F_y`` is the least Coulomb coefficient that holds the
lintel (a share can need more).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["lintel_load", "top_corner_acceleration", "lintel_force_from_accelerations", "lintel_extrema", "violations"]


def lintel_load(mu: float, gamma: float) -> float:
    """``(m3 + m4)/m1 = mu + gamma``: the mass the column tops carry (Eq. 10 ratios).

    Its weight ``(mu + gamma) m1 g`` is the unit of the lintel normal force: 1 at
    rest with the pendulum hanging still.
    """
    return mu + gamma


def top_corner_acceleration(theta, theta_dot, theta_ddot, side, b: float, h: float):
    """``r_ddot`` of the column-top corner ``r = R(theta) (side b, h)`` that carries
    the lintel (Eq. 5), relative to the pivot: ``theta_ddot e_z x r - theta_dot^2 r``.
    The columns' centres move with ``r / 2``.  Scalars or equal-shape arrays."""
    sb = side * b
    st, ct = np.sin(theta), np.cos(theta)
    px = sb * ct - h * st
    py = sb * st + h * ct
    w2 = theta_dot * theta_dot
    return -theta_ddot * py - w2 * px, theta_ddot * px - w2 * py


def lintel_force_from_accelerations(theta, theta_dot, psi, psi_dot, theta_ddot, psi_ddot,
                                    xg_ddot, side, b: float, h: float, mu: float,
                                    gamma: float, l: float, g: float):
    """``(F_x, F_y)`` per ``m1`` [N/kg]: the force of both column tops on the
    lintel and bob (module docstring), from a state and its accelerations.

    Parameters
    ----------
    theta, theta_dot, psi, psi_dot, theta_ddot, psi_ddot : float or ndarray
        State and accelerations (rad, rad/s, rad/s^2): Eq. 8 / A.1 while
        rocking, ``theta = theta_dot = theta_ddot = 0`` and Eq. 1 at rest.
    xg_ddot : float or ndarray
        Ground acceleration [m/s^2].
    side : float or ndarray
        +1, -1 (rocking, Eq. 8 / A.1) or 0 (rest).
    b, h, mu, gamma, l, g : float
        As in ``Scene.model_args()``.

    Returns
    -------
    (F_x, F_y) : float or ndarray
        ``F_y > 0``: the columns push the lintel up (it stays on them);
        ``|F_x|/F_y``: the friction coefficient it needs not to slide.

    Examples
    --------
    At rest with the pendulum hanging still, the tops carry the lintel and bob
    and accelerate them with the ground:

    >>> fx, fy = lintel_force_from_accelerations(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0,
    ...                                          0.6, 3.0, 1.0, 0.0, 2.0, 9.81)
    >>> float(fx), float(fy)
    (2.0, 9.81)
    """
    ax, ay = top_corner_acceleration(theta, theta_dot, theta_ddot, side, b, h)
    load = lintel_load(mu, gamma)
    fx = load * (xg_ddot + ax)
    fy = load * (g + ay)
    if gamma > 0.0:
        sp, cp = np.sin(psi), np.cos(psi)
        v2 = psi_dot * psi_dot
        fx = fx + gamma * l * (psi_ddot * cp - v2 * sp)
        fy = fy + gamma * l * (psi_ddot * sp + v2 * cp)
    return fx, fy


def lintel_extrema(fx: np.ndarray, fy: np.ndarray, weight: float) -> tuple[float, float]:
    """``(min F_y / weight, max |F_x|/F_y)`` over the given samples.

    Every sample counts, at rest too: the lintel can slide on resting columns as
    well (there ``|F_x|/F_y = mu |xg_ddot| / ((mu + gamma) g)`` with the bob
    hanging still).  The demand is ``inf`` if some ``F_y <= 0`` (no coefficient
    holds a lintel the columns would have to pull).
    """
    if len(fy) == 0:
        raise ValueError("the lintel force needs at least one sample, got none")
    min_fy = float(np.min(fy)) / weight
    if np.any(fy <= 0.0):
        return min_fy, math.inf
    return min_fy, float(np.max(np.abs(fx) / fy))


def violations(diagnostics: dict, friction: float | None = None) -> list[str]:
    """The model's contact assumptions that a run breaks, as sentences.

    Pulls first (a negative normal force: no friction coefficient helps), in the
    order of their first sample; then friction demands above ``friction`` (an
    engine's Coulomb coefficient), the larger excess first.  Empty when the
    model holds.

    Parameters
    ----------
    diagnostics : dict
        An analytic run's diagnostics (:func:`analytic.reactions.validity_diagnostics`).
    friction : float, optional
        Coefficient to compare the friction demands against; None skips them.

    Returns
    -------
    list of str
        E.g. ``"lintel normal force -0.26 of its weight (lintel + bob) at t =
        0.201 s (the lintel would be thrown off the columns)"``.
    """
    d = diagnostics
    pulls = []
    if d["min_vertical_reaction"] <= 0.0:
        pulls.append((d["ground_pull_time"],
                      f"ground normal force {d['min_vertical_reaction']:.2g} of the total weight "
                      f"at t = {d['ground_pull_time']:.3f} s (the columns would hop)"))
    if d["min_lintel_normal"] is not None and d["min_lintel_normal"] <= 0.0:
        pulls.append((d["lintel_pull_time"],
                      f"lintel normal force {d['min_lintel_normal']:.2g} of its weight (lintel + "
                      f"bob) at t = {d['lintel_pull_time']:.3f} s (the lintel would be thrown "
                      f"off the columns)"))
    out = [text for _, text in sorted(pulls, key=lambda p: p[0])]
    if friction is not None:
        slips = [(demand, f"friction demand {demand:.2g} at {where} above the engine's "
                          f"{friction:.2g}")
                 for demand, where in ((d["max_friction_demand"], "the ground"),
                                       (d["max_lintel_friction_demand"], "the column tops"))
                 if demand is not None and demand > friction]
        out += [text for _, text in sorted(slips, key=lambda p: -p[0])]
    return out
