"""Scene parameters: the trilith, its pendulum absorber and the derived quantities.

One frozen dataclass, :class:`Scene`, describes the geometry and masses that every
backend reads (analytic model, PyBullet, Pymunk).  Notation follows the paper
(Eq. 10): column width ``b``, slenderness ``lam = h/b``, lintel mass ``m3 = mu m1``,
pendulum mass ``m4 = gamma m1``.  ``m1`` is the mass of *one* column; the two
columns are equal.  SI units throughout.

The analytic model depends only on ``b, lam, mu, gamma, l, J_G/m1, g``; the gap,
lintel shape, depth and hinge position are there for the engines (the paper shows,
and ``tests/analytic/test_derivation.py`` re-derives, that the hinge position and the
lintel's centre of mass drop out of the equations).
"""
from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass

__all__ = ["Scene", "DENSITY_STONE", "G_STANDARD", "LENGTH_RANGE", "MASS_RANGE",
           "INERTIA_RATIO_RANGE", "G_RANGE", "GLOSSARY", "glossary_text"]

G_STANDARD = 9.81  # m/s^2, the value the paper's a_up = g/lam plots imply
DENSITY_STONE = 2500.0  # kg/m^3, used only to give the columns a default mass


# Physical ranges (documented in the Scene docstring and docs/model.md): the
# engines are calibrated on metre-sized stone blocks; these bounds keep every
# backend's numbers finite (a 1e-300 m column or a 1e-320 kg mass divides by
# zero or underflows) while covering millimetre models to tens-of-metres ruins.
LENGTH_RANGE = (1e-3, 100.0)  # m: b, h = lam b, l, gap, lintel_height, depth
MASS_RANGE = (1e-6, 1e10)  # kg: one column; contains the stone default at every size
INERTIA_RATIO_RANGE = (0.1, 10.0)  # J_G over the uniform rectangle's m1 (b^2 + h^2)/12
G_RANGE = (0.1, 100.0)  # m/s^2: from small moons to well past Jupiter

# What each scene value means, in the paper's symbols (Eq. 10): the one text the
# README, every command's --help and `trilith scenes` show, so that a reader from
# rocking or friction work does not take mu for a friction coefficient.
GLOSSARY = {
    "lam": "slenderness of a column, lambda = h/b [-]",
    "b": "full width of a column, B [m] (not the half-width)",
    "h": "height of a column, h = lam b [m]",
    "mu": "lintel mass over one column's mass, mu = m3/m1 [-] (a MASS ratio, not friction)",
    "gamma": "pendulum bob mass over one column's mass, gamma = m4/m1 [-]; 0 = no pendulum",
    "l": "pendulum length l, hinge to bob [m]; default 2h/3",
    "gap": "clear distance d between the two columns [m]; default h",
    "lintel_height": "thickness of the lintel [m]; default b/2 (engines only)",
    "alpha": "slenderness angle atan(b/h) [rad]: a block's static overturning angle",
    "column_mass": "mass m1 of one column [kg]; default stone, 2500 kg/m^3 x b h depth",
    "J_G": "polar inertia of one column about its centre of mass [kg m^2]; default uniform",
    "depth": "out-of-plane depth of every body [m] (engines only)",
    "hinge_x": "pendulum hinge position from the lintel's middle [m] (engines only)",
    "g": "gravity [m/s^2]; default 9.81",
}


def glossary_text(indent: str = "") -> str:
    """:data:`GLOSSARY` as text, one ``name  meaning`` line per value, aligned."""
    width = max(map(len, GLOSSARY))
    return "\n".join(f"{indent}{k:<{width}}  {v}" for k, v in GLOSSARY.items())


def _check_finite(name: str, value) -> float:
    """``value`` as a float; ``TypeError`` for non-numbers (str, bool, None),
    ``ValueError`` for NaN/inf, both naming the parameter."""
    # bool is an int subclass (b=True would be stored as 1 m); str would reach numba.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r} "
                        f"({type(value).__name__})")
    try:
        value = float(value)
    except OverflowError:  # an int beyond the float range, e.g. 10**400
        raise ValueError(f"{name} must be finite, got an integer of {len(str(abs(value)))} "
                         f"digits") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


