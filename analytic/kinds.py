"""Scenes the analytic model does not cover: columns of drums, unequal columns,
a block on a block.

Each kind is a frozen dataclass whose construction checks that the geometry can
stand at rest (the rules at the door, ``docs/geometry.md``); its
:meth:`~KindScene.layout` is its bodies as upright rectangles in the analytic
plane (x right, y up, the ground's top face at ``y = 0``), from which
:func:`engines.geometry.structure_of` builds the engines' body list.  Defined
here, beside :class:`~analytic.parameters.Scene`, because every layer reads
scenes (the scene files, the engines, the commands) and this is the bottom one;
nothing in the rocking model reads these kinds.

Masses are stone (:data:`~analytic.parameters.DENSITY_STONE`, 2500 kg/m^3)
times each body's ``b x h x depth`` unless stated; SI units throughout.
Rules checked at construction (one ``ValueError`` naming the field and its range):

* every size in :data:`~analytic.parameters.LENGTH_RANGE` (a zero or negative
  size is refused);
* no two bodies overlap, and every body rests on the ground or on a body whose
  top face it touches (a floating body cannot stand);
* a lintel covers the top faces it rests on (shorter than the span, it does not);
* a drum is at most :data:`MAX_WIDENING` wider than the drum below;
* a block on a block has its centre of mass over the lower block's top face.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

from .parameters import (DENSITY_STONE, G_RANGE, G_STANDARD, LENGTH_RANGE, MASS_RANGE, Scene,
                         _check_finite, _check_range)

__all__ = ["Rect", "KindScene", "Drums", "Unequal", "BlockOnBlock", "KINDS", "MAX_WIDENING",
           "DRUM_COUNT", "kind_of"]

# A drum may be at most 5 % wider than the drum below.  The failure rule takes a
# drum's own overturning angle atan(b/h) (engines.structure_monitor); a drum wider
# than its support pivots about the narrower drum's corner, whose angle
# atan(b_below/h) is smaller by up to the same fraction for slender drums: within
# 5 % the rule's angle errs by at most ~5 %, the spread of cut drums in a built
# column; beyond it the rule would name the wrong angle.
MAX_WIDENING = 0.05
# Drums per column of the 'drums' kind: one drum is the parametric trilith
# (Scene, the model's mechanism); four keep every run within the engines'
# calibrated contact counts (each joint adds two corner contacts per column).
DRUM_COUNT = (2, 4)
# Two faces touch (or two bodies overlap) when they are closer than this many
# metres: far below any size allowed (1 mm) and far above rounding (~1e-15 m).
_TOUCH = 1e-9


class Rect(NamedTuple):
    """An upright body of a layout: ``name``, width ``b`` and height ``h`` [m],
    centre ``x, y`` [m], ``mass`` [kg]."""

    name: str
    b: float
    h: float
    x: float
    y: float
    mass: float

    @property
    def left(self) -> float:
        return self.x - 0.5 * self.b

    @property
    def right(self) -> float:
        return self.x + 0.5 * self.b

    @property
    def bottom(self) -> float:
        return self.y - 0.5 * self.h

    @property
    def top(self) -> float:
        return self.y + 0.5 * self.h


def _length(name: str, value) -> float:
    return _check_range(name, value, *LENGTH_RANGE, lo_open=False)


@dataclass(frozen=True)
class KindScene:
    """What every kind shares: ``depth`` [m] (out of plane), ``g`` [m/s^2],
    ``name``; subclasses set ``kind`` and :meth:`_rects`."""

    kind: ClassVar[str]
    depth: float = 1.0
    g: float = G_STANDARD
    name: str = "custom"

    def _check_common(self) -> dict:
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a str, got {self.name!r}")
        return {"depth": _length("depth", self.depth),
                "g": _check_range("g", self.g, *G_RANGE, lo_open=False)}

    def _store(self, checked: dict) -> None:
        for key, value in checked.items():
            object.__setattr__(self, key, value)

    def _rects(self) -> list[Rect]:
        raise NotImplementedError

    def layout(self) -> tuple[Rect, ...]:
        """The bodies upright at rest, bottom-up, left column first."""
        return tuple(self._rects())

    def hinge(self):
        """``(parent, anchor in the parent's frame [m], mass [kg], length [m])`` of
        the pendulum, or None."""
        return None

    def supports(self) -> tuple[tuple[str, str], ...]:
        """``(upper, lower)`` pairs: each body on the ground (``'ground'``) or on
        the bodies whose top face its bottom face touches, with a common width."""
        rects = self.layout()
        out = []
        for r in rects:
            if abs(r.bottom) <= _TOUCH:
                out.append((r.name, "ground"))
            for q in rects:
                if (q is not r and abs(r.bottom - q.top) <= _TOUCH
                        and min(r.right, q.right) - max(r.left, q.left) > _TOUCH):
                    out.append((r.name, q.name))
        return tuple(out)

    def _check_stands(self) -> None:
        """Overlapping bodies and floating ones are refused (the field named is
        the kind's)."""
        rects = self.layout()
        for i, r in enumerate(rects):
            for q in rects[i + 1:]:
                if (min(r.right, q.right) - max(r.left, q.left) > _TOUCH
                        and min(r.top, q.top) - max(r.bottom, q.bottom) > _TOUCH):
                    raise ValueError(f"{self._overlap_field()}: bodies {r.name} and {q.name} "
                                     f"overlap; bodies may touch but not overlap")
        held = {upper for upper, _ in self.supports()}
        for r in rects:
            if r.name not in held:
                raise ValueError(f"{self._overlap_field()}: body {r.name} rests on nothing "
                                 f"(it cannot stand)")

    def _overlap_field(self) -> str:
        return "gap"

    @property
    def alpha(self) -> float:
        """The smallest overturning angle ``atan(b/h)`` of its bodies [rad]."""
        return min(math.atan2(r.b, r.h) for r in self.layout())

    @property
    def has_pendulum(self) -> bool:
        return self.hinge() is not None

    def without_pendulum(self):
        """This scene without its pendulum (itself if it has none)."""
        return self.replace(gamma=0.0) if self.has_pendulum else self

    def replace(self, **changes):
        """A copy with ``changes`` applied (validated again)."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    def to_dict(self) -> dict:
        out = {"kind": self.kind, **dataclasses.asdict(self)}
        out["bodies"] = [r._asdict() for r in self.layout()]
        return out


@dataclass(frozen=True)
class Drums(KindScene):
    """Two equal columns of 2-4 drums under a lintel (an optional pendulum).

    The parametric trilith's fields, with the column cut into drums: ``heights``
    [m] bottom to top (the column's height is their sum ``H``), ``widths`` [m]
    (None: every drum ``b``; given: bottom to top, the bottom one is ``b``, each
    at most :data:`MAX_WIDENING` wider than the one below; tapering allowed).
    Drums stand centred on their column's axis.  ``mu``, ``gamma`` are the lintel
    and bob masses over one column's mass (its drums' sum), ``l`` defaults to
    ``2H/3``, ``gap`` to ``H``, ``lintel_height`` to ``b/2``; the lintel is
    ``2b + gap`` long, as the trilith's (:class:`~analytic.parameters.Scene`).
    ``column_mass`` [kg], if given, is shared among the drums by volume.
    """

    kind: ClassVar[str] = "drums"
    heights: tuple[float, ...] = (1.5, 1.5)
    widths: tuple[float, ...] | None = None
    b: float = 0.6
    mu: float = 1.0
    gamma: float = 0.0
    l: float | None = None
    column_mass: float | None = None
    gap: float | None = None
    lintel_height: float | None = None
    hinge_x: float = 0.0

    def __post_init__(self) -> None:
        checked = self._check_common()
        heights = tuple(self.heights) if isinstance(self.heights, (list, tuple)) else None
        lo, hi = DRUM_COUNT
        if heights is None or not lo <= len(heights) <= hi:
            got = len(heights) if heights is not None else repr(self.heights)
            raise ValueError(f"heights: a column of drums has {lo} to {hi} drums (one drum is "
                             f"the parametric trilith: heights = [h] or h), got {got}")
        checked["heights"] = tuple(_length(f"heights[{i}]", h) for i, h in enumerate(heights))
        b = _length("b", self.b)
        if self.widths is not None:
            widths = tuple(self.widths) if isinstance(self.widths, (list, tuple)) else ()
            if len(widths) != len(heights):
                raise ValueError(f"widths: one width per drum ({len(heights)}), got "
                                 f"{self.widths!r}")
            widths = tuple(_length(f"widths[{i}]", w) for i, w in enumerate(widths))
            if widths[0] != b:
                raise ValueError(f"widths[0] is the bottom drum's width b = {b:g} m, got "
                                 f"{widths[0]!r}")
            for i in range(1, len(widths)):
                most = widths[i - 1] * (1.0 + MAX_WIDENING)
                if widths[i] > most:
                    raise ValueError(f"widths[{i}] must be at most {most:.6g} m "
                                     f"({MAX_WIDENING:.0%} wider than the drum below, "
                                     f"{widths[i - 1]:g} m), got {widths[i]!r}")
            checked["widths"] = widths
        checked["b"] = b
        self._store(checked)
        # The trilith's lengths and masses, checked by Scene (its messages name the field).
        try:
            base = self.base
        except ValueError as exc:
            raise ValueError(f"{exc} (for the column of drums: h = sum(heights) = "
                             f"{sum(heights):g} m, lam = h/b)") from None
        if self.column_mass is not None:
            _check_range("column_mass", self.column_mass, *MASS_RANGE, lo_open=False)
        _check_finite("hinge_x", self.hinge_x)
        self._store({k: getattr(base, k) for k in ("mu", "gamma", "hinge_x")})
        top = self.drum_widths[-1]
        if self.mu > 0.0 and top > b:  # the lintel spans 2b + gap: it must cover the top faces
            raise ValueError(f"widths[{len(heights) - 1}]: the top drum ({top:g} m) is wider "
                             f"than b = {b:g} m, so the lintel (2b + gap) is shorter than the "
                             f"span of the top faces; the top drum must be at most b")
        self._check_stands()

    @property
    def base(self) -> Scene:
        """The parametric trilith of the same outline (the monolithic columns'
        scene): its lintel, gap, pendulum length and checks."""
        h = sum(self.heights)
        return Scene(b=self.b, lam=h / self.b, mu=self.mu, gamma=self.gamma, l=self.l,
                     gap=self.gap, lintel_height=self.lintel_height, hinge_x=self.hinge_x,
                     depth=self.depth, g=self.g, name=self.name)

    @property
    def drum_widths(self) -> tuple[float, ...]:
        return self.widths if self.widths is not None else (self.b,) * len(self.heights)

    def _column_mass(self) -> float:
        volume = sum(w * h for w, h in zip(self.drum_widths, self.heights)) * self.depth
        return self.column_mass if self.column_mass is not None else DENSITY_STONE * volume

    def _rects(self) -> list[Rect]:
        base, b = self.base, self.b
        area = sum(w * h for w, h in zip(self.drum_widths, self.heights))
        m_col = self._column_mass()
        out = []
        for side, x_left in (("left", 0.0), ("right", b + base.d)):
            y = 0.0
            for i, (w, h) in enumerate(zip(self.drum_widths, self.heights)):
                out.append(Rect(f"column_{side}_{i}", w, h, x_left + 0.5 * b, y + 0.5 * h,
                                m_col * w * h / area))
                y += h
        if self.mu > 0.0:
            t = base.lintel_thickness
            out.append(Rect("lintel", base.lintel_length, t, 0.5 * base.lintel_length,
                            sum(self.heights) + 0.5 * t, self.mu * m_col))
        return out

    def hinge(self):
        if self.gamma == 0.0:
            return None
        base = self.base
        return ("lintel", (self.hinge_x, -0.5 * base.lintel_thickness),
                self.gamma * self._column_mass(), base.pendulum_length)


@dataclass(frozen=True)
class Unequal(KindScene):
    """Two columns of different widths under a level lintel.

    ``left_b``, ``right_b`` [m] the widths, ``left_h``, ``right_h`` [m] the
    heights, which must be equal: the lintel rests level on both (an inclined
    lintel is refused: it would rest on one corner of the lower column and slide
    or roll off under gravity alone, no longer a frame at rest).  ``gap`` [m]
    the clear distance (default ``h``); ``lintel_length`` [m] at least the span
    ``left_b + gap + right_b`` (default: the span), centred on it;
    ``lintel_height`` [m] (default a quarter of the widths' sum); ``mu`` the
    lintel's mass over the mean column mass.  No pendulum.
    """

    kind: ClassVar[str] = "unequal"
    left_b: float = 0.6
    left_h: float = 3.0
    right_b: float = 0.8
    right_h: float = 3.0
    gap: float | None = None
    lintel_length: float | None = None
    lintel_height: float | None = None
    mu: float = 1.0

    def __post_init__(self) -> None:
        checked = self._check_common()
        for key in ("left_b", "left_h", "right_b", "right_h"):
            checked[key] = _length(key, getattr(self, key))
        if checked["right_h"] != checked["left_h"]:
            raise ValueError(f"right_h must equal left_h = {checked['left_h']:g} m (the lintel "
                             f"rests level; an inclined lintel is refused), got {self.right_h!r}")
        gap = checked["left_h"] if self.gap is None else _check_range(
            "gap", self.gap, 0.0, LENGTH_RANGE[1], lo_open=False)
        span = checked["left_b"] + gap + checked["right_b"]
        if self.lintel_length is not None:
            length = _length("lintel_length", self.lintel_length)
            if length < span:
                raise ValueError(f"lintel_length must be at least the span left_b + gap + "
                                 f"right_b = {span:g} m (it rests on both top faces), got "
                                 f"{self.lintel_length!r}")
            checked["lintel_length"] = length
        if self.lintel_height is not None:
            checked["lintel_height"] = _length("lintel_height", self.lintel_height)
        checked["mu"] = _check_range("mu", self.mu, 0.0, 100.0)
        self._store(checked)
        self._check_stands()

    def _rects(self) -> list[Rect]:
        bl, br, h = self.left_b, self.right_b, self.left_h
        d = h if self.gap is None else self.gap
        span = bl + d + br
        length = span if self.lintel_length is None else self.lintel_length
        t = self.lintel_height if self.lintel_height is not None else 0.25 * (bl + br)
        ml, mr = (DENSITY_STONE * w * h * self.depth for w in (bl, br))
        return [Rect("column_left", bl, h, 0.5 * bl, 0.5 * h, ml),
                Rect("column_right", br, h, bl + d + 0.5 * br, 0.5 * h, mr),
                Rect("lintel", length, t, 0.5 * span, h + 0.5 * t, self.mu * 0.5 * (ml + mr))]


@dataclass(frozen=True)
class BlockOnBlock(KindScene):
    """A block resting on another block on the ground.

    ``lower_b``, ``lower_h``, ``upper_b``, ``upper_h`` [m]; ``offset`` [m] the
    upper block's centre minus the lower's, along x, in ``(-lower_b/2,
    lower_b/2)``: the upper block's centre of mass must be over the lower block's
    top face, else it cannot stand.
    """

    kind: ClassVar[str] = "block_on_block"
    lower_b: float = 0.8
    lower_h: float = 2.0
    upper_b: float = 0.5
    upper_h: float = 1.5
    offset: float = 0.0

    def __post_init__(self) -> None:
        checked = self._check_common()
        for key in ("lower_b", "lower_h", "upper_b", "upper_h"):
            checked[key] = _length(key, getattr(self, key))
        half = 0.5 * checked["lower_b"]
        offset = _check_finite("offset", self.offset)
        if not abs(offset) < half:
            raise ValueError(f"offset must be in (-{half:g}, {half:g}) m (the upper block's "
                             f"centre of mass over the lower block's top face), got "
                             f"{self.offset!r}")
        checked["offset"] = offset
        self._store(checked)
        self._check_stands()

    def _overlap_field(self) -> str:
        return "offset"

    def _rects(self) -> list[Rect]:
        bl, hl, bu, hu = self.lower_b, self.lower_h, self.upper_b, self.upper_h
        rho = DENSITY_STONE * self.depth
        return [Rect("lower", bl, hl, 0.5 * bl, 0.5 * hl, rho * bl * hl),
                Rect("upper", bu, hu, 0.5 * bl + self.offset, hl + 0.5 * hu, rho * bu * hu)]


KINDS = {cls.kind: cls for cls in (Drums, Unequal, BlockOnBlock)}


def kind_of(scene) -> str:
    """``'trilith'`` or ``'block'`` for a parametric Scene (``mu > 0`` or not),
    else the kind's name."""
    if isinstance(scene, Scene):
        return "trilith" if scene.mu > 0.0 else "block"
    return scene.kind
