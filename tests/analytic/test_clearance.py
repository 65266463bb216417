"""Bob-column clearance: closed forms of the frame's geometry."""
import math

import numpy as np
import pytest

from trilith_xval.analytic.clearance import bob_clearance, check_clearance
from trilith_xval.analytic.parameters import Scene

FIG8 = Scene(b=0.6, lam=3.0, gamma=0.1)  # d = h = 1.8 m, l = 2h/3 = 1.2 m


def test_upright_contact_angle_is_asin_half_gap_over_length():
    psi_c = math.asin(0.9 / 1.2)  # 0.848 rad: where the README's record shows the bob inside
    assert bob_clearance(FIG8, 0.0, psi_c) == pytest.approx(0.0, abs=1e-12)
    assert bob_clearance(FIG8, 0.0, 0.0) == pytest.approx(0.9)
    assert bob_clearance(FIG8, 0.0, 1.03) < 0.0  # psi of the README's PyBullet record
    assert bob_clearance(FIG8, 0.0, -psi_c) == pytest.approx(0.0, abs=1e-12)  # mirror
    r = 0.05
    assert bob_clearance(FIG8, 0.0, math.asin((0.9 - r) / 1.2), r) == pytest.approx(0, abs=1e-12)


def test_tilted_faces_by_hand():
    """theta > 0: the left column's face, turned about its inner top corner, leans in
    by |y| tan(theta) at the bob's depth; perpendicular distance = horizontal x cos."""
    th, psi = 0.1, -0.3
    x, y = 1.2 * math.sin(psi), -1.2 * math.cos(psi)
    left = (x - (-0.9 - y * math.tan(th))) * math.cos(th)
    right = (0.9 + 0.6 * (1 - math.cos(th)) - (y + 0.6 * math.sin(th)) * math.tan(th) - x) \
        * math.cos(th)
    assert bob_clearance(FIG8, th, psi) == pytest.approx(min(left, right), rel=1e-12)
    # mirror symmetry: (theta, psi) -> (-theta, -psi)
    assert bob_clearance(FIG8, -th, -psi) == pytest.approx(bob_clearance(FIG8, th, psi))
    arr = bob_clearance(FIG8, np.array([0.0, th]), np.array([0.0, psi]))
    assert arr.shape == (2,) and arr[1] == pytest.approx(min(left, right))


def test_check_on_a_model_run():
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.analytic.simulate import simulate
    tr = simulate(FIG8, Pulse(2.0, 15.0))  # below uplift: the bob barely moves
    out = check_clearance(FIG8, tr)
    assert out["valid"] and out["min_clearance"] == pytest.approx(0.9, abs=0.05)
    assert check_clearance(FIG8.without_pendulum(), tr)["min_clearance"] is None
