"""Independent sympy derivation of the trilith-pendulum model (helper for the tests).

Nothing here is copied from the paper's printed equations or from
``analytic/equations.py``: the model is rebuilt from the geometry alone.

* Positions: every material point of a column is moved by a rigid rotation about
  the active pivot (the paper's Eq. 2-4); the lintel translates with the column
  top corner it rides on; the pendulum mass hangs at ``l (sin psi, -cos psi)``
  from a hinge fixed to the lintel.  Lintel centre ``(b3, h3)``, hinge
  ``(b_o, h_o)`` (both measured from the top-right corner F of the left column at
  rest, as in Eq. 5) and the gap ``d`` stay symbolic.
* Rocking (Eq. 6-8, A.1): Lagrange's equations from ``T`` and ``V``.
* Uplift (Eq. 9, 11): a Lagrange multiplier holding ``theta = 0``.
* Impact (Eq. 13-21): full planar impulse-momentum balance of the four bodies
  (each with its own velocities), unknown impulses at the new ground corners, at
  the new lintel/column contacts and along the pendulum rod, one linear solve.

Masses are written per unit column mass (``m1 = 1``): ``m3 = mu``, ``m4 = gamma``,
``J_G = j``, the same normalisation as ``analytic.equations``.  ``side = +1`` is
rocking about the left base corners, ``-1`` about the right ones.
Results are cached: each derivation runs once per test session.
"""
from __future__ import annotations

import functools

import sympy as sp
from sympy.polys.matrices import DomainMatrix

t = sp.Symbol("t", real=True)
b, h, l, g = sp.symbols("b h l g", positive=True)
d = sp.Symbol("d", nonnegative=True)
b3, h3, bo, ho = sp.symbols("b_3 h_3 b_o h_o", real=True)
mu, gamma, j, j3 = sp.symbols("mu gamma j j_3", nonnegative=True)
th, thd, thdd, ps, psd, psdd, xgd, xgdd = sp.symbols(
    "theta theta_dot theta_ddot psi psi_dot psi_ddot xg_dot xg_ddot", real=True)
# Symbols that the paper claims drop out of every equation (hinge, lintel centre, gap).
GEOMETRY_FREE = (b3, h3, bo, ho, d, j3)

_TH = sp.Function("theta", real=True)(t)
_PS = sp.Function("psi", real=True)(t)
_XG = sp.Function("x_g", real=True)(t)


def rot(angle) -> sp.Matrix:
    """Planar rotation (the paper's Eq. 4, restricted to the plane)."""
    return sp.Matrix([[sp.cos(angle), -sp.sin(angle)], [sp.sin(angle), sp.cos(angle)]])


def corners(column: int) -> dict[str, sp.Matrix]:
    """Reference corners of a column: bottom-left, bottom-right, top-left, top-right.

    Column 1 has its bottom-left corner A at the origin; column 2 is shifted by
    ``b + d`` (its corners are C, D, K, H in the paper's Fig. 2-3).
    """
    x0 = 0 if column == 1 else b + d
    return {"bl": sp.Matrix([x0, 0]), "br": sp.Matrix([x0 + b, 0]),
            "tl": sp.Matrix([x0, h]), "tr": sp.Matrix([x0 + b, h])}


def pivot_and_rider(column: int, side: int) -> tuple[sp.Matrix, sp.Matrix]:
    """Pivot (base corner) and the top corner that carries the lintel.

    Rocking about the left corners (``side=+1``, theta > 0 CCW) raises the
    top-right corners, so the lintel rides on them; about the right corners
    (theta < 0) the top-left corners are the higher ones.
    """
    c = corners(column)
    return (c["bl"], c["tr"]) if side == 1 else (c["br"], c["tl"])


# Lintel-fixed points at rest (measured from F = top-right corner of column 1).
G3_REF = sp.Matrix([b + b3, h + h3])
HINGE_REF = sp.Matrix([b + bo, h + ho])
G_COL_REF = {1: sp.Matrix([b / 2, h / 2]), 2: sp.Matrix([b + d + b / 2, h / 2])}


