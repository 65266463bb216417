"""The paper's equations, re-derived and corrected, as scalar pure functions.

Every function takes plain floats (no objects) so that the same source is used by
the accurate path (called from Python) and compiled by numba for the fast path:
the physics is written once.  Masses are per unit column mass ``m1`` (the
equations are homogeneous in mass), so the model parameters are

    b, h   column width and height [m]
    mu     lintel mass / m1            (Eq. 10)
    gamma  pendulum mass / m1          (Eq. 10)
    j      J_G / m1 [m^2]              (J_G: one column's polar inertia)
    l      pendulum length [m]
    g      gravity [m/s^2]

``side = +1`` is rocking about the left base corners (``theta > 0``, Eq. 8);
``side = -1`` about the right ones (``theta < 0``, Eq. A.1).  Mirroring
(``b -> -b``) maps one onto the other, which is how both are written here.

Corrections to the print (see ``docs/paper-errata.md``; each is checked against
an independent sympy derivation in ``tests/analytic/test_derivation.py``):

* Eq. 8, first equation: the gravity term is ``g M (b cos(theta) - h sin(theta))``
  and the centripetal pendulum term ``l m4 psi_dot^2 (b cos(theta-psi) -
  h sin(theta-psi))``: the print has ``+ h sin`` in both (A.1 has them right).
* Eq. 9: the ``psi_dot^2`` term is ``2 gamma l psi_dot^2 (cos(psi) + lam sin(psi))``
  in the numerator after the sign change below (the print carries Eq. 8's typo).
* Eq. 19: the denominator's pendulum term is ``2 m4 (b cos(psi) + h sin(psi))^2``
  (the print drops the factor 2; Eq. 21 has it).
* Eq. 17 is OCR-damaged (``+ -l m4`` and a bracket ending in ``+ 1`` for ``+ l``).
  Eqs. 15-16 are right as printed, ``- J_G`` included (moment of momentum about
  the new top corner); Eq. 20's ``m_p + 2 m_t`` means ``m1 + 2 m3``.
"""
from __future__ import annotations

import math

__all__ = [
    "total_mass", "rocking_inertia", "rocking_accelerations", "rest_pendulum_acceleration",
    "uplift_margin", "uplift_acceleration", "impact_velocities", "restitution_ratio",
    "energy", "rest_energy", "overturn_energy_barrier",
]


def total_mass(mu: float, gamma: float) -> float:
    """``M = (m1 + m3 + m4)/m1 = 1 + mu + gamma``: the mass whose weight acts on the
    rocking mechanism (the two columns count once each with lever ``b/2``)."""
    return 1.0 + mu + gamma


def rocking_inertia(b: float, h: float, mu: float, gamma: float, j: float) -> float:
    """``I/m1 = ((b^2 + h^2)(1 + 2(mu + gamma)) + 4 j) / 2`` (Eq. 8, theta_ddot term):
    two columns about their corners plus the translating lintel and hinge."""
    return 0.5 * ((b * b + h * h) * (1.0 + 2.0 * (mu + gamma)) + 4.0 * j)


def rocking_accelerations(theta: float, theta_dot: float, psi: float, psi_dot: float,
                          xg_ddot: float, side: float, b: float, h: float, mu: float,
                          gamma: float, j: float, l: float, g: float) -> tuple[float, float]:
    """``(theta_ddot, psi_ddot)`` while rocking (Eq. 8 for ``side=+1``, A.1 for ``-1``).

    Corrected Eq. 8 (per ``m1``), with ``sb = side*b``, ``k = sb sin(theta-psi) +
    h cos(theta-psi)`` and ``kc = sb cos(theta-psi) - h sin(theta-psi)``::

        I theta_ddot - gamma l k psi_ddot + gamma l kc psi_dot^2
            + g M (sb cos(theta) - h sin(theta)) - M xg_ddot (h cos(theta) + sb sin(theta)) = 0
        -k theta_ddot + l psi_ddot - kc theta_dot^2 + g sin(psi) + xg_ddot cos(psi) = 0

    (the second is Eq. 8b divided by ``m4 l``).  Without a pendulum
    (``gamma = 0``) ``psi_ddot`` is returned as 0.
    """
    sb = side * b
    big_m = 1.0 + mu + gamma
    inertia = 0.5 * ((b * b + h * h) * (1.0 + 2.0 * (mu + gamma)) + 4.0 * j)
    st = math.sin(theta)
    ct = math.cos(theta)
    r1 = -(g * big_m * (sb * ct - h * st) - big_m * xg_ddot * (h * ct + sb * st))
    if gamma == 0.0:
        return r1 / inertia, 0.0
    d = theta - psi
    sd = math.sin(d)
    cd = math.cos(d)
    k = sb * sd + h * cd
    kc = sb * cd - h * sd
    r1 -= gamma * l * kc * psi_dot * psi_dot
    r2 = kc * theta_dot * theta_dot - g * math.sin(psi) - xg_ddot * math.cos(psi)
    theta_ddot = (r1 + gamma * k * r2) / (inertia - gamma * k * k)
    psi_ddot = (r2 + k * theta_ddot) / l
    return theta_ddot, psi_ddot