def _check_range(name: str, value, lo: float, hi: float, *,
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

    Every value is checked at construction: ``TypeError`` for a non-number
    (``str``, ``bool``, ``None`` where a number is needed), ``ValueError`` naming
    the parameter and its range otherwise.  The ranges are physical, so that every
    backend gets finite, well-scaled numbers: sizes from a millimetre to 100 m
    (``LENGTH_RANGE``), a column mass in [1e-6, 1e10] kg (``MASS_RANGE``),
    bounded mass and inertia ratios.

    Parameters
    ----------
    b : float
        Column width [m], in [1e-3, 100].  Default 0.6 (the paper's Fig. 5).
    lam : float
        Column slenderness ``h/b`` [-], in [1, 100]; the height ``h = lam b``
        must be in [1e-3, 100] m too.  Default 5.
    mu : float
        Lintel mass over one column's mass, ``m3/m1`` (Eq. 10), in [0, 100].
    gamma : float
        Pendulum mass over one column's mass, ``m4/m1`` (Eq. 10), in [0, 10].
        ``gamma = 0`` means no pendulum at all: no pendulum coordinate in the
        analytic model and no pendulum body in the engines.
    l : float or None
        Pendulum length [m], in [1e-3, 100].  ``None`` gives the paper's ``2h/3``.
    column_mass : float or None
        Mass of one column ``m1`` [kg], in [1e-6, 1e10].  ``None`` gives a stone
        column (2500 kg/m^3) of depth ``depth``, always inside that range
        (2.5e-6 to 2.5e9 kg).  The analytic response does not depend on it.
    J_G : float or None
        Polar inertia of one column about its centre of mass [kg m^2], within
        [0.1, 10] times the uniform rectangle's ``m1 (b^2 + h^2) / 12``, which
        ``None`` gives.
    gap : float or None
        Clear distance ``d`` between the columns [m], in [0, 100].  ``None``
        gives ``h`` (the columns cannot touch each other before lying on the ground).
    lintel_height : float or None
        Lintel thickness [m], in [1e-3, 100] (engines only).  ``None`` gives ``b/2``.
    hinge_x : float
        Horizontal position of the pendulum hinge, measured from the middle of
        the lintel's underside [m] (engines only), on the lintel.  Default 0.
    depth : float
        Out-of-plane depth of every body [m], in [1e-3, 100] (PyBullet only).
        Default 1.
    g : float
        Gravity [m/s^2], in [0.1, 100].  Default 9.81.
    name : str
        A label carried into reports.

    Examples
    --------
    >>> Scene(b=0.6, lam=5.0).h
    3.0
    >>> Scene(b=True)
    Traceback (most recent call last):
    TypeError: b must be a real number, got True (bool)
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
        lo, hi = LENGTH_RANGE
        # Store floats: Scene(b=1) and Scene(b=np.float32(1)) compare and hash alike.
        checked = {
            "b": _check_range("b", self.b, lo, hi, lo_open=False),
            "lam": _check_range("lam", self.lam, 1.0, 100.0, lo_open=False),
            "mu": _check_range("mu", self.mu, 0.0, 100.0, lo_open=False),
            "gamma": _check_range("gamma", self.gamma, 0.0, 10.0, lo_open=False),
            "depth": _check_range("depth", self.depth, lo, hi, lo_open=False),
            "g": _check_range("g", self.g, *G_RANGE, lo_open=False),
            "hinge_x": _check_finite("hinge_x", self.hinge_x),
        }
        for name in ("l", "lintel_height"):
            if getattr(self, name) is not None:
                checked[name] = _check_range(name, getattr(self, name), lo, hi, lo_open=False)
        if self.gap is not None:
            checked["gap"] = _check_range("gap", self.gap, 0.0, hi, lo_open=False)
        if self.column_mass is not None:
            checked["column_mass"] = _check_range("column_mass", self.column_mass,
                                                  *MASS_RANGE, lo_open=False)
        if self.J_G is not None:
            checked["J_G"] = _check_finite("J_G", self.J_G)
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a str, got {self.name!r} ({type(self.name).__name__})")
        for key, value in checked.items():
            object.__setattr__(self, key, value)
        if not (lo <= self.h <= hi):
            raise ValueError(f"h = lam*b must be in [{lo:g}, {hi:g}] m, got {self.h!r} "
                             f"(lam={self.lam:g}, b={self.b:g})")
        if self.J_G is not None:
            uniform = self.m1 * (self.b ** 2 + self.h ** 2) / 12.0
            rlo, rhi = INERTIA_RATIO_RANGE
            if not (rlo * uniform <= self.J_G <= rhi * uniform):
                raise ValueError(f"J_G must be in [{rlo:g}, {rhi:g}] x the uniform column's "
                                 f"m1 (b^2 + h^2)/12 = [{rlo * uniform:.4g}, {rhi * uniform:.4g}] "
                                 f"kg m^2, got {self.J_G!r}")
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
