"""``analytic.equations`` and the paper's printed equations against an independent
sympy derivation (``tests/support/derivation.py``).

Numerical comparisons use random states from a fixed seed (deterministic).  Their
tolerance is ``1e-10`` relative to the size of the terms being summed: both sides
are double-precision evaluations of the same exact quantity arranged differently,
so they can differ by a few ulps times the cancellation in the sums (~1e-14), while
any wrong term, sign or factor changes the result at order 1e-3 or more.
Symbolic comparisons are exact (:func:`is_zero`).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from trilith_xval.analytic import equations as eq

from tests.support import derivation as D

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
    """``|a - ref| <= RTOL * max(|ref|, scale)``; ``scale``: the size of the terms summed."""
    return abs(a - ref) <= RTOL * max(abs(ref), scale)


def is_zero(expr) -> bool:
    """Exact test that a rational trigonometric expression in theta, psi vanishes:
    the numerator is expanded into sines and cosines of theta and psi and reduced
    modulo ``sin^2 + cos^2 - 1`` (faster and surer than ``simplify``)."""
    s1, c1, s2, c2 = sp.symbols("s1_ c1_ s2_ c2_")
    num = sp.fraction(sp.together(expr))[0]
    num = sp.expand(sp.expand_trig(sp.expand(num)))
    num = num.subs({sp.sin(th): s1, sp.cos(th): c1, sp.sin(ps): s2, sp.cos(ps): c2})
    rem = sp.reduced(num, [s1 ** 2 + c1 ** 2 - 1, s2 ** 2 + c2 ** 2 - 1], s1, s2, c1, c2)[1]
    return rem == 0


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


@pytest.mark.parametrize("side", SIDES)
def test_lagrange_equals_documented_corrected_eq8(side):
    e_th, e_ps = D.lagrange(side)
    e1, e2 = D.corrected_eq8(side)
    assert is_zero(e_th - e1)
    assert is_zero(e_ps - gamma * l * e2)  # Eq. 8b is m4 l times the documented form


def test_printed_eq8_has_two_sign_typos_in_first_equation():
    """Printed minus derived is exactly the two ``+h sin`` terms (should be ``-h sin``)."""
    e_th, e_ps = D.lagrange(1)
    p1, p2 = D.printed_eq8()
    typo = 2 * g * M * h * sp.sin(th) + 2 * l * gamma * psd ** 2 * h * sp.sin(th - ps)
    assert is_zero(p1 - e_th - typo)
    assert is_zero(p2 - e_ps)


def test_printed_a1_is_correct():
    e_th, e_ps = D.lagrange(-1)
    p1, p2 = D.printed_a1()
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
    mass = D.mass_matrix_rhs(side)[0].subs(th, 0)
    f_schur = sp.lambdify(args[:-1], mass[0, 0] - mass[0, 1] ** 2 / mass[1, 1], "math")
    for cs in random_cases(seed=30 + side):
        vals = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"], cs["g"], cs["psi"],
                cs["psi_dot"])
        common = (side, cs["b"], cs["h"], cs["mu"], cs["gamma"])
        margin = eq.uplift_margin(cs["psi"], cs["psi_dot"], cs["xg_ddot"], *common, cs["l"], cs["g"])
        scale = (cs["h"] * (1 + cs["mu"] + cs["gamma"])
                 * (cs["g"] + abs(cs["xg_ddot"]) + cs["l"] * cs["psi_dot"] ** 2))
        assert close(margin, side * f_q(*vals, cs["xg_ddot"]), scale)
        # The margin has the sign of -side*theta_ddot of the free mechanism (Schur complement).
        schur = f_schur(*vals)
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


# ------------------------------------------------------------------ impact (Eq. 13-21)
def impact_cases(seed: int, n: int = 60):
    """Random cases plus the geometry the paper says does not matter."""
    rng = np.random.default_rng(seed + 1000)
    for k, cs in enumerate(random_cases(seed, n)):
        if k % 4 == 0:  # squat columns, heavy pendulum: the impact can stop the trilith
            cs["h"] = cs["b"] * rng.uniform(1.0, 1.3)
            cs["j"] = (cs["b"] ** 2 + cs["h"] ** 2) / 12.0
            cs["gamma"] = rng.uniform(0.4, 1.0)
            cs["mu"] = rng.uniform(0.0, 0.3)
            cs["psi"] = rng.uniform(-0.5, 0.5)
            cs["l"] = cs["h"] * rng.uniform(0.2, 1.0)
        geo = (rng.uniform(0.0, 2.0) * cs["h"], *rng.uniform(-1.0, 1.0, 4) * cs["b"],
               rng.uniform(0.0, 2.0) * cs["b"] ** 2)  # d, b3, h3, b_o, h_o, j3
        yield cs, geo


@pytest.mark.parametrize("new_side", SIDES)
def test_impact_velocities_match_impulse_momentum(new_side):
    full = D.impact_numeric(new_side)
    stop = D.impact_numeric(new_side, True)
    n_stop = 0
    for cs, geo in impact_cases(seed=40 + new_side):
        w_m = new_side * abs(cs["theta_dot"])       # rocking continues in the same sense
        par = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"])
        sol = full(*par, *geo, cs["psi"], w_m, cs["psi_dot"])
        scale = abs(w_m) + abs(cs["psi_dot"])
        # A regular 20x20 double solve leaves a residual of a few ulps of its entries
        # (lengths^2 times speeds): 1e-12 (1 + h)^3 is ~1000 times that, and a
        # singular (inconsistent) system would leave an O(1) residual.
        assert sol["residual"] < 1e-12 * (1 + cs["h"]) ** 3
        # The lintel does not rotate and both columns turn together: not imposed, found.
        assert close(sol["w2"], sol["w1"], scale) and abs(sol["w3"]) <= RTOL * scale
        # Same answer with the irrelevant geometry removed.
        bare = full(*par, *([0.0] * 6), cs["psi"], w_m, cs["psi_dot"])
        assert close(bare["w1"], sol["w1"], scale) and close(bare["psi_dot_plus"], sol["psi_dot_plus"], scale)
        if sol["w1"] / w_m <= 0.0:                   # it would need the ground to pull: it stops
            n_stop += 1
            sol = stop(*par, *geo, cs["psi"], w_m, cs["psi_dot"])
            assert abs(sol["w1"]) <= RTOL * scale
        got = eq.impact_velocities(w_m, cs["psi"], cs["psi_dot"], new_side, *par)
        assert close(got[0], sol["w1"], scale), (cs, got, sol)
        # psi_dot+ carries (h/l) theta_dot terms: the rounding scale grows with h/l.
        assert close(got[1], sol["psi_dot_plus"], scale * (1 + cs["h"] / cs["l"])), (cs, got, sol)
        ratio = eq.restitution_ratio(cs["psi"], new_side, *par[:5])
        assert close(ratio * w_m, got[0], scale)
    assert 0 < n_stop < N_STATES  # both branches were exercised (seeded: deterministic)


def test_impact_closed_form_eq19_21():
    """Exact solve (right -> left, Fig. 3): the corrected Eq. 19 and the printed
    Eq. 21 hold; the printed Eq. 19 lacks the factor 2 on ``m4 (b cos + h sin)^2``."""
    ratio, psi_p = D.impact_closed_form(1)
    doc_ratio, doc_psi = D.corrected_eq19_21()
    assert is_zero(ratio - doc_ratio)
    assert is_zero(psi_p - doc_psi)
    c = b * sp.cos(ps) + h * sp.sin(ps)
    num19 = -4 * j + gamma * (b ** 2 + h ** 2) * sp.cos(2 * ps) + (b ** 2 - h ** 2) * (1 + 2 * mu + gamma)
    den19 = 4 * j + gamma * c ** 2 + (b ** 2 + h ** 2) * (1 + 2 * mu)
    assert not is_zero(ratio + num19 / den19)
    assert is_zero(ratio + num19 / (den19 + gamma * c ** 2))
    w_m, p_m = D.W_MINUS, D.PSI_DOT_MINUS
    eq21 = p_m - 2 * b * (h * (1 + 2 * (mu + gamma)) * c + 4 * j * sp.sin(ps)) / (
        l * ((b ** 2 + h ** 2) * (1 + 2 * mu) + 2 * gamma * c ** 2 + 4 * j)) * w_m
    assert is_zero(psi_p - eq21)
    # Eq. 20 (m_p -> m1, m_t -> m3): the gamma = 0 limit.
    eq20 = -(-4 * j + (b ** 2 - h ** 2) * (1 + 2 * mu)) / (4 * j + (b ** 2 + h ** 2) * (1 + 2 * mu))
    assert is_zero(ratio.subs(gamma, 0) - eq20)


def test_restitution_makris_vassiliou_and_housner():
    """gamma = 0, uniform columns: Makris & Vassiliou's rocking frame
    ``(1 - 3/2 sin^2 a + 3 g cos 2a) / (1 + 3 g)``, ``g = m_beam / (2 m_column) = mu/2``;
    Housner's ``1 - 3/2 sin^2 a`` when also mu = 0."""
    ratio = D.impact_closed_form(1)[0].subs(gamma, 0)
    radius, alpha = sp.symbols("R alpha", positive=True)
    sub = {b: 2 * radius * sp.sin(alpha), h: 2 * radius * sp.cos(alpha)}
    uniform = ratio.subs(j, (b ** 2 + h ** 2) / 12).subs(sub)
    mv = (1 - sp.Rational(3, 2) * sp.sin(alpha) ** 2 + 3 * mu / 2 * sp.cos(2 * alpha)) / (1 + 3 * mu / 2)
    # is_zero's exact reduction (alpha in theta's place) instead of simplify, whose
    # factorisation picks random points: the same answer every run.
    assert is_zero((uniform - mv).subs(alpha, th))
    assert is_zero((uniform.subs(mu, 0) - (1 - sp.Rational(3, 2) * sp.sin(alpha) ** 2)
                    ).subs(alpha, th))
    assert not is_zero((uniform - mv.subs(mu, 2 * mu)).subs(alpha, th))  # and it can fail
    for cs in random_cases(seed=5, n=20):
        a = math.atan2(cs["b"], cs["h"])
        jj = (cs["b"] ** 2 + cs["h"] ** 2) / 12.0
        for side in SIDES:
            got = eq.restitution_ratio(0.7, side, cs["b"], cs["h"], cs["mu"], 0.0, jj)
            g_mv = cs["mu"] / 2.0
            ref = (1 - 1.5 * math.sin(a) ** 2 + 3 * g_mv * math.cos(2 * a)) / (1 + 3 * g_mv)
            assert close(got, max(ref, 0.0), 1.0)
            housner = eq.restitution_ratio(0.7, side, cs["b"], cs["h"], 0.0, 0.0, jj)
            assert close(housner, 1 - 1.5 * math.sin(a) ** 2, 1.0)


