"""Measured planar impacts of a square block: a loader for a user's copy of the
files and the rocking-like impacts found in them.

The data
--------
500 drops of a square block (side 0.06 m) tracked by motion capture at 250 Hz,
one file per drop, ``traj_<n>.csv`` with the header ``x,z,th,vx,vz,vth``: the
centre [m], the orientation [rad] and their rates, one row per frame.  The
files come from the MIT MCube lab (Fazeli et al.) and are redistributed in the
``DAIRLab/ImpactModeling`` repository (``IRB Bound/IRB Square/``); see
``docs/measured-impacts.md`` for the citation and the licence.  Nothing of them is
shipped here: :func:`load_folder` reads the user's own copy.

Conventions (those of the dataset's own reader ``ReadData.m``): ``x``
horizontal, ``z`` up, the ground at ``z = 0``; a body point ``(ox, oz)`` is at
``(x + ox cos(th) - oz sin(th), z + ox sin(th) + oz cos(th))`` (``ReadData.m``
draws ``-x`` and turns the body by ``-th``, which is the same figure mirrored).
The rate columns are backward differences of the positions at 250 Hz (from the
third row on ``vth[k] = (th[k] - th[k-1]) * 250``, and likewise ``vx``, ``vz``),
so only positions are used.

Impact rule (``ReadData.m``): a frame ``j`` whose centre height is a strict
local minimum, ``z[j] < z[j-1]`` and ``z[j] < z[j+1]``; this is ReadData's
"``zDot`` changes sign and ``z`` is at a local minimum", since its ``zDot`` is
the backward difference of ``z``.

Rocking-like filter (:class:`Filter`; each threshold's reason there): at frame
``j`` a face is flat (Housner's impact: the second corner of a face lands);
over the ``window`` frames before, the block pivots on one corner (the lowest
corner at the window's start stays on the ground) while the tilt falls onto the
face, fast enough to measure; over the ``window`` frames after, the block stays
on the ground (no flight: a small bounce only).  Per kept impact: the
angular-velocity ratio ``theta_dot+ / theta_dot-`` (Eq. 20 of the paper, which at
``mu = gamma = 0`` is Housner's ``1 - 1.5 sin^2(alpha)``, predicts +0.25 for a
square) with the pivot and landing corners.

Rates at the impact (:func:`impact_rate`): ``ReadData.m`` fits a line to each
side's positions (7 frames before, 6 after, ``z`` with the free fall ``g t^2/2``
taken out); here a parabola is fitted to ``th`` over ``window`` frames on each
side and its slope taken at frame ``j``.  The parabola leaves the angular
acceleration free: a block pivoting under gravity (Housner: ~120 rad/s^2 for
this square near flat), a sliding pivot or a rebound each decelerate
differently, and a line would read the rate at the window's middle, 8 ms from
the impact (1 rad/s off at 120 rad/s^2).  Frame ``j`` itself is left out: the
contact lasts part of that frame.
"""
from __future__ import annotations

import csv
import math
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.parameters import Scene

__all__ = ["COLUMNS", "FRAME_RATE", "SIDE", "Filter", "Trajectory", "Impact",
           "load_trajectory", "load_folder", "theta_offset", "angle_noise", "corner_positions",
           "square_scene", "housner_ratio", "impact_rate", "find_impacts"]

COLUMNS = ("x", "z", "th", "vx", "vz", "vth")
FRAME_RATE = 250.0  # Hz: ReadData.m's `rate = 1/250`, and the rate columns' step
SIDE = 0.06  # m: the square's side, "s = 0.06m" (DAIRLab README; half-width 0.03 in ReadData.m)
# kg: the block's mass in DAIRLab's IRB_NEW_torque_square.m (rigid ratios do not use it)
MASS = 0.0485
# Body-frame corners, counter-clockwise from the upper right: the corner labels 0-3.
CORNERS = np.array([[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]]) * (0.5 * SIDE)
MIN_FRAMES = 8  # a file shorter than two impact windows cannot hold an impact
MAX_FILE_BYTES = 16 << 20  # the dataset's files are ~25 kB; 16 MB is a mistake
_NAME = re.compile(r"traj_(\d+)\.csv$")


