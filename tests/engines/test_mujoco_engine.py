"""The MuJoCo backend: what is MuJoCo-specific, plus its acceptance checks.

Acceptance: free rocking against Eq. 20 (lam 3/5/7 x mu 0.5/1/2) and Eq. 19
(pendulum, lam 3/5/7) within 0.5 %; the paper's verdicts and modes at A-D with
and without the pendulum equal to the analytic backend's; one overturning
threshold within 2 %; bit-identical reruns; bad settings refused before any
model is built.  Specific: the MJCF is generated from the Scene, the tilted
start, the sign conventions, ``mu = 0`` builds no lintel, MuJoCo's reset
warnings end a run as 'unstable', "gravity" vs "ground" base motion.
"""
from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from trilith_xval.analytic.excitation import Pulse, Still
from trilith_xval.analytic.parameters import Scene
from trilith_xval.compare.measure.reference_spectra import first_overturning_amplitude
from trilith_xval.compare.measure.thresholds import engine_threshold
from trilith_xval.engines.mujoco_ import MujocoEngine, Settings
from trilith_xval.compare.measure.restitution import measure_restitution
from trilith_xval.scenes import load_scene

# Issue acceptance: 0.5 %.  Measured at the defaults (docs/mujoco.md): max
# 0.051 % (Eq. 20 grid, 36 impacts, median 0.02 %) and 0.053 % (Eq. 19, 12
# impacts); max 0.13 % over 216 impacts from releases at 0.3, 0.5, 0.8 alpha.
RESTITUTION_TOL = 5e-3


@pytest.mark.slow
def test_overturning_threshold_within_2_percent():
    """Pendulum, Omega = 12.5 rad/s (no-impact branch, 2 rad/s above the jump
    at 10-10.5): measured a_engine = a_ref within the 0.4 % bisection step."""
    scene = load_scene("fig5")
    a_ref, mode_ref = first_overturning_amplitude(scene, 12.5)
    p = engine_threshold("mujoco", scene, 12.5, a_ref, mode_reference=mode_ref, rel_tol=4e-3)
    assert p.irregular_runs == 0 and p.bracketed
    assert abs(p.rel_error) <= 0.02, (p.a_engine, a_ref)  # issue acceptance
    assert p.mode_engine == mode_ref


def test_reruns_are_bit_identical():
    scene, pulse = load_scene("fig5"), Pulse(4.0, 9.0)
    st = Settings(t_max=0.4)
    first = MujocoEngine.simulate(scene, pulse, st)
    MujocoEngine.simulate(scene, pulse, dataclasses.replace(st, dampratio=1.0, t_max=0.1))
    second = MujocoEngine.simulate(scene, pulse, st)
    for name in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(first, name), getattr(second, name)), name
    assert first.max_abs_theta > 1e-3  # it rocked


@pytest.mark.parametrize("changes, name", [
    ({"dt": 0.0}, "dt"), ({"dt": float("nan")}, "dt"), ({"base_motion": "shake"}, "base_motion"),
    ({"sample_every": 0}, "sample_every"), ({"friction": 0.1}, "friction"),
    ({"theta0": 2.0}, "theta0"), ({"psi0": 4.0}, "psi0"), ({"t_max": -1.0}, "t_max"),
    ({"timeconst_steps": 0.0}, "timeconst_steps"), ({"timeconst": -1e-3}, "timeconst"),
    ({"dampratio": -1.0}, "dampratio"), ({"cone": "round"}, "cone"),
    ({"impratio": 0.0}, "impratio"), ({"iterations": 0}, "iterations"),
    ({"solver": "magic"}, "solver"), ({"integrator": "leapfrog"}, "integrator"),
    ({"solimp": (0.9, 0.95)}, "solimp"), ({"solimp": (0.9, 1.5, 1e-3, 0.5, 2.0)}, "solimp"),
])
def test_bad_settings_raise_before_a_model_is_built(monkeypatch, changes, name):
    """friction 0.1 is below required_friction (0.41 at fig. 5 under 10 m/s^2)."""
    monkeypatch.setattr(mujoco.MjModel, "from_xml_string",
                        lambda *a, **k: pytest.fail("model built before validation"))
    with pytest.raises((ValueError, TypeError), match=name):  # at construction or at the run
        MujocoEngine.simulate(load_scene("fig5"), Pulse(10.0, 9.0),
                    dataclasses.replace(Settings(), **changes))


def test_massless_lintel_with_pendulum_is_refused(monkeypatch):
    monkeypatch.setattr(mujoco.MjModel, "from_xml_string", lambda *a, **k: pytest.fail("built"))
    with pytest.raises(ValueError, match="mu"):
        MujocoEngine.simulate(Scene(mu=0.0, gamma=0.3), Pulse(3.0, 6.0))


