"""The rocking block family (``block_lam*``: mu = gamma = 0, b = 0.6 m) against
closed-form anchors.

* Housner (1963): Eq. 20 at mu = gamma = 0 is ``1 - 1.5 sin^2(alpha)`` for a
  uniform rectangle, and the first impact of a run has that ratio.
* Zhang & Makris (2001), "Rocking response of free-standing blocks under
  cycloidal pulses", J. Eng. Mech. 127(5) 473-483: under a one-sine (their
  Type-A) pulse the minimum overturning acceleration, as ``a_p/(g tan alpha)``
  against ``w_p/p`` (``p = sqrt(3 g / (4 R))``, ``R`` the half-diagonal), starts at
  1 for a slow pulse and rises with the frequency, and a block overturns in two
  distinct modes, after one or more impacts (their mode 1) and without any
  impact (mode 2).  Their linearized equations are solved in closed form in
  :mod:`tests.support.linear_rocking` (written independently of analytic/); the
  model's thresholds must agree with them to the linearization error.
* Dimensional analysis (Housner's size effect): blocks of one slenderness have
  the same ``a_p/(g tan alpha)`` at the same ``w_p/p``, whatever their size.

Thresholds are the compiled first-overturning search (``analytic.first_overturn``)
with a bisection tolerance of 1e-3 m/s^2 (0.05 % of the smallest threshold here).
"""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic import fast
from trilith_xval.analytic import simulate as acc
from trilith_xval.analytic.excitation import Pulse, Still
from trilith_xval.analytic.first_overturn import (SpectrumSettings, first_overturn_amplitude,
                                                  search_run_settings)
from trilith_xval.scenes import load_scene, scene_names
from tests.support.linear_rocking import min_overturning_amplitude

LAMS = ("1.5", "2", "3", "5", "8", "10")
FAMILY = tuple(f"block_lam{lam}" for lam in LAMS)
TOL = 1e-3  # m/s^2, bisection resolution of the thresholds below


def _p(scene) -> float:
    """Housner's frequency parameter of a uniform rectangle [rad/s] (R: half-diagonal)."""
    return math.sqrt(3.0 * scene.g / (4.0 * 0.5 * math.hypot(scene.b, scene.h)))


def _housner(scene) -> float:
    return 1.0 - 1.5 * math.sin(scene.alpha) ** 2


def _threshold(scene, w_over_p: float, r: float = 1.0) -> tuple[float, str]:
    """``(a_p/(g tan alpha), mode)`` of the model at ``w_p/p``."""
    ss = SpectrumSettings(tol=TOL, fast=search_run_settings(restitution_factor=r))
    a, _, mode, _, _ = first_overturn_amplitude(scene, w_over_p * _p(scene), ss)
    return a / (scene.g * math.tan(scene.alpha)), mode


def test_the_family_is_shipped():
    assert set(FAMILY) <= set(scene_names())
    for name, lam in zip(FAMILY, LAMS):
        s = load_scene(name)
        assert (s.lam, s.b, s.mu, s.gamma) == (float(lam), 0.6, 0.0, 0.0)


@pytest.mark.parametrize("name", FAMILY)
def test_eq20_is_housner(name):
    s = load_scene(name)
    b, h, mu, gamma, j, _l, _g = s.model_args()
    for side in (1.0, -1.0):  # round-off only: the two are the same number
        assert eq.restitution_ratio(0.0, side, b, h, mu, gamma, j) == pytest.approx(
            _housner(s), rel=1e-12)


@pytest.mark.parametrize("name", FAMILY)
def test_first_impact_has_housners_ratio_in_both_paths(name):
    s = load_scene(name)
    free = acc.simulate(s, Still(), acc.Settings(theta0=0.5 * s.alpha, t_max=20.0,
                                                 early_stop=False))
    # Just above uplift at w_p = p: the block lifts, swings back and hits.
    forced = fast.simulate(s, Pulse(1.05 * s.g * math.tan(s.alpha), _p(s), "sine"),
                           fast.Settings(t_max=20.0))
    for traj in (free, forced):
        imp = next(e for e in traj.events if e.kind == "impact")
        assert imp.theta_dot_after / imp.theta_dot_before == pytest.approx(_housner(s),
                                                                            abs=1e-6)


