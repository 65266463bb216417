"""2D drawing of a trilith state: two rocking columns, the translating lintel, the
pendulum and the moving ground.

The geometry is the paper's Eq. 5 (positions of the bodies while rocking),
written once in :func:`trilith_shape` as a pure function of
``(scene, theta, psi, x_g)``; :class:`TrilithArtist` turns it into matplotlib
patches and updates them frame by frame (recordings and live windows use the
same code).

Frame: x to the right, y up, origin at the middle of the gap between the
columns on the ground *at rest*; :func:`trilith_shape` displaces everything by
the ground displacement ``x_g(t)``.  Panels (:class:`TrilithArtist`) are drawn
in the base frame instead: the camera follows the ground, so a trilith keeps its
place and scale however far the base drifts (a one-sine pulse leaves it
``2 pi A / Omega^2`` away, 1.3 m at A = 25 m/s^2, Omega = 11 rad/s), and light
vertical lines fixed in the world slide by ``-x_g`` to show the base motion.
Conventions (``analytic/trajectory.py``): ``theta > 0`` rotates the columns
counter-clockwise about their *left* base corners, ``theta < 0`` clockwise
about their right ones; the lintel rides on the top-right corner of each column
when ``theta > 0`` and on the top-left one when ``theta < 0`` (Eq. 5:
``r_G3 = x_g + b3 + b cos(theta) - h sin(theta)``, ...), so it translates
without rotating.  ``psi`` is the pendulum's angle from the downward vertical,
counter-clockwise positive: the bob is at ``hinge + l (sin psi, -cos psi)``.
The model has no contact between the bob and the ground: once the columns have
fallen far enough for that point to be below the ground, the bob is drawn lying
on the ground at the same distance ``l`` from the hinge (where a real bob would be),
and ``TrilithShape.bob_grounded`` says so.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from trilith_xval.analytic.parameters import Scene

__all__ = ["TrilithShape", "trilith_shape", "view_limits", "TrilithArtist", "draw_trilith",
           "COLORS"]

# Muted colours that stay distinct after GIF palette quantisation.
COLORS = {"column": "#8c7b6b", "lintel": "#6b5b4b", "edge": "#2b2b2b",
          "pendulum": "#b03a2e", "ground": "#4a4a4a", "text": "#111111", "world": "#c8d0dc"}


@dataclass(frozen=True)
class TrilithShape:
    """Outlines of one trilith state in the ground-fixed drawing frame [m].

    ``columns``: two (4, 2) arrays (left column first), corners counter-clockwise
    from the bottom-left one.  ``lintel``: (4, 2) array, same order; ``None``
    when the scene has no lintel (``mu = 0`` and no pendulum to carry: the
    engines then build no lintel body and the columns are free blocks).  ``hinge``
    and ``bob``: (2,) arrays, ``None`` without a pendulum.  ``ground_x``: the
    ground displacement ``x_g`` the shape was drawn with.
    """

    columns: tuple[np.ndarray, np.ndarray]
    lintel: np.ndarray | None
    hinge: np.ndarray | None
    bob: np.ndarray | None
    ground_x: float
    bob_grounded: bool = False


def _rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _rectangle(x0: float, y0: float, width: float, height: float) -> np.ndarray:
    return np.array([[x0, y0], [x0 + width, y0], [x0 + width, y0 + height],
                     [x0, y0 + height]], dtype=float)


def trilith_shape(scene: Scene, theta: float, psi: float = 0.0, x_g: float = 0.0) -> TrilithShape:
    """The outlines of the trilith at rocking angle ``theta`` (Eq. 5).

    Parameters
    ----------
    scene : Scene
        Geometry: ``b``, ``h``, gap ``d``, lintel thickness, hinge position,
        pendulum length.
    theta : float
        Column rotation [rad]; > 0 about the left base corners, < 0 about the
        right ones.
    psi : float
        Pendulum angle from the downward vertical [rad], CCW positive; ignored
        without a pendulum (``gamma = 0``).
    x_g : float
        Ground displacement [m] (``excitation.displacement(t)``).

    Returns
    -------
    TrilithShape
    """
    for name, value in (("theta", theta), ("psi", psi), ("x_g", x_g)):
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    b, h, d = scene.b, scene.h, scene.d
    side = 1.0 if theta >= 0.0 else -1.0
    rot = _rotation(theta)
    shift = np.array([x_g, 0.0])
    columns = []
    for x_left in (-0.5 * d - b, 0.5 * d):
        rest = _rectangle(x_left, 0.0, b, h)
        # Pivot: left base corner when theta > 0, right base corner when theta < 0.
        pivot = rest[0] if side > 0 else rest[1]
        columns.append((rest - pivot) @ rot.T + pivot + shift)
    # The lintel translates with the corner it rides on (top-right of a column for
    # theta > 0, top-left for theta < 0): that corner sits at (side*b, h) from the
    # pivot at rest and at R(theta) (side*b, h) while rocking.
    corner = np.array([side * b, h])
    lift = rot @ corner - corner
    length = scene.lintel_length
    lintel = None
    if scene.mu > 0.0 or scene.has_pendulum:
        lintel = _rectangle(-0.5 * length, h, length, scene.lintel_thickness) + lift + shift
    hinge = bob = None
    grounded = False
    if scene.has_pendulum:
        ell = scene.pendulum_length
        hinge = np.array([scene.hinge_x, h]) + lift + shift
        bob = hinge + ell * np.array([math.sin(psi), -math.cos(psi)])
        r = bob_radius(scene)
        if bob[1] < r:  # below the ground: lay it on the ground, still l from the hinge
            grounded = True
            drop = max(hinge[1] - r, 0.0)
            reach = math.sqrt(max(ell * ell - drop * drop, 0.0))
            bob = np.array([hinge[0] + math.copysign(reach, math.sin(psi) or 1.0),
                            hinge[1] - min(drop, ell)])
    return TrilithShape(columns=(columns[0], columns[1]), lintel=lintel, hinge=hinge, bob=bob,
                        ground_x=float(x_g), bob_grounded=grounded)


def bob_radius(scene: Scene) -> float:
    """Drawn radius of the pendulum bob [m]: a fixed fraction of the column width."""
    return 0.15 * scene.b


def view_limits(scene: Scene, theta, psi, x_g, margin: float = 0.08, headroom: float = 0.35
                ) -> tuple[tuple[float, float], tuple[float, float]]:
    """Axis limits that contain every given state, with a relative ``margin``
    and ``headroom`` (fraction of the height) above it for the text overlay.

    ``theta``, ``psi``, ``x_g`` are equal-length sequences (all frames of a
    recording), so the view does not jump from frame to frame; panels drawn in
    the base frame pass ``x_g = 0``.
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    psi = np.atleast_1d(np.asarray(psi, dtype=float))
    x_g = np.atleast_1d(np.asarray(x_g, dtype=float))
    if not (theta.shape == psi.shape == x_g.shape) or theta.size == 0:
        raise ValueError("theta, psi and x_g must be non-empty sequences of equal length")
    r = bob_radius(scene) if scene.has_pendulum else 0.0
    xs, ys = [], []
    # The extreme states suffice for columns and lintel; every pendulum state is
    # cheap enough to include directly.
    for k in {int(np.argmin(theta)), int(np.argmax(theta)), int(np.argmin(x_g)),
              int(np.argmax(x_g)), 0, theta.size - 1}:
        shape = trilith_shape(scene, float(theta[k]), float(psi[k]), float(x_g[k]))
        pts = np.vstack([*shape.columns] + ([shape.lintel] if shape.lintel is not None else []))
        xs += [pts[:, 0].min(), pts[:, 0].max()]
        ys += [pts[:, 1].max()]
    if scene.has_pendulum:
        for k in range(theta.size):
            shape = trilith_shape(scene, float(theta[k]), float(psi[k]), float(x_g[k]))
            xs += [shape.bob[0] - r, shape.bob[0] + r]
            ys += [shape.bob[1] + r]
    x_lo, x_hi = min(xs), max(xs)
    y_hi = max(ys)
    pad = margin * max(x_hi - x_lo, y_hi)
    # The ground band below y = 0 gets its own fixed share of the height.
    return (x_lo - pad, x_hi + pad), (-0.06 * y_hi - pad, (1.0 + headroom) * y_hi + pad)


