"""``analytic.equations`` and the paper's printed equations against an independent
sympy derivation (``tests/derivation.py``).

Numerical comparisons use random states from a fixed seed (deterministic).  Their
tolerance is ``1e-10`` relative to the size of the terms being summed: both sides
are double-precision evaluations of the same exact quantity arranged differently,
so they can differ by a few ulps times the cancellation in the sums (~1e-14), while
any wrong term, sign or factor changes the result at order 1e-3 or more.
Symbolic comparisons are exact (``simplify(difference) == 0``).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from analytic import equations as eq

try:  # tests/ on sys.path (pytest's default rootdir-less import) or as a package
    import derivation as D
except ImportError:  # pragma: no cover
    from tests import derivation as D

RTOL = 1e-10  # see module docstring: rounding of differently arranged sums
N_STATES = 200
SIDES = (1, -1)
b, h, l, g, mu, gamma, j = D.b, D.h, D.l, D.g, D.mu, D.gamma, D.j
th, thd, thdd, ps, psd, psdd, xgdd = D.th, D.thd, D.thdd, D.ps, D.psd, D.psdd, D.xgdd
M = 1 + mu + gamma


def random_cases(seed: int, n: int = N_STATES, gamma_zero: bool = False):
    """Random parameters and states covering squat to slender columns, light to
    heavy lintels and pendulums, non-uniform columns (``j`` off the rectangle)."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        bb = rng.uniform(0.2, 1.0)
        hh = bb * rng.uniform(1.5, 10.0)
        yield dict(
            b=bb, h=hh, mu=rng.uniform(0.0, 3.0),
            gamma=0.0 if gamma_zero else rng.uniform(0.05, 1.0),
            j=(bb * bb + hh * hh) / 12.0 * rng.uniform(0.5, 1.5),
            l=hh * rng.uniform(0.2, 1.0), g=9.81, theta=rng.uniform(0.0, 0.5),
            theta_dot=rng.uniform(-3.0, 3.0), psi=rng.uniform(-1.5, 1.5),
            psi_dot=rng.uniform(-5.0, 5.0), xg_ddot=rng.uniform(-20.0, 20.0))


def close(a: float, ref: float, scale: float) -> bool:
    return abs(a - ref) <= RTOL * max(abs(ref), scale)


def is_zero(expr) -> bool:
    return sp.simplify(sp.expand_trig(sp.expand(expr))) == 0


# ------------------------------------------------------------------ positions
def test_positions_reproduce_printed_eq5():
    """Eq. 5 is the rotation about A of Eq. 3 (printed correctly)."""
    t_th, t_ps, t_xg = sp.symbols("T P X", real=True)
    pos = D.positions(1, t_th, t_ps, t_xg)
    c, s = sp.cos(t_th), sp.sin(t_th)
    printed = [
        (t_xg + b / 2 * c - h / 2 * s, b / 2 * s + h / 2 * c),
        (t_xg + b + D.d + b / 2 * c - h / 2 * s, b / 2 * s + h / 2 * c),
        (t_xg + D.b3 + b * c - h * s, D.h3 + b * s + h * c),
        (t_xg + D.bo + b * c - h * s + l * sp.sin(t_ps), D.ho + b * s + h * c - l * sp.cos(t_ps)),
    ]
    # Eq. 5's (b3, h3) and (b_o, h_o) are r_FG3 and r_Fo of Eq. 2-3: offsets from the
    # top-right corner F, exactly the derivation's lintel-fixed points.
    for r, p in zip(pos, printed):
        diff = r - sp.Matrix(p)
        assert all(is_zero(x) for x in diff), diff


# ------------------------------------------------------------------ rocking (Eq. 8, A.1)
@pytest.mark.parametrize("side", SIDES)
def test_hinge_lintel_and_gap_drop_out(side):
    """The paper's invariance claim (after Eq. 20): b3, h3, b_o, h_o, d never appear."""
    eqs = D.lagrange(side)
    q, a_up, _ = D.uplift(side)
    for expr in (*eqs, q, a_up):
        assert not expr.free_symbols & set(D.GEOMETRY_FREE)


def corrected_eq8(side: int):
    """The corrected Eq. 8 / A.1 as written in ``rocking_accelerations``'s docstring."""
    sb = side * b
    k = sb * sp.sin(th - ps) + h * sp.cos(th - ps)
    kc = sb * sp.cos(th - ps) - h * sp.sin(th - ps)
    inertia = ((b ** 2 + h ** 2) * (1 + 2 * (mu + gamma)) + 4 * j) / 2
    e1 = (inertia * thdd - gamma * l * k * psdd + gamma * l * kc * psd ** 2
          + g * M * (sb * sp.cos(th) - h * sp.sin(th)) - M * xgdd * (h * sp.cos(th) + sb * sp.sin(th)))
    e2 = -k * thdd + l * psdd - kc * thd ** 2 + g * sp.sin(ps) + xgdd * sp.cos(ps)
    return e1, e2