def rest_pendulum_acceleration(psi: float, xg_ddot: float, l: float, g: float) -> float:
    """Eq. 1 solved for ``psi_ddot``: the pendulum on a trilith at rest."""
    return -(g * math.sin(psi) + xg_ddot * math.cos(psi)) / l


def uplift_margin(psi: float, psi_dot: float, xg_ddot: float, side: float, b: float,
                  h: float, mu: float, gamma: float, l: float, g: float) -> float:
    """Moment per ``m1`` [m^2/s^2] that the ground must supply at the corners
    opposite to ``side`` to keep the trilith at rest, times ``side``.

    Positive: the trilith stays down.  It uplifts about ``side`` when the margin
    reaches zero.  Obtained from Eq. 8 (or A.1) with ``theta = theta_dot =
    theta_ddot = 0`` and the pendulum obeying Eq. 1::

        Q = g M sb - M xg_ddot h + gamma (h cos(psi) - sb sin(psi)) (g sin(psi) + xg_ddot cos(psi))
            + gamma l psi_dot^2 (sb cos(psi) + h sin(psi)),    margin = side * Q

    This is also the sign of the coupled ``theta_ddot`` at ``theta = 0`` (a Schur
    complement of Eq. 8's mass matrix), so uplift is decided consistently.
    """
    sb = side * b
    big_m = 1.0 + mu + gamma
    sp = math.sin(psi)
    cp = math.cos(psi)
    q = (g * big_m * sb - big_m * xg_ddot * h
         + gamma * (h * cp - sb * sp) * (g * sp + xg_ddot * cp)
         + gamma * l * psi_dot * psi_dot * (sb * cp + h * sp))
    return side * q


def uplift_acceleration(psi: float, psi_dot: float, side: float, b: float, h: float,
                        mu: float, gamma: float, l: float, g: float) -> float:
    """Ground acceleration [m/s^2] at which the trilith uplifts about ``side``
    (Eq. 9, corrected).  For ``side=+1`` uplift needs ``xg_ddot >= a_up``; for
    ``side=-1``, ``xg_ddot <= a_up`` (negative).

    With ``gamma = 0`` it is ``side * g / lam`` (Eq. 11); with the pendulum hanging
    still (``psi = psi_dot = 0``) it is ``side * g (1 + mu + gamma) / (lam (1 + mu))``.
    The denominator vanishes only for a very heavy pendulum on a squat trilith
    (e.g. ``lam = 1, mu = 0, gamma > 4.8`` at ``psi ~ 0.39``): then +-inf.
    """
    sb = side * b
    big_m = 1.0 + mu + gamma
    sp = math.sin(psi)
    cp = math.cos(psi)
    num = (g * big_m * sb + gamma * g * sp * (h * cp - sb * sp)
           + gamma * l * psi_dot * psi_dot * (sb * cp + h * sp))
    den = big_m * h - gamma * cp * (h * cp - sb * sp)
    if den == 0.0:
        # The base acceleration drops out of the margin (heavy pendulum on a squat
        # trilith at one psi): no base acceleration uplifts if the margin is
        # positive, any does otherwise.
        return math.copysign(math.inf, side) if side * num > 0.0 else -math.copysign(math.inf, side)
    return num / den