def test_printed_impulse_balances_eq13_to_18():
    """Eqs. 13-18 hold for the derived impulses once read with Fig. 3's convention
    (impulses drawn as exerted on the ground, i.e. minus those on the columns), with
    Eq. 17's OCR ``+ -`` -> ``-`` and trailing ``1`` -> ``l``.  Eq. 15/16's
    ``(m1 h^2/4 - J_G)`` is right: ``+ J_G`` would violate the balance."""
    solve = D.impact_numeric(1)
    for cs, geo in impact_cases(seed=6, n=40):
        bb, hh, mm, gg, jj, ll = (cs[k] for k in ("b", "h", "mu", "gamma", "j", "l"))
        dd, b3, h3, b0, h0, _ = geo
        psi, w_m, p_m = cs["psi"], abs(cs["theta_dot"]), cs["psi_dot"]
        sol = solve(bb, hh, mm, gg, jj, ll, *geo, psi, w_m, p_m)
        w_p, p_p = sol["w1"], sol["psi_dot_plus"]
        ax, ay = -sol["ground_1bl_x"], -sol["ground_1bl_y"]  # Fig. 3 convention
        cx, cy = -sol["ground_2bl_x"], -sol["ground_2bl_y"]
        big = 1 + mm + gg
        sp_, cp_ = math.sin(psi), math.cos(psi)
        scale = big * (hh + dd + abs(b3) + abs(h3) + abs(b0) + abs(h0) + ll) ** 2 * (w_m + abs(p_m))
        col = (hh ** 2 / 4 - jj) * (w_p - w_m) + bb ** 2 / 4 * (w_m + w_p)
        residuals = [
            ax + cx + (hh * big * (w_m - w_p) + gg * ll * cp_ * (p_p - p_m)),           # Eq. 13
            ay + cy + (bb * big * (w_m + w_p) + gg * ll * sp_ * (p_p - p_m)),           # Eq. 14
            -ay * bb + ax * hh - col,                                                    # Eq. 15
            -cy * bb + cx * hh - col,                                                    # Eq. 16
            cy * (bb + dd) - (-bb * (w_m + w_p) * (gg * (bb + b0 + ll * sp_) + (bb + dd / 2)
                                                    + mm * (bb + b3))
                              + (w_m - w_p) * (2 * jj + hh ** 2 / 2 + hh * gg * (hh + h0 - ll * cp_)
                                               + hh * (hh + h3) * mm)
                              - ll * gg * (p_p - p_m) * ((bb + b0) * sp_ - (hh + h0) * cp_ + ll)),  # Eq. 17
            gg * (ll ** 2 * (p_p - p_m) + bb * ll * sp_ * (w_p + w_m) + hh * ll * cp_ * (w_m - w_p)),  # Eq. 18
        ]
        for k, res in enumerate(residuals):
            assert abs(res) <= RTOL * scale, (13 + k, res, cs)
        plus_j = -ay * bb + ax * hh - (col + 2 * jj * (w_p - w_m))
        # The "+ J_G" reading misses by 2 J_G (w+ - w-): far beyond the tolerance met above.
        assert abs(plus_j) > 100 * RTOL * scale


