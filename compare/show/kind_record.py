"""Recordings of a scene the model does not cover (:mod:`analytic.kinds`: drums,
unequal columns, a block on a block): every body of the structure drawn from the
engine's own poses, one panel per engine, on one time base, scale and camera.

A kind's :class:`~analytic.trajectory.Trajectory` carries the mean rotation of the
bodies on the ground only, so :func:`run_with_poses` runs the engine's own loop
and keeps, at each sample, every body's centre and angle, the bob's angle and the
ground's displacement.  Panels are drawn in the base frame (the camera follows
the ground, as :mod:`compare.show.record` does for the trilith); each says the
engine's verdict (:mod:`engines.structure_monitor`) once it is reached.  There is
no model panel: engine against engine, never agreement with the model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["PoseRun", "run_with_poses", "KindPanels", "structure_outlines"]


@dataclass(frozen=True, eq=False)
class PoseRun:
    """One engine's run with its bodies' poses.

    ``t`` (n,) [s]; ``poses`` (n, bodies, 3): centre ``x, y`` [m] in the world
    frame and angle [rad, CCW], in the structure's body order; ``psi`` (n,) the
    bob's angle from the downward vertical [rad] (0 without a bob); ``ground_x``
    (n,) the ground's displacement [m]; ``structure`` the
    :class:`engines.geometry.Structure` run; ``trajectory`` the engine's
    Trajectory with its verdict.
    """

    t: np.ndarray
    poses: np.ndarray
    psi: np.ndarray
    ground_x: np.ndarray
    structure: object
    trajectory: object


def run_with_poses(run) -> PoseRun:
    """Run ``run`` (a :class:`compare.run.spec.RunSpec` on a kind) in its engine's
    own loop, keeping every sample's poses (module docstring)."""
    from trilith_xval.engines import get_backend
    engine = get_backend(run.backend)(run.scene, run.excitation, run.settings)
    samples = []
    read = engine.read

    def read_and_keep():  # the loop's own read: the poses the verdict is judged on
        state = read()
        samples.append((engine.step_index * engine.settings.dt, state.psi, state.ground_x,
                        [(p.x, p.y, p.angle) for p in state.bodies]))
        return state

    engine.read = read_and_keep
    trajectory = engine.run()
    if not samples:
        raise ValueError(f"{run.backend} returned no sample")
    return PoseRun(t=np.array([s[0] for s in samples]),
                   poses=np.array([s[3] for s in samples], dtype=float),
                   psi=np.array([s[1] for s in samples]),
                   ground_x=np.array([s[2] for s in samples]),
                   structure=engine.structure, trajectory=trajectory)


def _rotate(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, s], [-s, c]])


def structure_outlines(structure, pose: np.ndarray, psi: float, ground_x: float):
    """``(boxes, hinge, bob)`` in the base frame [m]: a (4, 2) outline per body
    (counter-clockwise from the bottom-left corner), the bob's hinge and centre
    (None without a bob), for one sample's ``pose`` (bodies, 3)."""
    boxes = []
    for box, (x, y, angle) in zip(structure.bodies, pose):
        half = 0.5 * np.array([[-box.b, -box.h], [box.b, -box.h], [box.b, box.h],
                               [-box.b, box.h]])
        boxes.append(_rotate(half, angle) + [x - ground_x, y])
    hinge = bob = None
    if structure.bob is not None:
        k = [b.name for b in structure.bodies].index(structure.bob.parent)
        x, y, angle = pose[k]
        hinge = _rotate(np.array([structure.bob.anchor]), angle)[0] + [x - ground_x, y]
        bob = hinge + structure.bob.length * np.array([math.sin(psi), -math.cos(psi)])
    return boxes, hinge, bob


def _note(traj, t: float) -> str:
    v = traj.verdict
    if v.status in ("overturned", "collapsed", "unstable") and v.time is not None \
            and t >= v.time:
        return f"{v.status.upper()} at {v.time:.3f} s\n{_short(v.reason)}"
    if t > traj.t[-1]:
        return f"run ended: {v.status}"
    return ""


def _short(reason: str | None) -> str:
    """The verdict's reason up to its first bracket (the body and what it did)."""
    return (reason or "").split(" (")[0]


