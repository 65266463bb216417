"""Forces from a trajectory by central differences (Newton on a group of bodies):
``F = d^2(sum m r)/dt^2 + load (xg_ddot, g)``, the independent check of the
analytic reactions (``tests/analytic/test_reactions.py``, ``tests/analytic/test_lintel_reactions.py``)."""
from __future__ import annotations

import numpy as np


def central_difference_force(scene, tr, pulse, moment, load: float):
    """``F`` per unit ``m1`` at every sample ``i`` whose neighbours ``i-1, i+1`` are
    equally spaced and in the same phase (same rocking side, or all at rest), and
    whose stencil does not straddle the pulse end (``xg_ddot``'s derivative jumps).

    ``moment(theta[3], psi[3], side) -> array (2, 3)``: the group's mass moment
    ``sum m r`` per ``m1`` at the three samples; ``load``: its mass per ``m1``.
    Returns ``(indices, F_fd[2, n])``.
    """
    t = tr.t
    dt = np.diff(t)
    end = pulse.end_time
    idx, out = [], []
    for i in range(1, len(t) - 1):
        if not (dt[i - 1] > 0 and abs(dt[i] - dt[i - 1]) < 1e-12 * max(1.0, t[i])):
            continue
        th = tr.theta[i - 1:i + 2]
        sides = np.sign(th)
        side = sides[1]
        if (side == 0 and np.any(th != 0.0)) or (side != 0 and np.any(sides != side)):
            continue
        if end in t[i - 1:i + 2] or t[i - 1] < end < t[i + 1]:
            continue
        m = moment(th, tr.psi[i - 1:i + 2], side if side else 1.0)
        acc = (m[:, 2] - 2.0 * m[:, 1] + m[:, 0]) / (dt[i] * dt[i])
        out.append(acc + load * np.array([pulse.acceleration(t[i]), scene.g]))
        idx.append(i)
    return np.array(idx), np.array(out).T