# ------------------------------------------------------------------ energy
@pytest.mark.parametrize("side", SIDES)
def test_energy_is_derived_t_plus_v(side):
    e_sym = D.energy(side)
    # Lagrangian identity dE/dt = sum(q_dot * E_q) (xg fixed): checks the derivation itself.
    e_th, e_ps = D.lagrange(side)
    rate = (e_sym.diff(th) * thd + e_sym.diff(thd) * thdd + e_sym.diff(ps) * psd
            + e_sym.diff(psd) * psdd)
    assert is_zero(rate - (thd * e_th + psd * e_ps).subs(xgdd, 0))
    f_e = sp.lambdify((b, h, mu, gamma, j, l, g, th, thd, ps, psd), e_sym, "math")
    for cs in random_cases(seed=50 + side, n=100):
        vals = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"], cs["g"],
                side * cs["theta"], cs["theta_dot"], cs["psi"], cs["psi_dot"])
        got = eq.energy(vals[7], vals[8], vals[9], vals[10], side, *vals[:7])
        scale = (1 + cs["mu"] + cs["gamma"]) * (cs["g"] * cs["h"] + (cs["h"] * cs["theta_dot"]) ** 2
                                                + (cs["l"] * cs["psi_dot"]) ** 2)
        assert close(got, f_e(*vals), scale)


@pytest.mark.parametrize("new_side", SIDES)
def test_impact_never_creates_energy(new_side):
    """A perfectly plastic impact dissipates (independent physical check on the map)."""
    for cs in random_cases(seed=60 + new_side, n=100):
        par = (cs["b"], cs["h"], cs["mu"], cs["gamma"], cs["j"], cs["l"])
        w_m = new_side * abs(cs["theta_dot"])
        w_p, p_p = eq.impact_velocities(w_m, cs["psi"], cs["psi_dot"], new_side, *par)
        before = eq.energy(0.0, w_m, cs["psi"], cs["psi_dot"], -new_side, *par, cs["g"])
        after = eq.energy(0.0, w_p, cs["psi"], p_p, new_side, *par, cs["g"])
        scale = (1 + cs["mu"] + cs["gamma"]) * ((cs["h"] * w_m) ** 2 + (cs["l"] * cs["psi_dot"]) ** 2)
        assert after <= before + RTOL * scale