@dataclass(frozen=True)
class Filter:
    """What makes a detected impact rocking-like (see the module docstring).

    Parameters
    ----------
    window : int
        Frames fitted on each side of the impact frame (16 ms at 250 Hz).  4:
        the block's motion between contacts is short (a rebound reverses within
        ~20 ms); a parabola through 4 frames gives a rate noise of 2.5
        sigma/frame, 0.24 rad/s at the measured angle noise sigma = 0.38 mrad
        (:func:`angle_noise`).
    contact_tol : float
        A corner within this height [m] of the ground touches it.  3 mm: the
        lowest corner of the blocks at rest reads -1.1 to +3.3 mm (99 % of the
        frames within -0.1 to +2.7 mm; nominal geometry on the marker frame, the
        offset removed), and 3 mm is 5 % of the side.
    flat_tol : float
        Largest tilt [rad] of the nearest face at the impact frame.  5 deg: one
        frame at 10 rad/s turns 2.3 deg, so the frame nearest the landing is
        within ~1.2 deg of flat; the marker frame's offset spreads by +-0.3 deg.
    min_tilt : float
        Smallest tilt [rad] at the start of the pre-impact window.  3 deg lifts
        the landing corner 3.1 mm, above ``contact_tol``: the block was truly
        on one corner, not jittering on a face.
    min_rate : float
        Smallest ``|theta_dot-|`` [rad/s].  2: the rate noise (0.24 rad/s)
        then moves a ratio by at most 0.12, half Housner's 0.25 (and by 0.04 at
        the median ``|theta_dot-|``, 6 rad/s).
    tilt_ahead : float
        Smallest tilt [rad] one frame before the impact frame: the landing
        corner is still up there (the replays start from that frame).  0.5 deg
        (a 0.5 mm lift): above the spread of the marker frame's offset between
        drops (+-0.3 deg).
    max_residual : float
        Largest RMS residual [rad] of either window's parabola.  1.5e-3, 4 times
        the angle noise (the 4-frame parabola's own residual is ~sigma/2): a
        larger one means another contact inside the window.
    """

    window: int = 4
    contact_tol: float = 3e-3
    flat_tol: float = math.radians(5.0)
    min_tilt: float = math.radians(3.0)
    min_rate: float = 2.0
    tilt_ahead: float = math.radians(0.5)
    max_residual: float = 1.5e-3

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Trajectory:
    """One drop: the file's name and its columns (frames at :data:`FRAME_RATE`)."""

    name: str
    x: np.ndarray
    z: np.ndarray
    th: np.ndarray

    @property
    def t(self) -> np.ndarray:
        return np.arange(len(self.z)) / FRAME_RATE


@dataclass(frozen=True)
class Impact:
    """One rocking-like impact: where, which corners, the rates and their ratio.

    ``frame`` is the impact frame ``j``; ``pivot``/``landing`` the body-frame
    corner labels (0-3, :data:`CORNERS`) pivoted on before and landing at the
    impact; ``phi`` [rad] the face tilt at ``j``; ``rate_before``/``rate_after``
    [rad/s] ``theta_dot`` just before/after; ``ratio`` their quotient (Housner:
    +0.25; negative: the block rebounds onto its pivot); ``slip`` [m/s] the
    pivot's horizontal speed before; ``state`` the replay's start (frame ``j-1``:
    ``x, z, th, vx, vz, omega`` with the pivot on the ground).
    """

    name: str
    frame: int
    pivot: int
    landing: int
    phi: float
    rate_before: float
    rate_after: float
    residual_before: float
    residual_after: float
    slip: float
    state: tuple = field(default=())

    @property
    def ratio(self) -> float:
        return self.rate_after / self.rate_before

    @property
    def outcome(self) -> str:
        """'continues' onto the landing corner (ratio > 0) or 'rebounds' onto the pivot."""
        return "continues" if self.ratio > 0.0 else "rebounds"

    def to_dict(self) -> dict:
        out = asdict(self)
        out.update(ratio=self.ratio, outcome=self.outcome, state=list(self.state))
        return out