@pytest.mark.parametrize("name", FAMILY)
def test_slow_pulse_limit_is_g_tan_alpha(name):
    """Zhang & Makris's low-frequency end: a pulse much slower than the block
    (w_p/p -> 0) overturns it as soon as it uplifts it, a_p -> g tan alpha (Eq.
    11), approached from above.  At w_p/p = 0.1 the model needs 0.4-0.5 % more;
    1 % is half the threshold tolerance the engines are held to (2 %)."""
    s = load_scene(name)
    ratios = [_threshold(s, x)[0] for x in (1.0, 0.5, 0.25, 0.1)]
    assert all(r > 1.0 for r in ratios)  # never below uplift
    assert ratios == sorted(ratios, reverse=True)  # falls towards 1 as w_p/p falls
    assert ratios[-1] < 1.01


@pytest.mark.parametrize("name", FAMILY)
def test_two_overturning_modes(name):
    """Zhang & Makris's two modes: at w_p/p = 1 and 2 the first overturning comes
    after an impact (mode 1); at w_p/p = 8 the stockier blocks (lam <= 3) need a
    pulse that throws them over without any impact (mode 2), several times
    stronger (the curve jumps); the more slender the block, the higher its
    restitution and the later the jump (measured: w_p/p 2-3 at lam 1.5, 3-4 at 2,
    4-6 at 3, above 8 at lam >= 5)."""
    s = load_scene(name)
    (r1, m1), (r2, m2), (r8, m8) = (_threshold(s, x) for x in (1.0, 2.0, 8.0))
    assert (m1, m2) == ("after-impact", "after-impact")
    assert r1 < r2 < r8  # the curve rises with the frequency
    if s.lam <= 3.0:
        assert m8 == "no-impact" and r8 > 4.0 * r2
    else:
        assert m8 == "after-impact"


# The linearized equations drop terms of relative order x^2 (sin x -> x, cos x -> 1
# with x = alpha - theta, |x| ~ alpha along a threshold run): the model must agree
# with them to alpha^2 (3.9 % at lam 5, 1.5 % at 8, 1.0 % at 10).  Measured: at
# most 0.35 % for w_p/p <= 4, 1.9 % at lam 5 and w_p/p = 6.  A restitution off by
# 10 % moves the w_p/p = 4 threshold by 10 %: the comparison can fail.
@pytest.mark.parametrize("lam", ("5", "8", "10"))
@pytest.mark.parametrize("w_over_p", (0.5, 1.0, 2.0, 3.0, 4.0, 6.0))
def test_thresholds_match_the_linearized_closed_form(lam, w_over_p):
    s = load_scene(f"block_lam{lam}")
    model, mode = _threshold(s, w_over_p)
    lin, n_impacts = min_overturning_amplitude(w_over_p * _p(s), _p(s), s.alpha, _housner(s))
    # Normalized by g tan(alpha) (uplift) and by g alpha (the linear uplift) alike.
    assert model == pytest.approx(lin / s.alpha, rel=s.alpha ** 2)
    assert (mode == "no-impact") == (n_impacts == 0)


@pytest.mark.parametrize("r, w_over_p, mode", [(0.9, 2.0, "after-impact"),
                                               (0.9, 4.0, "after-impact"),
                                               (0.7, 4.0, "no-impact")])
def test_scaled_restitution_matches_the_closed_form_with_that_restitution(r, w_over_p, mode):
    """With ``restitution_factor`` r the model is the block whose impact keeps
    r x Housner: the closed form run with e = r (1 - 1.5 sin^2 alpha) agrees as
    closely as at r = 1 (measured: 0.16 % at most), and at r = 0.7 the first
    overturning at w_p/p = 4 becomes mode 2 in both."""
    s = load_scene("block_lam10")
    model, got = _threshold(s, w_over_p, r)
    lin, n_impacts = min_overturning_amplitude(w_over_p * _p(s), _p(s), s.alpha,
                                               r * _housner(s))
    assert got == mode and (n_impacts == 0) == (mode == "no-impact")
    assert model == pytest.approx(lin / s.alpha, rel=s.alpha ** 2)


@pytest.mark.parametrize("lam", ("1.5", "5"))
def test_size_effect_is_exact_similarity(lam):
    """Housner's size effect: only w_p/p matters at a given slenderness.  Blocks
    0.15, 0.6 and 1.2 m wide (p differing by 2.8x) have the same normalized
    thresholds to the bisection tolerance."""
    base = load_scene(f"block_lam{lam}")
    rows = [[_threshold(base.replace(b=b), x)[0] for x in (1.0, 2.0, 4.0)]
            for b in (0.15, 0.6, 1.2)]
    g_tan = base.g * math.tan(base.alpha)
    for row in rows[1:]:
        assert row == pytest.approx(rows[0], abs=2.0 * TOL / g_tan)