def positions(side: int, theta=_TH, psi=_PS, xg=_XG) -> list[sp.Matrix]:
    """Centres of mass ``[G1, G2, G3, G4]`` while rocking about ``side`` (Eq. 3, 5)."""
    shift = sp.Matrix([xg, 0])
    out = []
    for col in (1, 2):
        pivot, _ = pivot_and_rider(col, side)
        out.append(shift + pivot + rot(theta) * (G_COL_REF[col] - pivot))
    pivot, rider = pivot_and_rider(1, side)
    lintel_move = shift + pivot + rot(theta) * (rider - pivot) - rider  # translation only
    out.append(G3_REF + lintel_move)
    out.append(HINGE_REF + lintel_move + l * sp.Matrix([sp.sin(psi), -sp.cos(psi)]))
    return out


MASSES = (1, 1, mu, gamma)


def _to_symbols(expr):
    """Replace theta(t), psi(t), x_g(t) and their derivatives by plain symbols."""
    reps = {sp.Derivative(_TH, (t, 2)): thdd, sp.Derivative(_PS, (t, 2)): psdd,
            sp.Derivative(_XG, (t, 2)): xgdd, sp.Derivative(_TH, t): thd,
            sp.Derivative(_PS, t): psd, sp.Derivative(_XG, t): xgd}
    return expr.subs(reps).subs({_TH: th, _PS: ps})


def kinetic_potential(side: int):
    """``(T, V)`` per ``m1`` as functions of time (Eq. 6 and 7).

    ``T`` has the four translational terms and both columns' rotational
    inertia ``J_G`` (the lintel does not rotate, the pendulum is a point mass);
    ``V = g * sum(m_i y_i)``.
    """
    pos = positions(side)
    kin = sum(m * r.diff(t).dot(r.diff(t)) for m, r in zip(MASSES, pos)) / 2
    kin += 2 * j * _TH.diff(t) ** 2 / 2
    pot = g * sum(m * r[1] for m, r in zip(MASSES, pos))
    return kin, pot


@functools.lru_cache(maxsize=None)
def lagrange(side: int) -> tuple[sp.Expr, sp.Expr]:
    """Lagrange's equations ``(E_theta, E_psi)`` per ``m1``, ``E = 0`` (Eq. 8 / A.1)."""
    kin, pot = kinetic_potential(side)
    lag = kin - pot
    eqs = []
    for q in (_TH, _PS):
        qd = q.diff(t)
        eqs.append(sp.expand(_to_symbols(lag.diff(qd).diff(t) - lag.diff(q))))
    return eqs[0], eqs[1]


@functools.lru_cache(maxsize=None)
def mass_matrix_rhs(side: int) -> tuple[sp.Matrix, sp.Matrix]:
    """``M [theta_ddot, psi_ddot]^T = f`` from :func:`lagrange` (linear in accelerations)."""
    eqs = sp.Matrix(lagrange(side))
    mass = eqs.jacobian([thdd, psdd])
    rhs = -eqs.subs({thdd: 0, psdd: 0})
    return mass.applyfunc(sp.expand), rhs.applyfunc(sp.expand)


@functools.lru_cache(maxsize=None)
def energy(side: int) -> sp.Expr:
    """``T + V`` per ``m1`` in the base frame (``xg_dot = 0``), datum at rest with
    the pendulum hanging (``theta = psi = 0``)."""
    kin, pot = kinetic_potential(side)
    e = _to_symbols(kin + pot).subs(xgd, 0)
    return sp.expand(e - e.subs({th: 0, ps: 0, thd: 0, psd: 0}))