def impact_velocities(theta_dot_minus: float, psi: float, psi_dot_minus: float,
                      new_side: float, b: float, h: float, mu: float, gamma: float,
                      j: float, l: float, rf: float = 1.0) -> tuple[float, float]:
    """Post-impact ``(theta_dot_plus, psi_dot_plus)`` at ``theta = 0`` (Eq. 19, 21
    corrected), for an impact that hands the rocking over to ``new_side``
    (``new_side=+1``: from the right corners to the left ones, ``theta_dot > 0``).

    Impulse-momentum (Eq. 13-18) with perfectly plastic contact at the new corners::

        theta_dot+ = -[-4j + (b^2 - h^2)(1 + 2 mu) + 2 gamma c d] /
                      [ 4j + (b^2 + h^2)(1 + 2 mu) + 2 gamma c^2] * theta_dot-
        c = sb cos(psi) + h sin(psi),   d = sb cos(psi) - h sin(psi),  sb = new_side*b
        psi_dot+ = psi_dot- + (h cos(psi) (theta_dot+ - theta_dot-)
                               - sb sin(psi) (theta_dot+ + theta_dot-)) / l

    If the ratio is not positive the trilith cannot re-uplift: it stops
    (``theta_dot+ = 0``) and the pendulum jump follows from the same formula.

    ``rf`` is the restitution factor in (0, 1] (callers validate it): it
    multiplies the rocking angular-velocity ratio ``theta_dot+ / theta_dot-`` of
    Eq. 19 (Eq. 20 without pendulum), and nothing else, so that a measured impact
    can stand in for the plastic one.  The pendulum's ``psi_dot+`` still follows
    from the second line above with the scaled ``theta_dot+``: that line says
    the bob's velocity across the rod is the same before and after (the rod,
    hinged at both ends, passes the impulse along itself only), which holds for
    any base impulse; at ``rf = 1`` it is Eq. 21.  ``rf = 1`` returns the exact
    ratio bit for bit (a product by 1.0 is exact).
    """
    sb = new_side * b
    sp = math.sin(psi)
    cp = math.cos(psi)
    c = sb * cp + h * sp
    dd = sb * cp - h * sp
    num = -4.0 * j + (b * b - h * h) * (1.0 + 2.0 * mu) + 2.0 * gamma * c * dd
    den = 4.0 * j + (b * b + h * h) * (1.0 + 2.0 * mu) + 2.0 * gamma * c * c
    ratio = -num / den * rf
    if ratio <= 0.0:
        ratio = 0.0
    theta_dot_plus = ratio * theta_dot_minus
    if gamma == 0.0:
        return theta_dot_plus, 0.0
    psi_dot_plus = psi_dot_minus + (h * cp * (theta_dot_plus - theta_dot_minus)
                                    - sb * sp * (theta_dot_plus + theta_dot_minus)) / l
    return theta_dot_plus, psi_dot_plus


def restitution_ratio(psi: float, new_side: float, b: float, h: float, mu: float,
                      gamma: float, j: float) -> float:
    """``theta_dot+ / theta_dot-`` at an impact (Eq. 19; Eq. 20 when ``gamma = 0``).

    Independent of ``psi_dot`` and of ``l``.  Clipped at 0 (the trilith stops).
    For ``gamma = 0`` and a uniform column this is the Makris-Vassiliou rocking
    frame value, and ``1 - 1.5 sin^2(alpha)`` (Housner) when also ``mu = 0``.
    """
    return impact_velocities(1.0, psi, 0.0, new_side, b, h, mu, gamma, j, 1.0)[0]


def energy(theta: float, theta_dot: float, psi: float, psi_dot: float, side: float,
           b: float, h: float, mu: float, gamma: float, j: float, l: float,
           g: float) -> float:
    """Mechanical energy per ``m1`` [J/kg] in the base frame, while rocking about
    ``side``; potential measured from the resting trilith with the pendulum hanging.

    ``T = I theta_dot^2/2 + gamma (l^2 psi_dot^2/2 - l k theta_dot psi_dot)``,
    ``V = g M (sb sin(theta) + h cos(theta) - h) + gamma g l (1 - cos(psi))``.
    Conserved while ``xg_ddot = 0`` and between impacts.
    """
    sb = side * b
    big_m = 1.0 + mu + gamma
    inertia = 0.5 * ((b * b + h * h) * (1.0 + 2.0 * (mu + gamma)) + 4.0 * j)
    k = sb * math.sin(theta - psi) + h * math.cos(theta - psi)
    kinetic = 0.5 * inertia * theta_dot * theta_dot + gamma * (
        0.5 * l * l * psi_dot * psi_dot - l * k * theta_dot * psi_dot)
    potential = g * big_m * (sb * math.sin(theta) + h * math.cos(theta) - h) + gamma * g * l * (
        1.0 - math.cos(psi))
    return kinetic + potential


def rest_energy(psi: float, psi_dot: float, gamma: float, l: float, g: float) -> float:
    """Energy per ``m1`` of the pendulum on a trilith at rest (same datum as :func:`energy`)."""
    return gamma * (0.5 * l * l * psi_dot * psi_dot + g * l * (1.0 - math.cos(psi)))


def overturn_energy_barrier(b: float, h: float, mu: float, gamma: float, g: float) -> float:
    """Lowest energy per ``m1`` at which ``|theta| = alpha`` can be reached:
    ``g M (sqrt(b^2 + h^2) - h)`` (pendulum hanging, trilith at rest speed).

    After the pulse the energy never increases, so a run whose energy is below
    this barrier *while* ``|theta| < alpha`` can never reach ``alpha``: it has
    survived, exactly.  Past ``alpha`` the rocking potential falls below the
    barrier (it is negative beyond ``2 alpha``), so the rule says nothing there:
    the paper's point D leans past ``alpha`` at the pulse end with less energy
    than the barrier and still topples.
    """
    return g * (1.0 + mu + gamma) * (math.hypot(b, h) - h)
