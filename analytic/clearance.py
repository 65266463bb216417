"""Does the pendulum bob clear the columns?  Pure geometry of the rocking frame.

The analytic model lets the pendulum swing freely (Eq. 10-12); a real trilith's
bob hangs between the columns and meets an inner column face at a large swing.
Where it would, the model (and an engine that lets the bob pass through the
column, or stops it) no longer describes the same structure.

Geometry, in the lintel's frame (origin at the middle of the lintel's underside,
x to the right, y up; the lintel translates, it does not rotate).  For
``theta > 0`` (rocking about the left bottom corners, Housner's convention of
:mod:`analytic.equations`) each column turns by ``theta`` counter-clockwise and
carries the lintel on its top-right corner, so relative to the lintel it turns
about that corner:

* left column, inner (right) face through ``(-d/2, 0)``:
  ``x_L(y) = -d/2 - y tan(theta)``;
* right column, inner (left) face through ``(d/2 + b - b cos(theta), -b sin(theta))``:
  ``x_R(y) = d/2 + b (1 - cos theta) - (y + b sin theta) tan(theta)``;
* the bob (``psi`` from the vertical, positive to the right) at
  ``(hinge_x + l sin psi, -l cos psi)``.

The clearance is the perpendicular distance from the bob's centre to the nearer
face, ``(x - x_L) cos(theta)`` or ``(x_R - x) cos(theta)``, minus the bob's
radius; ``theta < 0`` is the mirror image.  Upright (``theta = 0``) the bob
touches a face at ``sin(psi) = (d/2 - r - hinge_x)/l``: for the Fig. 8 trilith
``lam = 3``, ``b = 0.6`` m (``d = h = 1.8`` m, ``l = 2h/3 = 1.2`` m),
``psi = asin(0.9/1.2) = 0.848`` rad.
"""
from __future__ import annotations

import numpy as np

__all__ = ["bob_clearance", "check_clearance"]


def bob_clearance(scene, theta, psi, bob_radius: float = 0.0):
    """Distance [m] from the bob to the nearer inner column face (< 0: inside it).

    Parameters
    ----------
    scene : Scene
        With its pendulum (``l``, ``hinge_x``, gap ``d``, ``b``).
    theta, psi : float or ndarray
        Rocking and pendulum angles [rad] (the model's coordinates).
    bob_radius : float
        The bob's radius [m]; default 0, the model's point mass.

    Returns
    -------
    float or ndarray
        Same shape as ``theta``/``psi`` (broadcast).

    Examples
    --------
    >>> from trilith_xval.analytic.parameters import Scene
    >>> sc = Scene(b=0.6, lam=3.0, gamma=0.1)
    >>> round(float(bob_clearance(sc, 0.0, np.arcsin(0.9 / 1.2))), 12)
    0.0
    """
    theta, psi = np.broadcast_arrays(np.asarray(theta, float), np.asarray(psi, float))
    sign = np.where(theta < 0.0, -1.0, 1.0)  # mirror theta < 0 onto theta > 0
    th = sign * theta
    x = sign * (scene.hinge_x + scene.pendulum_length * np.sin(psi))
    y = -scene.pendulum_length * np.cos(psi)
    half, b = 0.5 * scene.d, scene.b
    tan, cos = np.tan(th), np.cos(th)
    x_left = -half - y * tan
    x_right = half + b * (1.0 - cos) - (y + b * np.sin(th)) * tan
    out = np.minimum(x - x_left, x_right - x) * cos - bob_radius
    return float(out) if out.ndim == 0 else out


def check_clearance(scene, trajectory, bob_radius: float = 0.0) -> dict:
    """The smallest bob-column clearance along a model run.

    Parameters
    ----------
    scene : Scene
    trajectory : Trajectory
        A run of ``scene`` (samples ``t``, ``theta``, ``psi``); an overturned run
        is read up to its last sample with ``|theta| <= alpha`` (past it the
        frame is falling, as in :func:`analytic.reactions.validity_diagnostics`).
    bob_radius : float
        [m], default 0 (the model's point mass).

    Returns
    -------
    dict
        ``min_clearance`` [m] (None without a pendulum), ``t`` [s] and ``psi``
        [rad] where it occurs, ``valid`` (clearance >= 0) and ``reason`` ("" when
        valid).
    """
    if not scene.has_pendulum or len(trajectory.t) == 0:
        return {"min_clearance": None, "t": None, "psi": None, "valid": True, "reason": ""}
    t, theta, psi = (np.asarray(a) for a in (trajectory.t, trajectory.theta, trajectory.psi))
    if trajectory.overturned:
        inside = np.nonzero(np.abs(theta) <= scene.alpha)[0]
        end = int(inside[-1]) + 1 if inside.size else 1
        t, theta, psi = t[:end], theta[:end], psi[:end]
    c = bob_clearance(scene, theta, psi, bob_radius)
    k = int(np.argmin(c))
    valid = bool(c[k] >= 0.0)
    reason = "" if valid else (f"the bob meets an inner column face at t = {t[k]:.3g} s "
                               f"(psi = {psi[k]:.3g} rad, {-c[k]:.3g} m inside)")
    return {"min_clearance": float(c[k]), "t": float(t[k]), "psi": float(psi[k]),
            "valid": valid, "reason": reason}