@functools.lru_cache(maxsize=None)
def uplift(side: int) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """``(Q, a_up, theta_ddot_free)`` at ``theta = theta_dot = 0``.

    ``Q`` is the Lagrange multiplier (generalised force along ``theta`` of the
    mechanism about ``side``, per ``m1``) that keeps ``theta = 0`` while the
    pendulum moves freely: ``M11*0 + M12 psi_ddot = f1 + Q``, ``M22 psi_ddot = f2``
    (which is Eq. 1).  The ground can supply it only with ``side*Q >= 0``
    (it pushes at the opposite corners), so uplift starts at ``Q = 0``; ``a_up``
    solves ``Q = 0`` for ``xg_ddot``.  ``theta_ddot_free`` is the acceleration of
    the unconstrained mechanism at the same state.
    """
    mass, rhs = mass_matrix_rhs(side)
    at_rest = {th: 0, thd: 0}
    m0 = mass.subs(at_rest)
    f0 = rhs.subs(at_rest)
    psi_dd = f0[1] / m0[1, 1]
    q = sp.expand(sp.cancel(m0[0, 1] * psi_dd - f0[0]))   # linear in xg_ddot
    a_up = sp.cancel(-q.subs(xgdd, 0) / q.coeff(xgdd))
    free = sp.cancel(m0.LUsolve(f0)[0])
    return q, a_up, free


# ---------------------------------------------------------------- impact (Eq. 13-21)
def _cross(r: sp.Matrix, v: sp.Matrix) -> sp.Expr:
    return r[0] * v[1] - r[1] * v[0]


def _spin(omega, r: sp.Matrix) -> sp.Matrix:
    """Velocity ``omega z x r``."""
    return sp.Matrix([-omega * r[1], omega * r[0]])


def _linear_solve(eqs: list, unknowns: list) -> dict:
    """Exact solve of a square linear system over the field of rational functions.

    ``sin(psi)`` and ``cos(psi)`` become plain symbols so that the polys domain
    solver (no expression swell) can be used; they are put back afterwards.
    """
    sn, cs = sp.symbols("s_psi c_psi", real=True)
    trig = {sp.sin(ps): sn, sp.cos(ps): cs}
    sys_a, sys_b = sp.linear_eq_to_matrix([sp.expand(e).subs(trig) for e in eqs], unknowns)
    assert sys_a.shape[0] == sys_a.shape[1], "impact system must be square"
    n = sys_a.shape[1]
    aug = DomainMatrix.from_Matrix(sys_a.row_join(sys_b)).to_field()
    x = aug[:, :n].lu_solve(aug[:, n:]).to_Matrix()
    back = {sn: sp.sin(ps), cs: sp.cos(ps)}
    return {u: x[i].subs(back) for i, u in enumerate(unknowns)}


W_MINUS, PSI_DOT_MINUS = sp.symbols("w_minus psi_dot_minus", real=True)
IMPACT_PARAMS = (b, h, mu, gamma, j, l, d, b3, h3, bo, ho, j3, ps, W_MINUS, PSI_DOT_MINUS)


