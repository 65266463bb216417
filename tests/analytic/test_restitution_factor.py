"""The restitution factor ``r`` of the model's impacts (docs/model.md, "A measured
restitution"): it multiplies the rocking angular-velocity ratio of Eq. 19 (Eq. 20
without pendulum) in both analytic paths, and ``r = 1`` is the model as it was.

Closed forms: for the single rocking block (``mu = gamma = 0``) Eq. 20 is
Housner's ``1 - 1.5 sin^2(alpha)``, so the first impact's measured ratio must be
``r (1 - 1.5 sin^2(alpha))`` and the kinetic energy just after it (all of the
energy: the block is upright there) ``r^2`` times the one at ``r = 1``.
"""
from __future__ import annotations

import hashlib
import json
import math
import platform
from pathlib import Path

import numpy as np
import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic import fast
from trilith_xval.analytic import simulate as acc
from trilith_xval.analytic.excitation import Pulse, Still
from trilith_xval.compare.run.keys import settings_dict
from trilith_xval.scenes import load_scene

REFERENCE = Path(__file__).parent / "data" / "restitution_r1_reference.json"
FACTORS = (1.0, 0.9, 0.6, 0.25)


@pytest.fixture(scope="module")
def block():
    return load_scene("single_block")


def _first_impact(traj):
    return next(e for e in traj.events if e.kind == "impact")


def _housner(scene) -> float:
    return 1.0 - 1.5 * math.sin(scene.alpha) ** 2


@pytest.mark.parametrize("r", FACTORS)
def test_accurate_first_impact_ratio_is_r_times_housner(block, r):
    # Free rocking from a tilt: the first impact sees the same theta_dot- for every r.
    traj = acc.simulate(block, Still(), acc.Settings(theta0=0.1, t_max=1.2, early_stop=False,
                                                     restitution_factor=r))
    imp = _first_impact(traj)
    assert imp.theta_dot_after / imp.theta_dot_before == pytest.approx(r * _housner(block),
                                                                        abs=1e-6)


@pytest.mark.parametrize("r", FACTORS)
def test_fast_first_impact_ratio_is_r_times_housner(block, r):
    # The compiled path starts at rest: a pulse above g/lam lifts the block.
    traj = fast.simulate(block, Pulse(3.0, 10.0, "sine"),
                         fast.Settings(t_max=3.0, restitution_factor=r))
    imp = _first_impact(traj)
    assert imp.theta_dot_after / imp.theta_dot_before == pytest.approx(r * _housner(block),
                                                                        abs=1e-6)


def test_energy_after_the_first_impact_scales_with_r_squared(block):
    b, h, mu, gamma, j, l, g = block.model_args()

    def after(r):
        traj = acc.simulate(block, Still(), acc.Settings(theta0=0.1, t_max=1.2,
                                                         early_stop=False,
                                                         restitution_factor=r))
        imp = _first_impact(traj)
        before = eq.energy(0.0, imp.theta_dot_before, 0.0, 0.0, -imp.side, b, h, mu, gamma,
                           j, l, g)
        return before, eq.energy(0.0, imp.theta_dot_after, 0.0, 0.0, imp.side, b, h, mu,
                                 gamma, j, l, g)

    e_in, e1 = after(1.0)
    # Released at rest from theta0: the energy reaching the impact is the drop in height.
    assert e_in == pytest.approx(eq.energy(0.1, 0.0, 0.0, 0.0, 1.0, b, h, mu, gamma, j, l, g),
                                 rel=1e-8)
    assert e1 / e_in == pytest.approx(_housner(block) ** 2, rel=1e-8)
    for r in FACTORS[1:]:
        e_in_r, e_r = after(r)
        assert e_in_r == e_in  # same motion up to the first impact
        assert e_r / e1 == pytest.approx(r * r, rel=1e-10)


def test_pendulum_jump_follows_the_scaled_rocking_velocity(fig5):
    """With the pendulum only theta_dot+ is scaled; psi_dot+ keeps the bob's
    velocity across the rod (the second line of ``impact_velocities``)."""
    b, h, mu, gamma, j, l, g = fig5.model_args()
    td, psi, pd = -0.8, 0.3, 1.1
    full = eq.impact_velocities(td, psi, pd, 1.0, b, h, mu, gamma, j, l)
    half = eq.impact_velocities(td, psi, pd, 1.0, b, h, mu, gamma, j, l, 0.5)
    assert half[0] == 0.5 * full[0]
    assert full[0] / td == eq.restitution_ratio(psi, 1.0, b, h, mu, gamma, j)
    sb = b  # new_side = +1
    for td_p, pd_p in (full, half):
        lhs = l * (pd_p - pd)
        rhs = h * math.cos(psi) * (td_p - td) - sb * math.sin(psi) * (td_p + td)
        assert lhs == pytest.approx(rhs, abs=1e-12)
    assert half[1] != full[1]  # a lossier base impact does change the bob's swing


@pytest.mark.parametrize("cls", [acc.Settings, fast.Settings])
@pytest.mark.parametrize("bad", [0.0, -0.1, 1.0 + 1e-12, math.nan, math.inf])
def test_out_of_range_factor_is_refused_naming_it(cls, bad):
    with pytest.raises(ValueError, match=r"restitution_factor must be finite in \(0, 1\]"):
        cls(restitution_factor=bad)


@pytest.mark.parametrize("cls", [acc.Settings, fast.Settings])
def test_keys_unchanged_at_one_and_distinct_below(cls):
    default = settings_dict(cls())
    assert "restitution_factor" not in default  # runs stored before it keep their keys
    assert settings_dict(cls(restitution_factor=1.0)) == default
    scaled = settings_dict(cls(restitution_factor=0.9))
    assert scaled == {**default, "restitution_factor": 0.9}


def _reference_runs():
    blk, fig5 = load_scene("single_block"), load_scene("fig5")
    yield "acc_block", acc.simulate(blk, Still(), acc.Settings(theta0=0.1, t_max=3.0,
                                                               early_stop=False))
    for name, sc, amp in (("fig5", fig5, 4.0), ("block", blk, 3.0)):
        p = Pulse(amplitude=amp, omega=10.0, kind="sine")
        yield f"acc_{name}_pulse", acc.simulate(sc, p, acc.Settings(t_max=6.0, early_stop=False))
        yield f"fast_{name}_pulse", fast.simulate(sc, p, fast.Settings(t_max=6.0))


def test_factor_one_reproduces_the_model_before_the_factor():
    """The stored digests are the output of the code before the factor existed.
    In the environment they were made in (same numpy, scipy, numba, machine)
    the arrays must be identical bit for bit; elsewhere a libm may round a sine
    differently, so there the stored rows are compared to 1e-9 relative."""
    ref = json.loads(REFERENCE.read_text())
    import numba
    import scipy
    here = {"python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "numba": numba.__version__,
            "machine": platform.machine()}
    same_env = here == ref["versions"]
    for name, traj in _reference_runs():
        want = ref["runs"][name]
        arr = np.ascontiguousarray(np.column_stack([traj.t, traj.theta, traj.theta_dot,
                                                    traj.psi, traj.psi_dot]), dtype=np.float64)
        if same_env:
            assert list(arr.shape) == want["shape"], name
            assert hashlib.sha256(arr.tobytes()).hexdigest() == want["sha256"], name
        for i, row in want["rows"].items():
            i = int(i)
            expected = [float.fromhex(x) for x in row]
            if same_env:
                assert arr[i].tolist() == expected, (name, i)
            else:
                assert arr[i] == pytest.approx(expected, rel=1e-9, abs=1e-12), (name, i)
