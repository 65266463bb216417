"""What an engine run is checked against, defined once and applied to every engine.

An engine reads its bodies into a :class:`PlaneState` (the analytic plane of
:mod:`engines.geometry`); :class:`Diagnostics` turns the samples into

* the **model-holds window**: both columns stand (``|theta| < alpha`` for each,
  at every sample so far).  Past ``alpha`` the columns may hop and part (the
  model's vertical reaction turns negative in the fall); one swinging back below
  ``alpha`` is still the collapse, beyond the model.  The contact diagnostics
  below are taken inside the window only;
* ``pivot_sliding_max`` [m]: horizontal drift of a column's pivot corner from its
  upright rest position, relative to the ground (while rocking the corner it
  leans on, at rest both);
* ``lintel_rotation_max`` [rad]: the lintel's rotation (the model's lintel
  translates);
* ``penetration_max`` [m]: depth of the columns' base corners below the ground's
  top face, from the poses (the same measure for every engine, whatever its
  contact model reports);
* ``out_of_plane_max`` [m], ``out_of_plane_rotation_max`` [rad]: 3D engines'
  drift and rotation out of the analytic plane (0 for planar engines);
* **blow-up** (at any time): a non-finite state, a body (column or lintel)
  farther than ``blowup_distance`` trilith sizes from its start relative to the
  ground, faster than ``blowup_speed (sqrt(g size) + peak ground speed)`` (the
  pendulum: ``l |psi_dot|``), or, inside the window, drifted out of the plane by
  more than ``max_out_of_plane`` sizes.  The thresholds are the run's
  :class:`~engines.monitor.MonitorSettings`.
"""
from __future__ import annotations

import math
from typing import NamedTuple

from . import geometry

__all__ = ["Pose", "PlaneState", "Diagnostics", "peak_ground_speed", "joint_plane_state"]


class Pose(NamedTuple):
    """A body in the analytic plane: centre of mass ``x, y`` [m], ``angle`` [rad]
    (CCW), velocity ``vx, vy`` [m/s], ``omega`` [rad/s]."""

    x: float
    y: float
    angle: float
    vx: float
    vy: float
    omega: float


class PlaneState(NamedTuple):
    """What :meth:`engines.base.Engine.read` returns at a sample.

    ``columns``: left and right column poses; ``lintel``: its pose or None
    (``mu = 0``); ``psi, psi_dot``: the pendulum's absolute angle from the
    downward vertical (CCW) and its rate, 0 without pendulum; ``ground_x``: the
    ground's displacement [m] (0 under the gravity base motion);
    ``out_of_plane``: largest drift [m] of a body out of the plane and
    ``out_of_plane_rotation`` its largest rotation [rad] out of it (3D engines);
    ``problem``: an engine's own report that its state is invalid (e.g. a
    solver reset), or None; ``bodies``: every box of a structure that is not
    the parametric trilith (:mod:`analytic.kinds`), in its structure's order
    (``columns`` is then empty).
    """

    columns: tuple[Pose, Pose]
    lintel: Pose | None = None
    psi: float = 0.0
    psi_dot: float = 0.0
    ground_x: float = 0.0
    out_of_plane: float = 0.0
    out_of_plane_rotation: float = 0.0
    problem: str | None = None
    bodies: tuple[Pose, ...] = ()


def joint_plane_state(states, pendulum=None) -> PlaneState:
    """The plane state of an engine whose bodies hang on planar joints (DART, Drake).

    ``states``: ``(x, y, angle, vx, vy, omega)`` of the left column, the right
    column and, when there is one, the lintel; ``pendulum``: the bob's hinge angle
    and rate relative to the lintel, or None.  ``psi`` is measured from the downward
    vertical, so the lintel's rotation is added to the relative angle."""
    bodies = [Pose(*state) for state in states]
    lintel = bodies[2] if len(bodies) > 2 else None
    psi = psi_dot = 0.0
    if pendulum is not None:
        psi, psi_dot = pendulum[0] + lintel.angle, pendulum[1] + lintel.omega
    return PlaneState((bodies[0], bodies[1]), lintel, psi, psi_dot)