@functools.lru_cache(maxsize=None)
def impact_system(new_side: int, stop: bool = False) -> dict:
    """Impulse-momentum equations of an impact at ``theta = 0`` (Eq. 13-18, rebuilt).

    Before: rocking about ``-new_side`` with ``theta_dot = w_m`` (lintel on the
    old top corners).  After: every body has its own unknown planar velocity;
    perfectly plastic sticking contact at the new ground corners and at the new
    top corners (the old ones release, no impulse), an inextensible rod carrying
    impulse along itself only.  With ``stop=True`` all four base corners and
    both top corners of each column hold (the trilith comes to rest).
    Returns the linear system ``A x = rhs`` in the unknowns (body velocities,
    rod tension impulse, contact impulses) and the expressions of the outputs
    (``w1, w2, w3``: body spins; ``psi_dot``; ground impulses) in the unknowns.
    """
    w_m, p_m = W_MINUS, PSI_DOT_MINUS
    tang = sp.Matrix([sp.cos(ps), sp.sin(ps)])          # pendulum velocity direction
    rod = sp.Matrix([sp.sin(ps), -sp.cos(ps)])          # hinge -> mass
    masses = {1: 1, 2: 1, 3: mu}
    inert = {1: j, 2: j, 3: j3}
    cog = {1: G_COL_REF[1], 2: G_COL_REF[2], 3: G3_REF}
    # Pre-impact velocities (old mechanism).
    pre = {}
    for col in (1, 2):
        pivot, _ = pivot_and_rider(col, -new_side)
        pre[col] = (_spin(w_m, cog[col] - pivot), w_m)
    pivot, rider = pivot_and_rider(1, -new_side)
    pre[3] = (_spin(w_m, rider - pivot), 0)
    v4_pre = pre[3][0] + l * p_m * tang
    # Unknowns.
    vel = {k: sp.Matrix(sp.symbols(f"u{k} v{k}", real=True)) for k in (1, 2, 3, 4)}
    w = {k: sp.Symbol(f"w{k}", real=True) for k in (1, 2, 3)}
    grounds = ("bl", "br") if stop else (("bl",) if new_side == 1 else ("br",))
    tops = ("tl", "tr") if stop else (("tr",) if new_side == 1 else ("tl",))
    imp_g = {(c, k): sp.Matrix(sp.symbols(f"I_{k}{c}x I_{k}{c}y", real=True))
             for c in (1, 2) for k in grounds}
    imp_t = {(c, k): sp.Matrix(sp.symbols(f"J_{k}{c}x J_{k}{c}y", real=True))
             for c in (1, 2) for k in tops}              # on the lintel, from column c
    tension = sp.Symbol("N", real=True)                  # on the mass, towards the hinge
    eqs = []
    for col in (1, 2):
        cor = corners(col)
        lin = sum((imp_g[(col, k)] for k in grounds), sp.zeros(2, 1)) - sum(
            (imp_t[(col, k)] for k in tops), sp.zeros(2, 1))
        ang = sum(_cross(cor[k] - cog[col], imp_g[(col, k)]) for k in grounds) - sum(
            _cross(cor[k] - cog[col], imp_t[(col, k)]) for k in tops)
        eqs += list(masses[col] * (vel[col] - pre[col][0]) - lin)
        eqs.append(inert[col] * (w[col] - pre[col][1]) - ang)
        for k in grounds:                                # new base corners stick
            eqs += list(vel[col] + _spin(w[col], cor[k] - cog[col]))
        for k in tops:                                   # column and lintel move together
            eqs += list(vel[col] + _spin(w[col], cor[k] - cog[col])
                        - vel[3] - _spin(w[3], cor[k] - G3_REF))
    lin3 = sum(imp_t.values(), sp.zeros(2, 1)) + tension * rod
    ang3 = sum(_cross(corners(c)[k] - G3_REF, imp_t[(c, k)]) for c in (1, 2) for k in tops)
    ang3 += _cross(HINGE_REF - G3_REF, tension * rod)
    eqs += list(mu * (vel[3] - pre[3][0]) - lin3)
    eqs.append(j3 * w[3] - ang3)
    eqs += list(gamma * (vel[4] - v4_pre) + tension * rod)
    eqs.append((vel[4] - vel[3] - _spin(w[3], HINGE_REF - G3_REF)).dot(rod))  # inextensible
    unknowns = [*vel[1], w[1], *vel[2], w[2], *vel[3], w[3], *vel[4], tension]
    unknowns += [s for v in (*imp_g.values(), *imp_t.values()) for s in v]
    hinge_vel = vel[3] + _spin(w[3], HINGE_REF - G3_REF)
    outputs = {"w1": w[1], "w2": w[2], "w3": w[3],
               "psi_dot_plus": (vel[4] - hinge_vel).dot(tang) / l}
    for (c, k), vec in imp_g.items():
        outputs[f"ground_{c}{k}_x"], outputs[f"ground_{c}{k}_y"] = vec[0], vec[1]
    sys_a, sys_b = sp.linear_eq_to_matrix([sp.expand(e) for e in eqs], unknowns)
    return {"A": sys_a, "rhs": sys_b, "unknowns": unknowns, "outputs": outputs}


