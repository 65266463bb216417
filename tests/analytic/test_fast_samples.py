"""The compiled per-sample accelerations (``analytic._fast_steps.sample_accelerations``)
that the contact checks use once a spectrum has loaded the fast path: bit for
bit the scalar equations' numbers, so the validity of a threshold run does not
depend on what else the process has loaded."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from trilith_xval.analytic import _fast_steps, fast, reactions
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.simulate import simulate
from trilith_xval.scenes import load_scene


def _samples(scene, pulse):
    tr = simulate(scene, pulse)
    arrays = [np.asarray(a, dtype=float) for a in (tr.t, tr.theta, tr.theta_dot, tr.psi,
                                                     tr.psi_dot)]
    return tr, arrays


# Rocking with impacts and rest (5 rad/s), the Omega = 11 no-impact overturn, and
# the lintel thrown off at 26 rad/s; with and without the pendulum.
CASES = [(3.0, 5.0), (9.5, 11.0), (74.9, 26.0)]


@pytest.mark.parametrize("pendulum", [True, False])
@pytest.mark.parametrize("amplitude, omega", CASES)
def test_compiled_accelerations_are_the_scalar_ones(pendulum, amplitude, omega):
    scene = load_scene("fig5")
    scene = scene if pendulum else scene.without_pendulum()
    pulse = Pulse(amplitude, omega)
    _, (t, th, thd, ps, psd) = _samples(scene, pulse)
    sides = reactions.sample_sides(t, th, thd)
    xg = np.asarray(pulse.acceleration_array(t), dtype=float)
    args = scene.model_args()
    scalar = np.array([reactions._accelerations(*row, *args) for row in
                       zip(th.tolist(), thd.tolist(), ps.tolist(), psd.tolist(), xg.tolist(),
                           sides.tolist())]).reshape(len(t), 2)
    compiled = _fast_steps.sample_accelerations(th, thd, ps, psd, xg, sides, *args)
    assert np.any(sides != 0.0) and np.any(sides == 0.0)  # both branches taken
    assert np.array_equal(compiled.view(np.int64), scalar.view(np.int64))


def test_validity_is_the_same_with_and_without_the_compiled_path(monkeypatch):
    scene = load_scene("fig5")
    tr, (t, th, thd, ps, psd) = _samples(scene, Pulse(74.9, 26.0))
    call = (t, th, thd, ps, psd, tr.excitation, scene.model_args(), scene.alpha,
            tr.verdict.status == "overturned")
    fast.warm_up(record=False)  # what a spectrum does first
    assert reactions._compiled_accelerations() is not None
    with_kernels = reactions.validity_diagnostics(*call)
    monkeypatch.delitem(sys.modules, "trilith_xval.analytic._fast_kernels")  # a process without them
    assert reactions._compiled_accelerations() is None
    assert reactions.validity_diagnostics(*call) == with_kernels
