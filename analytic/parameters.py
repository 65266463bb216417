"""Scene parameters: the trilith, its pendulum absorber and the derived quantities.

One frozen dataclass, :class:`Scene`, describes the geometry and masses that every
backend reads (analytic model, PyBullet, Pymunk).  Notation follows the paper
(Eq. 10): column width ``b``, slenderness ``lam = h/b``, lintel mass ``m3 = mu m1``,
pendulum mass ``m4 = gamma m1``.  ``m1`` is the mass of *one* column; the two
columns are equal.  SI units throughout.

The analytic model depends only on ``b, lam, mu, gamma, l, J_G/m1, g``; the gap,
lintel shape, depth and hinge position are there for the engines (the paper shows,
and ``tests/test_derivation.py`` re-derives, that the hinge position and the
lintel's centre of mass drop out of the equations).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

__all__ = ["Scene", "DENSITY_STONE", "G_STANDARD"]

G_STANDARD = 9.81  # m/s^2, the value the paper's a_up = g/lam plots imply
DENSITY_STONE = 2500.0  # kg/m^3, used only to give the columns a default mass


def _check_finite(name: str, value: float) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


def _check_range(name: str, value: float, lo: float, hi: float, *,
                 lo_open: bool = True, hi_open: bool = False) -> float:
    value = _check_finite(name, value)
    ok_lo = value > lo if lo_open else value >= lo
    ok_hi = value < hi if hi_open else value <= hi
    if not (ok_lo and ok_hi):
        left = "(" if lo_open else "["
        right = ")" if hi_open else "]"
        hi_txt = "inf" if math.isinf(hi) else f"{hi:g}"
        raise ValueError(f"{name} must be in {left}{lo:g}, {hi_txt}{right}, got {value!r}")
    return value


@dataclass(frozen=True)
class Scene:
    """A trilith (two equal rigid columns and a translating lintel) with a pendulum.

    Parameters
    ----------
    b : float
        Column width [m], > 0.  Default 0.6 (the paper's Fig. 5).
    lam : float
        Column slenderness ``h/b`` [-], in [1, 100].  Default 5.
    mu : float
        Lintel mass over one column's mass, ``m3/m1`` (Eq. 10), in [0, 100].
    gamma : float
        Pendulum mass over one column's mass, ``m4/m1`` (Eq. 10), in [0, 10].
        ``gamma = 0`` means no pendulum at all: no pendulum coordinate in the
        analytic model and no pendulum body in the engines.
    l : float or None
        Pendulum length [m], > 0.  ``None`` gives the paper's ``2h/3``.
    column_mass : float or None
        Mass of one column ``m1`` [kg], > 0.  ``None`` gives a stone column of
        unit depth.  The analytic response does not depend on it (only ratios do).
    J_G : float or None
        Polar inertia of one column about its centre of mass [kg m^2], > 0.
        ``None`` gives the uniform rectangle ``m1 (b^2 + h^2) / 12``.
    gap : float or None
        Clear distance ``d`` between the columns [m], >= 0.  ``None`` gives ``h``
        (the columns cannot touch each other before lying on the ground).
    lintel_height : float or None
        Lintel thickness [m], > 0 (engines only).  ``None`` gives ``b/2``.
    hinge_x : float
        Horizontal position of the pendulum hinge, measured from the middle of
        the lintel's underside [m] (engines only).  Default 0.
    depth : float
        Out-of-plane depth of every body [m], > 0 (PyBullet only).  Default 1.
    g : float
        Gravity [m/s^2], > 0.  Default 9.81.
    name : str
        A label carried into reports.
    """

    b: float = 0.6
    lam: float = 5.0
    mu: float = 1.0
    gamma: float = 0.3
    l: float | None = None
    column_mass: float | None = None
    J_G: float | None = None
    gap: float | None = None
    lintel_height: float | None = None
    hinge_x: float = 0.0
    depth: float = 1.0
    g: float = G_STANDARD
    name: str = "custom"

    def __post_init__(self) -> None:
        _check_range("b", self.b, 0.0, 1e3)
        _check_range("lam", self.lam, 1.0, 100.0, lo_open=False)
        _check_range("mu", self.mu, 0.0, 100.0, lo_open=False)
        _check_range("gamma", self.gamma, 0.0, 10.0, lo_open=False)
        _check_range("depth", self.depth, 0.0, 1e3)
        _check_range("g", self.g, 0.0, 1e3)
        _check_finite("hinge_x", self.hinge_x)
        for name in ("l", "column_mass", "J_G", "lintel_height"):
            value = getattr(self, name)
            if value is not None:
                _check_range(name, value, 0.0, math.inf)
        if self.gap is not None:
            _check_range("gap", self.gap, 0.0, math.inf, lo_open=False)
        half_span = 0.5 * self.lintel_length
        if abs(self.hinge_x) > half_span:
            raise ValueError(f"hinge_x must be in [-{half_span:g}, {half_span:g}] "
                             f"(on the lintel), got {self.hinge_x!r}")

    # --- geometry -------------------------------------------------------------
    @property
    def h(self) -> float:
        """Column height [m]."""
        return self.lam * self.b

    @property
    def alpha(self) -> float:
        """Slenderness angle ``atan(b/h)`` [rad]: the static overturning angle."""
        return math.atan2(self.b, self.h)

    @property
    def R(self) -> float:
        """Half diagonal of a column, ``sqrt(b^2 + h^2)/2`` [m]."""
        return 0.5 * math.hypot(self.b, self.h)

    @property
    def pendulum_length(self) -> float:
        """Pendulum length ``l`` [m]; ``2h/3`` unless given."""
        return self.l if self.l is not None else 2.0 * self.h / 3.0

    @property
    def d(self) -> float:
        """Clear gap between the columns [m]; ``h`` unless given."""
        return self.gap if self.gap is not None else self.h

    @property
    def lintel_length(self) -> float:
        """Lintel length: it spans both columns exactly, ``2b + d`` [m]."""
        return 2.0 * self.b + self.d

    @property
    def lintel_thickness(self) -> float:
        return self.lintel_height if self.lintel_height is not None else 0.5 * self.b

    @property
    def has_pendulum(self) -> bool:
        return self.gamma > 0.0

    # --- masses ---------------------------------------------------------------
    @property
    def m1(self) -> float:
        """Mass of one column [kg]."""
        if self.column_mass is not None:
            return self.column_mass
        return DENSITY_STONE * self.b * self.h * self.depth

    @property
    def m3(self) -> float:
        """Lintel mass [kg] (Eq. 10)."""
        return self.mu * self.m1

    @property
    def m4(self) -> float:
        """Pendulum mass [kg] (Eq. 10)."""
        return self.gamma * self.m1

    @property
    def j(self) -> float:
        """``J_G / m1`` [m^2]: a column's polar inertia per unit column mass."""
        if self.J_G is not None:
            return self.J_G / self.m1
        return (self.b ** 2 + self.h ** 2) / 12.0

    @property
    def inertia_J_G(self) -> float:
        return self.j * self.m1

    def model_args(self) -> tuple[float, float, float, float, float, float, float]:
        """``(b, h, mu, gamma, j, l, g)``: the only numbers the analytic model uses."""
        return (self.b, self.h, self.mu, self.gamma, self.j, self.pendulum_length, self.g)

    def replace(self, **changes) -> "Scene":
        """A copy with ``changes`` applied (validated again)."""
        return dataclasses.replace(self, **changes)

    def without_pendulum(self) -> "Scene":
        return self.replace(gamma=0.0)

    def to_dict(self) -> dict:
        out = dataclasses.asdict(self)
        out.update(h=self.h, alpha=self.alpha, l_effective=self.pendulum_length,
                   m1=self.m1, gap_effective=self.d)
        return out

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))