@functools.lru_cache(maxsize=None)
def impact_numeric(new_side: int, stop: bool = False):
    """A function ``f(*IMPACT_PARAMS) -> dict`` solving :func:`impact_system` in floats.

    Without ``stop`` the system is square and regular (``numpy.linalg.solve``);
    with ``stop`` the redundant supports make the impulse split indeterminate, so
    a least-squares solve is used and its residual is returned (velocities are
    still unique: they are fixed by the kinematic constraints).
    """
    import numpy as np

    system = impact_system(new_side, stop)
    fa = sp.lambdify(IMPACT_PARAMS, system["A"], "numpy")
    fb = sp.lambdify(IMPACT_PARAMS, system["rhs"], "numpy")
    pick = {name: sp.lambdify([*system["unknowns"], *IMPACT_PARAMS], expr, "numpy")
            for name, expr in system["outputs"].items()}

    def solve(*values: float) -> dict:
        mat = np.array(fa(*values), dtype=float)
        vec = np.array(fb(*values), dtype=float).reshape(-1)
        if stop:
            x = np.linalg.lstsq(mat, vec, rcond=None)[0]
        else:
            x = np.linalg.solve(mat, vec)
        out = {name: float(f(*x, *values)) for name, f in pick.items()}
        out["residual"] = float(np.max(np.abs(mat @ x - vec)))
        return out

    return solve


@functools.lru_cache(maxsize=None)
def impact_closed_form(new_side: int) -> tuple[sp.Expr, sp.Expr]:
    """``(theta_dot+ / theta_dot-, psi_dot+)`` in closed form (exact linear solve).

    The symbols that provably do not matter (``d, b3, h3, b_o, h_o, j3``: the
    numerical tests vary them) are set to 0 here to keep the exact solve fast.
    """
    system = impact_system(new_side)
    zero = dict.fromkeys(GEOMETRY_FREE, 0)
    eqs = list(system["A"].subs(zero) * sp.Matrix(system["unknowns"]) - system["rhs"].subs(zero))
    sol = _linear_solve(eqs, system["unknowns"])
    w1 = system["outputs"]["w1"].subs(sol)
    psi_plus = system["outputs"]["psi_dot_plus"].subs(zero).subs(sol)
    # cancel (a gcd) rather than factor: sympy's multivariate factorisation picks
    # random evaluation points and now and then lifts for minutes (seen: 16 min).
    return sp.cancel(w1 / W_MINUS), sp.cancel(psi_plus)


# ----------------------------------------------- forms to compare with (not derived)
# The paper's printed equations (OCR text, per m1: m3 = mu, m4 = gamma, J_G = j) and
# the corrected forms documented in ``analytic/equations.py``; used only as the
# other side of a comparison with the derivation above.
M = 1 + mu + gamma


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


def corrected_eq19_21():
    """``(ratio, psi_dot+)`` for new_side = +1 as documented in ``impact_velocities``."""
    c = b * sp.cos(ps) + h * sp.sin(ps)
    dd = b * sp.cos(ps) - h * sp.sin(ps)
    ratio = -(-4 * j + (b ** 2 - h ** 2) * (1 + 2 * mu) + 2 * gamma * c * dd) / (
        4 * j + (b ** 2 + h ** 2) * (1 + 2 * mu) + 2 * gamma * c ** 2)
    w_m, p_m = W_MINUS, PSI_DOT_MINUS
    w_p = ratio * w_m
    psi_p = p_m + (h * sp.cos(ps) * (w_p - w_m) - b * sp.sin(ps) * (w_p + w_m)) / l
    return ratio, psi_p