class TrilithArtist:
    """The matplotlib artists of one trilith panel, updated in place per frame."""

    def __init__(self, ax, scene: Scene, title: str | None = None) -> None:
        from matplotlib.patches import Circle, Polygon

        self.ax = ax
        self.scene = scene
        self.columns = [Polygon(np.zeros((4, 2)), closed=True, fc=COLORS["column"],
                                ec=COLORS["edge"], lw=1.0) for _ in range(2)]
        self.lintel = Polygon(np.zeros((4, 2)), closed=True, fc=COLORS["lintel"],
                              ec=COLORS["edge"], lw=1.0)
        self.lintel.set_visible(trilith_shape(scene, 0.0).lintel is not None)
        for patch in (*self.columns, self.lintel):
            ax.add_patch(patch)
        self.rod = self.bob = None
        if scene.has_pendulum:
            (self.rod,) = ax.plot([0, 0], [0, 0], color=COLORS["pendulum"], lw=1.5)
            self.bob = Circle((0.0, 0.0), bob_radius(scene), fc=COLORS["pendulum"],
                              ec=COLORS["edge"], lw=0.8, zorder=3)
            ax.add_patch(self.bob)
        (self.ground,) = ax.plot([], [], color=COLORS["ground"], lw=2.0)
        # Hatch ticks below the ground line belong to the base (drawn once the limits
        # are known); the light vertical lines are fixed in the world and slide by -x_g.
        (self.hatch,) = ax.plot([], [], color=COLORS["ground"], lw=0.8)
        (self.world,) = ax.plot([], [], color=COLORS["world"], lw=0.8, zorder=0)
        self.text = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", ha="left",
                            family="monospace", fontsize=8, color=COLORS["text"])
        if title:
            ax.set_title(title, fontsize=10)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])

    def set_limits(self, xlim, ylim) -> None:
        """Set the view and draw the base (ground line and hatch: static in the
        base frame)."""
        self.ax.set_xlim(*xlim)
        self.ax.set_ylim(*ylim)
        x_lo, x_hi = xlim
        self.ground.set_data([x_lo, x_hi], [0.0, 0.0])
        depth = 0.03 * (x_hi - x_lo)
        starts = np.arange(x_lo, x_hi + self._step, self._step)
        hx = np.full(3 * starts.size, np.nan)
        hy = np.full(3 * starts.size, np.nan)
        hx[0::3], hx[1::3] = starts, starts - depth
        hy[0::3], hy[1::3] = 0.0, -depth
        self.hatch.set_data(hx, hy)

    @property
    def _step(self) -> float:
        return 0.5 * self.scene.b

    def update(self, t: float, theta: float, psi: float, x_g: float, note: str = "") -> list:
        """Move every artist to state ``(theta, psi)``, in the base frame (the
        camera follows the ground); slide the world lines by ``-x_g`` and write the
        overlay (time, angles, ground displacement, ``note``)."""
        shape = trilith_shape(self.scene, theta, psi, 0.0)
        for patch, outline in zip(self.columns, shape.columns):
            patch.set_xy(outline)
        if shape.lintel is not None:
            self.lintel.set_xy(shape.lintel)
        if self.rod is not None:
            self.rod.set_data([shape.hinge[0], shape.bob[0]], [shape.hinge[1], shape.bob[1]])
            self.bob.center = (float(shape.bob[0]), float(shape.bob[1]))
        x_lo, x_hi = self.ax.get_xlim()
        y_lo, y_hi = self.ax.get_ylim()
        step = 4.0 * self._step  # world lines every 2 b
        first = -x_g + step * math.floor((x_lo + x_g) / step)
        xs = np.arange(first, x_hi + step, step)
        wx = np.full(3 * xs.size, np.nan)
        wy = np.full(3 * xs.size, np.nan)
        wx[0::3], wx[1::3] = xs, xs
        wy[0::3], wy[1::3] = y_lo, y_hi
        self.world.set_data(wx, wy)
        lines = [f"t     = {t:7.3f} s",
                 f"theta = {theta:+7.4f} rad",
                 f"psi   = {psi:+7.4f} rad" if self.scene.has_pendulum else "psi   =   (none)",
                 f"x_g   = {x_g:+7.4f} m"]
        if note:
            lines.append(note)
        self.text.set_text("\n".join(lines))
        artists = [self.world, *self.columns, self.lintel, self.ground, self.hatch, self.text]
        if self.rod is not None:
            artists += [self.rod, self.bob]
        return artists


def draw_trilith(ax, scene: Scene, t: float, theta: float, psi: float = 0.0, x_g: float = 0.0,
                 title: str | None = None, limits=None) -> TrilithArtist:
    """Draw one trilith state on ``ax`` and return its artists for later updates.

    ``limits``: ``(xlim, ylim)``; by default those of this single state
    (:func:`view_limits`).
    """
    artist = TrilithArtist(ax, scene, title)
    artist.set_limits(*(limits or view_limits(scene, [theta], [psi], [0.0])))
    artist.update(t, theta, psi, x_g)
    return artist