def _number(text: str, where: str, column: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: column {column!r} holds {text!r}, not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: column {column!r} holds {text!r}, not a finite number")
    return value


def load_trajectory(path) -> Trajectory:
    """One ``traj_<n>.csv`` file; ``ValueError`` naming the file (and the column)
    when it is not a readable CSV with exactly the header ``x,z,th,vx,vz,vth``,
    at least :data:`MIN_FRAMES` rows of six finite numbers."""
    path = Path(path)
    where = f"impact data file {str(path)!r}"
    if not path.is_file():
        raise ValueError(f"{where} is not a regular file")
    if path.stat().st_size > MAX_FILE_BYTES:
        raise ValueError(f"{where} is over {MAX_FILE_BYTES >> 20} MB: not a trajectory")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{where} is not a UTF-8 text file") from None
    rows = list(csv.reader(text.splitlines()))
    if not rows:
        raise ValueError(f"{where} is empty")
    header = tuple(c.strip() for c in rows[0])
    if header != COLUMNS:
        missing = [c for c in COLUMNS if c not in header]
        detail = f"column {missing[0]!r} is missing" if missing else "the columns are out of order"
        raise ValueError(f"{where}: header must be {','.join(COLUMNS)}, got {','.join(header)} "
                         f"({detail})")
    data = []
    for n, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(COLUMNS):
            raise ValueError(f"{where}, line {n}: {len(row)} values, expected {len(COLUMNS)}")
        data.append([_number(v, f"{where}, line {n}", c) for v, c in zip(row, COLUMNS)])
    if len(data) < MIN_FRAMES:
        raise ValueError(f"{where}: {len(data)} rows, at least {MIN_FRAMES} needed")
    a = np.array(data)
    return Trajectory(path.name, a[:, 0], a[:, 1], a[:, 2])


def load_folder(folder) -> list[Trajectory]:
    """Every ``traj_<n>.csv`` of ``folder`` (sorted by ``n``); ``ValueError`` when
    there is none, or on the first bad file (naming it)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"impact data folder {str(folder)!r} is not a folder")
    paths = sorted((p for p in folder.iterdir() if _NAME.search(p.name)),
                   key=lambda p: int(_NAME.search(p.name).group(1)))
    if not paths:
        raise ValueError(f"impact data folder {str(folder)!r} holds no traj_<n>.csv file")
    return [load_trajectory(p) for p in paths]


def _tilt(th) -> np.ndarray:
    """Signed tilt [rad] of the nearest face from flat, in [-pi/4, pi/4)."""
    return (np.asarray(th) + 0.25 * math.pi) % (0.5 * math.pi) - 0.25 * math.pi


def theta_offset(trajectories, rest_frames: int = 25,
                 rest_span: float = math.radians(0.5)) -> float:
    """The marker frame's orientation offset [rad]: the median tilt of the blocks
    that end at rest (``th`` spanning under ``rest_span`` over the last
    ``rest_frames`` frames, 0.1 s: the angle noise alone spans ~0.1 deg), where a
    face lies flat.  Measured -1.9 deg on
    the dataset; 0 when no drop ends at rest."""
    tilts = [float(np.median(_tilt(tr.th[-rest_frames:]))) for tr in trajectories
             if len(tr.th) >= rest_frames and np.ptp(tr.th[-rest_frames:]) < rest_span]
    return float(np.median(tilts)) if tilts else 0.0


def angle_noise(trajectories, rest_frames: int = 25,
                rest_span: float = math.radians(0.5)) -> float:
    """The angle's measurement noise [rad]: median over the drops that end at
    rest (as :func:`theta_offset`) of ``std(diff(th)) / sqrt(2)`` over their last
    ``rest_frames`` frames (a still block: only noise moves ``th``); NaN if none."""
    sig = [float(np.std(np.diff(tr.th[-rest_frames:])) / math.sqrt(2.0)) for tr in trajectories
           if len(tr.th) >= rest_frames and np.ptp(tr.th[-rest_frames:]) < rest_span]
    return float(np.median(sig)) if sig else math.nan


def corner_positions(x, z, th):
    """Corner positions ``(cx, cz)`` [m], each of shape ``(frames, 4)``."""
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    ox, oz = CORNERS[:, 0], CORNERS[:, 1]
    return (np.asarray(x)[:, None] + c * ox - s * oz, np.asarray(z)[:, None] + s * ox + c * oz)


def square_scene() -> Scene:
    """The block as a project Scene: full width = height = :data:`SIDE`, no lintel,
    no pendulum, uniform inertia."""
    return Scene(b=SIDE, lam=1.0, mu=0.0, gamma=0.0, column_mass=MASS, depth=SIDE,
                 name="mcube_square")


def housner_ratio(scene: Scene | None = None) -> float:
    """``theta_dot+/theta_dot-`` of Eq. 20 at ``mu = gamma = 0`` (Housner 1963,
    ``1 - 1.5 sin^2(alpha)``) by the project's own function: 0.25 for a square."""
    scene = scene or square_scene()
    b, h, mu, gamma, j, _, _ = scene.model_args()
    return eq.restitution_ratio(0.0, 1.0, b, h, mu, gamma, j)


def impact_rate(t, th, t_impact: float):
    """``(rate, residual)``: ``theta_dot`` [rad/s] at ``t_impact`` from a parabola
    fitted to ``th`` over the frames ``t`` (module docstring), and the fit's RMS
    residual [rad].

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1, 5) / 250.0
    >>> rate, resid = impact_rate(t, 0.1 + 3.0 * t - 60.0 * t * t, 0.0)
    >>> round(rate, 9), resid < 1e-12
    (3.0, True)
    """
    dt = np.asarray(t) - t_impact
    coef = np.polyfit(dt, th, 2)
    resid = float(np.sqrt(np.mean((np.polyval(coef, dt) - th) ** 2)))
    return float(coef[1]), resid


def _replay_state(tr: Trajectory, j: int, pivot: int, pre: np.ndarray, offset: float,
                  slip: float) -> tuple:
    """The measured state at frame ``j - 1`` put on the ground: the fitted angle
    and rate there, the pivot corner at ``z = 0`` with the measured slip and no
    vertical speed (it is on the ground), the centre's velocity from the rigid
    body (``v_c = v_pivot + omega x r``, ``r`` from the pivot to the centre)."""
    dtp = (pre - (j - 1)) / FRAME_RATE
    coef = np.polyfit(dtp, tr.th[pre] - offset, 2)
    theta, omega = float(coef[2]), float(coef[1])
    c, s = math.cos(theta), math.sin(theta)
    ox, oz = CORNERS[pivot]
    rx, rz = -(c * ox - s * oz), -(s * ox + c * oz)
    return (float(tr.x[j - 1]), float(rz), theta, float(slip - omega * rz), float(omega * rx),
            omega)


def find_impacts(tr: Trajectory, offset: float = 0.0, flt: Filter = Filter(),
                 rejected: dict | None = None) -> list[Impact]:
    """The rocking-like impacts of one drop (module docstring), oldest first.

    ``offset`` is :func:`theta_offset` (removed from ``th``); ``rejected``, when
    given, counts every detected impact left out, by its first failed test.
    """
    rejected = {} if rejected is None else rejected
    th = tr.th - offset
    cx, cz = corner_positions(tr.x, tr.z, th)
    t = tr.t
    n, w = len(tr.z), flt.window
    found = []

    def reject(why: str) -> None:
        rejected[why] = rejected.get(why, 0) + 1

    for j in range(1, n - 1):
        if not (tr.z[j] < tr.z[j - 1] and tr.z[j] < tr.z[j + 1]):
            continue
        if j - w < 0 or j + w >= n:
            reject("window outside the file")
            continue
        pre, post = np.arange(j - w, j), np.arange(j + 1, j + w + 1)
        phi = float(_tilt(th[j]))
        if abs(phi) > flt.flat_tol:
            reject("no face flat at the impact")
            continue
        pivot = int(np.argmin(cz[pre[0]]))
        if np.max(np.abs(cz[pre, pivot])) > flt.contact_tol:
            reject("no pivot on the ground before")
            continue
        tilt0 = float(_tilt(th[pre[0]]))
        if abs(tilt0) < flt.min_tilt:
            reject("not tilted onto a corner before")
            continue
        before, res_b = impact_rate(t[pre], th[pre], t[j])
        if abs(before) < flt.min_rate:
            reject("too slow to measure")
            continue
        if tilt0 * before > 0.0:
            reject("turning away from the face")
            continue
        if abs(_tilt(th[j - 1])) <= flt.tilt_ahead:
            reject("landed before the last frame ahead")
            continue
        if np.max(np.min(cz[post], axis=1)) > flt.contact_tol:
            reject("flight after (a bounce off the ground)")
            continue
        after, res_a = impact_rate(t[post], th[post], t[j])
        if max(res_b, res_a) > flt.max_residual:
            reject("another contact inside a window")
            continue
        # The landing corner: the pivot's neighbour on the face that lands (the
        # one the rotation brings down, lowest of the two at the impact frame).
        neighbours = [(pivot + 1) % 4, (pivot + 3) % 4]
        landing = min(neighbours, key=lambda k: cz[j, k])
        slip = float(np.polyfit(t[pre], cx[pre, pivot], 1)[0])
        state = _replay_state(tr, j, pivot, pre, offset, slip)
        found.append(Impact(tr.name, j, pivot, landing, phi, before, after, res_b, res_a,
                            slip, state))
    return found