def test_model_is_generated_from_the_scene():
    """Sizes, masses and inertias in the compiled model are the Scene's, for a
    scene whose every engine-only field differs from its default."""
    scene = Scene(b=0.4, lam=4.0, mu=1.5, gamma=0.2, l=0.9, gap=1.1, lintel_height=0.3,
                  hinge_x=0.2, depth=0.7, J_G=2.0 * Scene(b=0.4, lam=4.0).inertia_J_G)
    w = MujocoEngine(scene, Still(), Settings())
    w.build()
    m = w.model

    def body(name):
        return mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)

    col, lintel, pend = body("column_left"), body("lintel"), body("pendulum")
    assert m.geom_size[m.body_geomadr[col]] == pytest.approx(
        [0.5 * scene.b, 0.5 * scene.depth, 0.5 * scene.h], rel=1e-12)
    assert m.geom_size[m.body_geomadr[lintel]] == pytest.approx(
        [0.5 * scene.lintel_length, 0.5 * scene.depth, 0.5 * scene.lintel_thickness], rel=1e-12)
    assert m.body_mass[col] == pytest.approx(scene.m1, rel=1e-12)
    assert m.body_inertia[col][1] == pytest.approx(scene.inertia_J_G, rel=1e-12)
    assert m.body_mass[lintel] == pytest.approx(scene.m3, rel=1e-12)
    assert m.body_mass[pend] == pytest.approx(scene.m4, rel=1e-12)
    assert m.body_geomnum[pend] == 0  # the bob collides with nothing
    mujoco.mj_forward(m, w.data)
    right = w.data.xpos[body("column_right")]
    assert right[0] - 0.5 * scene.b == pytest.approx(scene.b + scene.d, abs=1e-12)
    # Bob l below the hinge, which is hinge_x from the lintel's middle, on its underside.
    bob = w.data.xipos[pend]
    assert bob[0] == pytest.approx(0.5 * scene.lintel_length + scene.hinge_x, abs=1e-12)
    assert bob[2] == pytest.approx(scene.h - scene.pendulum_length, abs=1e-12)
    friction = {tuple(f) for f in m.geom_friction}
    assert friction == {(10.0, 0.0, 0.0)}  # every geom: MuJoCo takes the pair's maximum


def test_mu_zero_builds_no_lintel_and_rocks_as_housner():
    """mu = 0: two independent blocks; Eq. 20 is then Housner's 1 - 1.5 sin^2 alpha."""
    scene = load_scene("single_block")
    w = MujocoEngine(scene, Still(), Settings())
    w.build()
    assert w.model.nbody == 3 and w.lintel is None  # world + two columns
    res = measure_restitution("mujoco", scene, 0.5 * scene.alpha, n_impacts=2)
    assert res.impacts[0].predicted == pytest.approx(1.0 - 1.5 * math.sin(scene.alpha) ** 2,
                                                     rel=1e-12)
    assert res.max_rel_error <= RESTITUTION_TOL, [i.rel_error for i in res.impacts]


@pytest.mark.parametrize("sign", [1, -1])
def test_tilted_start_rests_on_its_pivots_and_rocks_to_the_other_side(sign):
    """theta0 > 0 leans left on the left corners (analytic sign); the pivots
    start on the ground and the lintel's underside on the raised top corners."""
    scene = load_scene("no_pendulum")
    theta0 = sign * 0.3 * scene.alpha
    w = MujocoEngine(scene, Still(), Settings(theta0=theta0))
    w.build()
    mujoco.mj_forward(w.model, w.data)
    assert w.data.ncon > 0
    assert np.min(w.data.contact.dist[:w.data.ncon]) == pytest.approx(0.0, abs=1e-12)
    assert tuple(c.angle for c in w.read().columns) == (theta0, theta0)
    tr = MujocoEngine.simulate(scene, Still(), Settings(theta0=theta0, t_max=0.8,
                                                 early_stop=False))
    assert tr.theta[0] == theta0
    assert np.sign(tr.theta_dot[5]) == -sign
    assert tr.impacts and tr.impacts[0].side == -sign
    assert tr.diagnostics["pivot_sliding_max"] < 1e-5


def test_mujoco_reset_warning_ends_the_run_as_unstable(monkeypatch):
    """A velocity beyond MuJoCo's limit (1e10) makes mj_step reset the state and
    warn; the run must stop as 'unstable' then, not carry on from the reset."""
    class Kicked(MujocoEngine):
        def advance(self, steps):
            if self.step_index * self.settings.dt >= 0.2:
                self.data.qvel[0] = 1e11
            super().advance(steps)

    tr = Kicked.simulate(load_scene("fig5"), Pulse(4.0, 9.0), Settings(t_max=1.0))
    assert tr.verdict.status == "unstable"
    assert "mjWARN_BADQVEL" in tr.verdict.reason
    spacing = Settings().sample_every * Settings().dt  # seen at the next sample
    assert 0.2 < tr.verdict.time <= 0.2 + spacing + 1e-9