def peak_ground_speed(excitation) -> float:
    """A bound of ``max |xg_dot|`` [m/s] (it only scales the blow-up speed limit):
    the excitation's ``velocity_bound()``."""
    return excitation.velocity_bound()


class Diagnostics:
    """Accumulates the diagnostics of one run from its :class:`PlaneState` samples.

    Parameters
    ----------
    scene, excitation
        What is run.
    monitor : MonitorSettings
        The thresholds (``uplift_angle``, ``max_out_of_plane``, blow-up).
    """

    def __init__(self, scene, excitation, monitor) -> None:
        self.scene = scene
        self.size = size = geometry.size(scene)
        self.alpha = scene.alpha
        self.uplift_angle = monitor.uplift_angle
        self.rest_corners = [(x, x + scene.b) for x in geometry.column_lefts(scene)]
        self.max_distance = monitor.blowup_distance * size
        self.max_speed = monitor.blowup_speed * (math.sqrt(scene.g * size)
                                                 + peak_ground_speed(excitation))
        self.max_out_of_plane = monitor.max_out_of_plane * size
        self.blowup_distance = monitor.blowup_distance
        self.length = scene.pendulum_length if scene.has_pendulum else 0.0
        self.start: list[tuple[float, float]] | None = None
        self.standing = True
        self.values = dict(pivot_sliding_max=0.0, lintel_rotation_max=0.0, penetration_max=0.0,
                           out_of_plane_max=0.0, out_of_plane_rotation_max=0.0)

    def update(self, state: PlaneState) -> str | None:
        """Take one sample into the diagnostics; returns what blew up, or None."""
        bodies = state.columns + ((state.lintel,) if state.lintel is not None else ())
        if not all(map(math.isfinite, (state.psi, state.psi_dot, state.ground_x)))\
                or not all(math.isfinite(v) for body in bodies for v in body):
            return "non-finite state"
        if state.problem is not None:
            return state.problem
        if self.start is None:
            self.start = [(body.x, body.y) for body in bodies]
        gx, values = state.ground_x, self.values
        left, right = state.columns
        self.standing = self.standing and max(abs(left.angle), abs(right.angle)) < self.alpha
        if self.standing:
            b, h = self.scene.b, self.scene.h
            for k, col in enumerate(state.columns):
                xl, yl, xr, yr = geometry.base_corners(col.x, col.y, col.angle, b, h)
                rest = self.rest_corners[k]
                if abs(col.angle) > self.uplift_angle:  # rocking: the corner it leans on
                    slide = abs(xl - rest[0] - gx) if col.angle > 0.0 else abs(xr - rest[1] - gx)
                else:  # at rest: both corners
                    slide = max(abs(xl - rest[0] - gx), abs(xr - rest[1] - gx))
                values["pivot_sliding_max"] = max(values["pivot_sliding_max"], slide)
                values["penetration_max"] = max(values["penetration_max"], -yl, -yr)
            if state.lintel is not None:
                values["lintel_rotation_max"] = max(values["lintel_rotation_max"],
                                                    abs(state.lintel.angle))
            values["out_of_plane_max"] = max(values["out_of_plane_max"], state.out_of_plane)
            values["out_of_plane_rotation_max"] = max(values["out_of_plane_rotation_max"],
                                                      state.out_of_plane_rotation)
            if state.out_of_plane > self.max_out_of_plane:
                return f"out-of-plane drift {state.out_of_plane:.3g} m"
        for body, (x0, y0) in zip(bodies, self.start):
            if math.hypot(body.x - x0 - gx, body.y - y0) > self.max_distance:
                return f"a body flew away (> {self.blowup_distance:g} trilith sizes)"
            if math.hypot(body.vx, body.vy) > self.max_speed:
                return f"a body exceeded {self.max_speed:.3g} m/s"
        if self.length * abs(state.psi_dot) > self.max_speed:
            return f"the pendulum exceeded {self.max_speed:.3g} m/s"
        return None