@pytest.mark.parametrize("side", SIDES)
def test_lagrange_equals_documented_corrected_eq8(side):
    e_th, e_ps = D.lagrange(side)
    e1, e2 = corrected_eq8(side)
    assert is_zero(e_th - e1)
    assert is_zero(e_ps - gamma * l * e2)  # Eq. 8b is m4 l times the documented form


def printed_eq8():
    """Eq. 8 exactly as printed (per m1: m3 = mu, m4 = gamma, J_G = j)."""
    s, c = sp.sin(th - ps), sp.cos(th - ps)
    e1 = (g * M * (b * sp.cos(th) + h * sp.sin(th)) + l * gamma * psd ** 2 * (b * c + h * s)
          - M * xgdd * (h * sp.cos(th) + b * sp.sin(th))
          + thdd * ((b ** 2 + h ** 2) * (1 + 2 * (mu + gamma)) + 4 * j) / 2
          - l * gamma * psdd * (b * s + h * c))
    e2 = (-l * gamma * thdd * (b * s + h * c) + l * gamma * thd ** 2 * (-b * c + h * s)
          + l * gamma * (g * sp.sin(ps) + l * psdd + sp.cos(ps) * xgdd))
    return e1, e2


def printed_a1():
    """Eq. A.1 exactly as printed."""
    s, c = sp.sin(th - ps), sp.cos(th - ps)
    e1 = (-g * M * (b * sp.cos(th) + h * sp.sin(th)) - l * gamma * psd ** 2 * (b * c + h * s)
          - M * xgdd * (h * sp.cos(th) - b * sp.sin(th))
          + thdd * ((b ** 2 + h ** 2) * (1 + 2 * (mu + gamma)) + 4 * j) / 2
          + l * gamma * psdd * (b * s - h * c))
    e2 = (l * gamma * thdd * (b * s - h * c) + l * gamma * thd ** 2 * (b * c + h * s)
          + l * gamma * (g * sp.sin(ps) + l * psdd + sp.cos(ps) * xgdd))
    return e1, e2


def test_printed_eq8_has_two_sign_typos_in_first_equation():
    """Printed minus derived is exactly the two ``+h sin`` terms (should be ``-h sin``)."""
    e_th, e_ps = D.lagrange(1)
    p1, p2 = printed_eq8()
    typo = 2 * g * M * h * sp.sin(th) + 2 * l * gamma * psd ** 2 * h * sp.sin(th - ps)
    assert is_zero(p1 - e_th - typo)
    assert is_zero(p2 - e_ps)


def test_printed_a1_is_correct():
    e_th, e_ps = D.lagrange(-1)
    p1, p2 = printed_a1()
    assert is_zero(p1 - e_th)
    assert is_zero(p2 - e_ps)


@pytest.mark.parametrize("side", SIDES)
def test_rocking_accelerations_match_derivation(side):
    mass, rhs = D.mass_matrix_rhs(side)
    args = (b, h, mu, gamma, j, l, g, th, thd, ps, psd, xgdd)
    f_mass = sp.lambdify(args, mass, "numpy")
    f_rhs = sp.lambdify(args, rhs, "numpy")
    for cs in random_cases(seed=10 + side):
        theta = side * cs["theta"]
        vals = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"], cs["g"], theta,
                cs["theta_dot"], cs["psi"], cs["psi_dot"], cs["xg_ddot"])
        ref = np.linalg.solve(np.array(f_mass(*vals), float), np.array(f_rhs(*vals), float).ravel())
        got = eq.rocking_accelerations(theta, cs["theta_dot"], cs["psi"], cs["psi_dot"],
                                       cs["xg_ddot"], side, cs["b"], cs["h"], cs["mu"],
                                       cs["gamma"], cs["j"], cs["l"], cs["g"])
        # Scale: the largest acceleration a term of Eq. 8 can produce here.
        scale = (cs["g"] + abs(cs["xg_ddot"]) + cs["l"] * cs["psi_dot"] ** 2
                 + cs["h"] * cs["theta_dot"] ** 2) / cs["l"]
        assert close(got[0], ref[0], scale) and close(got[1], ref[1], scale), (cs, got, ref)


@pytest.mark.parametrize("side", SIDES)
def test_rocking_without_pendulum_matches_derivation(side):
    """gamma = 0: only the theta equation exists; the code returns psi_ddot = 0."""
    e_th = D.lagrange(side)[0].subs(gamma, 0)
    solved = sp.lambdify((b, h, mu, j, g, th, xgdd), sp.solve(e_th, thdd)[0], "numpy")
    for cs in random_cases(seed=20 + side, n=50, gamma_zero=True):
        theta = side * cs["theta"]
        ref = solved(cs["b"], cs["h"], cs["mu"], cs["j"], cs["g"], theta, cs["xg_ddot"])
        got = eq.rocking_accelerations(theta, cs["theta_dot"], cs["psi"], cs["psi_dot"],
                                       cs["xg_ddot"], side, cs["b"], cs["h"], cs["mu"], 0.0,
                                       cs["j"], cs["l"], cs["g"])
        assert got[1] == 0.0
        assert close(got[0], ref, (cs["g"] + abs(cs["xg_ddot"])) / cs["h"])