class KindPanels:
    """One figure, one panel per engine (duck-typed as
    :class:`compare.show.record.Panels` for :func:`compare.show.record.render_frames`)."""

    def __init__(self, times, runs: dict[str, PoseRun], excitation, figure) -> None:
        from matplotlib.patches import Circle, Polygon

        from trilith_xval.compare.show.draw import COLORS
        self.times = np.asarray(times, dtype=float)
        self.runs = runs
        self.x_g = np.array([excitation.displacement(float(t)) for t in self.times])
        # Each sample's poses at the frame times, held after a run's end.
        self.frames = {}
        for name, r in runs.items():
            k = np.clip(np.searchsorted(r.t, self.times, side="right") - 1, 0, r.t.size - 1)
            self.frames[name] = [structure_outlines(r.structure, r.poses[i], r.psi[i],
                                                    r.ground_x[i]) for i in k]
        pts = np.vstack([p for fr in self.frames.values() for boxes, _, bob in fr
                         for p in boxes + ([bob[None, :]] if bob is not None else [])])
        first = next(iter(runs.values())).structure
        width = min(box.b for box in first.bodies)
        r_bob = 0.15 * width
        x_lo, x_hi = pts[:, 0].min() - r_bob, pts[:, 0].max() + r_bob
        y_hi = max(pts[:, 1].max(), 0.0) + r_bob
        pad = 0.08 * max(x_hi - x_lo, y_hi)
        xlim, ylim = (x_lo - pad, x_hi + pad), (-0.06 * y_hi - pad, 1.4 * y_hi + pad)
        # Fill the panel's width (a tall, narrow structure would leave the verdict
        # text running out of a narrow axes): widen x about its middle.
        aspect = (0.98 * figure.get_figwidth() / len(runs)) / (0.85 * figure.get_figheight())
        half = 0.5 * max(xlim[1] - xlim[0], aspect * (ylim[1] - ylim[0]))
        mid = 0.5 * (xlim[0] + xlim[1])
        xlim = (mid - half, mid + half)
        axes = figure.subplots(1, len(runs), squeeze=False)[0]
        figure.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.86, wspace=0.03)
        figure.suptitle("engine against engine, never agreement with the model", fontsize=8,
                        y=0.995)
        self.artists = {}
        for ax, (name, r) in zip(axes, runs.items()):
            bodies = []
            for box in r.structure.bodies:
                face = COLORS["lintel"] if box.name == "lintel" else COLORS["column"]
                bodies.append(Polygon(np.zeros((4, 2)), closed=True, fc=face, ec=COLORS["edge"],
                                      lw=1.0))
                ax.add_patch(bodies[-1])
            rod = bob = None
            if r.structure.bob is not None:
                (rod,) = ax.plot([0, 0], [0, 0], color=COLORS["pendulum"], lw=1.5)
                bob = Circle((0.0, 0.0), r_bob, fc=COLORS["pendulum"], ec=COLORS["edge"],
                             lw=0.8, zorder=3)
                ax.add_patch(bob)
            ax.plot(xlim, [0.0, 0.0], color=COLORS["ground"], lw=2.0)
            text = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", ha="left",
                           family="monospace", fontsize=8, color=COLORS["text"])
            ax.set_title(f"{name} ({r.structure.kind})", fontsize=10)
            ax.set_aspect("equal")
            ax.set_xlim(*xlim)
            ax.set_ylim(*ylim)
            ax.set_xticks([])
            ax.set_yticks([])
            self.artists[name] = (bodies, rod, bob, text)

    def __len__(self) -> int:
        return self.times.size

    def update(self, k: int) -> list:
        """Show frame ``k`` in every panel; returns the changed artists."""
        t = float(self.times[k])
        changed = []
        for name, (bodies, rod, bob, text) in self.artists.items():
            boxes, hinge, centre = self.frames[name][k]
            for patch, outline in zip(bodies, boxes):
                patch.set_xy(outline)
            changed += bodies
            if rod is not None:
                rod.set_data([hinge[0], centre[0]], [hinge[1], centre[1]])
                bob.center = (float(centre[0]), float(centre[1]))
                changed += [rod, bob]
            lines = [f"t   = {t:7.3f} s", f"x_g = {self.x_g[k]:+7.4f} m"]
            note = _note(self.runs[name].trajectory, t)
            text.set_text("\n".join(lines + ([note] if note else [])))
            changed.append(text)
        return changed