# ------------------------------------------------------------------ full contact (Eq. 1)
def test_rest_pendulum_is_eq1():
    """Eq. 8b with the trilith held still (theta = 0 at all times) is the printed Eq. 1."""
    e_ps = D.lagrange(1)[1].subs({th: 0, thd: 0, thdd: 0})
    printed = gamma * g * l * sp.sin(ps) + gamma * l ** 2 * psdd + gamma * xgdd * l * sp.cos(ps)
    assert is_zero(e_ps - printed)
    solved = sp.lambdify((ps, xgdd, l, g), sp.solve(e_ps, psdd)[0], "math")
    for cs in random_cases(seed=3, n=50):
        ref = solved(cs["psi"], cs["xg_ddot"], cs["l"], cs["g"])
        got = eq.rest_pendulum_acceleration(cs["psi"], cs["xg_ddot"], cs["l"], cs["g"])
        assert close(got, ref, (cs["g"] + abs(cs["xg_ddot"])) / cs["l"])


# ------------------------------------------------------------------ uplift (Eq. 9, 11)
@pytest.mark.parametrize("side", SIDES)
def test_uplift_margin_and_acceleration_match_multiplier(side):
    q, a_up, free = D.uplift(side)
    args = (b, h, mu, gamma, j, l, g, ps, psd, xgdd)
    f_q, f_free = (sp.lambdify(args, e, "math") for e in (q, free))
    f_a = sp.lambdify(args[:-1], a_up, "math")
    for cs in random_cases(seed=30 + side):
        vals = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"], cs["g"], cs["psi"],
                cs["psi_dot"])
        common = (side, cs["b"], cs["h"], cs["mu"], cs["gamma"])
        margin = eq.uplift_margin(cs["psi"], cs["psi_dot"], cs["xg_ddot"], *common, cs["l"], cs["g"])
        scale = cs["h"] * (cs["g"] + abs(cs["xg_ddot"]) + cs["l"] * cs["psi_dot"] ** 2) * (1 + cs["mu"] + cs["gamma"])
        assert close(margin, side * f_q(*vals, cs["xg_ddot"]), scale)
        # The margin has the sign of -side*theta_ddot of the free mechanism (Schur complement).
        schur = 0.5 * ((cs["b"] ** 2 + cs["h"] ** 2) * (1 + 2 * cs["mu"] + 2 * cs["gamma"]) + 4 * cs["j"])
        schur -= cs["gamma"] * (cs["h"] * math.cos(cs["psi"]) - side * cs["b"] * math.sin(cs["psi"])) ** 2
        assert close(margin, -side * schur * f_free(*vals, cs["xg_ddot"]), scale)
        got = eq.uplift_acceleration(cs["psi"], cs["psi_dot"], *common, cs["l"], cs["g"])
        assert close(got, f_a(*vals), scale / cs["h"])


def test_uplift_closed_forms():
    """gamma = 0: Eq. 11 ``g/lam``; pendulum hanging still: ``g M / (lam (1 + mu))``."""
    for side in SIDES:
        a_up = D.uplift(side)[1]
        assert is_zero(a_up.subs(gamma, 0) - side * g * b / h)
        assert is_zero(a_up.subs({ps: 0, psd: 0}) - side * g * M * b / (h * (1 + mu)))
    for cs in random_cases(seed=4, n=20):
        lam = cs["h"] / cs["b"]
        for side in SIDES:
            got0 = eq.uplift_acceleration(0.3, 1.0, side, cs["b"], cs["h"], cs["mu"], 0.0, cs["l"], cs["g"])
            assert close(got0, side * cs["g"] / lam, cs["g"])
            got = eq.uplift_acceleration(0.0, 0.0, side, cs["b"], cs["h"], cs["mu"], cs["gamma"],
                                         cs["l"], cs["g"])
            ref = side * cs["g"] * (1 + cs["mu"] + cs["gamma"]) / (lam * (1 + cs["mu"]))
            assert close(got, ref, cs["g"])


def test_printed_eq9_differs_only_in_psi_dot_term():
    """Eq. 9 is right except ``(lam sin psi - cos psi)``, which must be
    ``-(cos psi + lam sin psi)`` (it inherits Eq. 8's ``+h sin(theta-psi)``)."""
    lam = h / b
    den = -lam * (gamma + 2 * mu + 2) + gamma * lam * sp.cos(2 * ps) - gamma * sp.sin(2 * ps)
    rest = -g * (gamma * lam * sp.sin(2 * ps) + gamma * sp.cos(2 * ps) + gamma + 2 * mu + 2)
    printed = (2 * gamma * l * psd ** 2 * (lam * sp.sin(ps) - sp.cos(ps)) + rest) / den
    fixed = (-2 * gamma * l * psd ** 2 * (sp.cos(ps) + lam * sp.sin(ps)) + rest) / den
    a_up = D.uplift(1)[1]
    assert is_zero(a_up - fixed)
    assert is_zero((a_up - printed).subs(psd, 0))
    assert not is_zero(a_up - printed)
