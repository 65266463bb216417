"""Engines running the other kinds (analytic.kinds) from the body list, the failure
rule of engines.structure_monitor, and the engines that refuse those kinds."""
from __future__ import annotations

import math

import pytest

from trilith_xval.analytic.excitation import Pulse, Still
from trilith_xval.engines import geometry, get_backend
from trilith_xval.engines.diagnostics import PlaneState, Pose
from trilith_xval.engines.pymunk_ import Settings as PymunkSettings
from trilith_xval.engines.structure_monitor import StructureMonitor
from trilith_xval.scenes import load_scene
from tests.support.slip import support_slip

KINDS = ("drums", "unequal", "block_on_block")


def test_an_engine_without_the_body_list_refuses_another_kind_by_name():
    # Every shipped engine builds the body list; an engine that does not (the
    # toy engine of the contract tests, structures = False) refuses by name.
    from tests.support.toy_engine import ToyEngine
    with pytest.raises(ValueError) as info:
        ToyEngine(load_scene("drums"), Pulse(2.0, 8.0))
    message = str(info.value)
    assert message.startswith("toy runs the parametric trilith only")
    assert "'drums' kind" in message and len(message.splitlines()) == 1


def test_structure_engines_are_the_ones_that_say_so():
    from trilith_xval import engines
    says = {name for name in engines.ENGINES
            if getattr(get_backend(name), "structures", False)}
    assert says == set(geometry.STRUCTURE_ENGINES)
    assert set(geometry.STRUCTURE_ENGINES) == {"pymunk", "mujoco", "pybullet", "dart", "drake"}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("engine", geometry.STRUCTURE_ENGINES)
def test_below_uplift_every_body_stays_put(engine, kind):
    # Any rigid part of the structure tips about a corner only when a/g reaches the
    # horizontal distance from that corner to its centre of mass over the centre's
    # height: at least (w_min / 2) / H_top here (centred parts; the offsets of the
    # examples are smaller than the half-widths).  Half of that: nothing rocks.
    scene = load_scene(kind)
    st = geometry.structure_of(scene)
    w_min = min(box.b for box in st.bodies)
    top = max(box.upright[1] + 0.5 * box.h for box in st.bodies)
    amplitude = 0.5 * scene.g * 0.5 * w_min / top
    tr = get_backend(engine).simulate(scene, Pulse(amplitude, 8.0))
    assert tr.verdict.status == "survived", tr.verdict
    # Contact compliance tilts a resting body by ~1e-6 rad (MonitorSettings.uplift_angle).
    ratios = [v for k, v in tr.diagnostics.items() if k.startswith("max_angle_over_alpha.")]
    assert len(ratios) == len(geometry.structure_of(scene).bodies)
    assert max(ratios) < 1e-2


# A pulse well above each kind's uplift (4-6 g tan alpha_min) at 8 rad/s: both engines
# must fail the structure, and in the same way (an overturn, or the lintel falling off).
STRONG = {"drums": 8.0, "unequal": 8.0, "block_on_block": 12.0}


@pytest.mark.slow  # five engines, DART and Drake at 2-4 CPU s per simulated second
@pytest.mark.parametrize("kind", KINDS)
def test_the_engines_fail_a_strongly_shaken_structure_alike(kind):
    scene = load_scene(kind)
    runs = [get_backend(e).simulate(scene, Pulse(STRONG[kind], 8.0))
            for e in geometry.STRUCTURE_ENGINES]
    statuses = {tr.verdict.status for tr in runs}
    assert len(statuses) == 1 and statuses <= {"overturned", "collapsed"}, \
        [tr.verdict for tr in runs]
    # Their failure times agree within 5 % (the engines' contact models differ; a
    # sample is 8 ms of runs lasting about a second or more).
    times = [tr.verdict.time for tr in runs]
    assert max(times) - min(times) <= 0.05 * max(times)


@pytest.mark.parametrize("kind", KINDS)
def test_pybullet_calibrated_friction_holds_at_the_strong_pulses(kind):
    # PyBullet's calibrated friction is 1 (Pymunk's and MuJoCo's 10); the strong pulses
    # ask PGA/g = 0.82 (drums, unequal: friction 1 is used) and 1.22 (block_on_block:
    # 1.2 x 1.22 = 1.47 is used).  Followed until a body passes 0.9 of its alpha.
    backend = get_backend("pybullet")
    settings = backend.Settings(sample_every=10)
    slip = support_slip(backend, load_scene(kind), Pulse(STRONG[kind], 8.0), settings)
    # 1e-4 m is the contact slop, the depth a resting corner sinks into its support: a
    # sunk corner turning by theta moves by about slop * theta without slipping
    # (measured at most 0.03 mm, at friction 0.82, 1 and 3 alike).
    assert max(slip.values()) < 1e-4, slip


def test_the_slip_measure_sees_a_slide():
    # The same measure with friction forced to 0.3, under the 1.22 this pulse needs
    # before uplift: the blocks slide (measured 0.42 m at the ground, 80 mm between them).
    backend = get_backend("pybullet")
    settings = backend.Settings(sample_every=10)
    slip = support_slip(backend, load_scene("block_on_block"), Pulse(12.0, 8.0), settings,
                        friction=0.3)
    assert slip[("lower", "ground")] > 1e-2, slip


# ------------------------------------------------------------ the failure rule
def _states(scene, change=None):
    """A PlaneState of the structure at rest, with ``change(name, pose) -> pose``."""
    st = geometry.structure_of(scene)
    bodies = []
    for box in st.bodies:
        pose = Pose(box.upright[0], box.upright[1], 0.0, 0.0, 0.0, 0.0)
        bodies.append(change(box.name, pose) if change else pose)
    return st, PlaneState((), None, bodies=tuple(bodies))


def _monitor(scene, st, **options):
    return StructureMonitor(scene, st, Still(), PymunkSettings(**options))


def test_a_drum_past_the_topple_angle_overturns():
    scene = load_scene("drums")
    st, state = _states(scene, lambda n, p: p._replace(angle=1.5) if n == "column_left_2" else p)
    m = _monitor(scene, st)
    assert m.record(0.0, state)
    assert m.verdict.status == "overturned" and "column_left_2" in m.verdict.reason


def test_alpha_criterion_uses_each_bodys_own_angle():
    from trilith_xval.analytic.trajectory import OverturnCriterion
    scene = load_scene("block_on_block")
    st = geometry.structure_of(scene)
    upper = st.body("upper")
    below, above = 0.99 * upper.alpha, 1.01 * upper.alpha
    for angle, decided in ((below, False), (above, True)):
        _, state = _states(scene, lambda n, p: p._replace(angle=angle) if n == "upper" else p)
        m = _monitor(scene, st, criterion=OverturnCriterion("alpha"), t_max=1.0)
        assert m.record(0.0, state) is decided


def test_a_lintel_that_falls_off_is_a_collapse_and_a_fallen_drum_an_overturn():
    scene = load_scene("unequal")
    st, state = _states(scene, lambda n, p: p._replace(y=p.y - 0.5) if n == "lintel" else p)
    m = _monitor(scene, st)
    assert m.record(0.0, state) and m.verdict.status == "collapsed"
    assert "fell off" in m.verdict.reason
    scene = load_scene("drums")
    st, state = _states(scene, lambda n, p: p._replace(y=p.y - 0.4) if n == "column_right_2"
                        else p)
    m = _monitor(scene, st)
    assert m.record(0.0, state) and m.verdict.status == "overturned"


def test_at_rest_after_the_pulse_survives_after_the_hold():
    scene = load_scene("block_on_block")
    st, state = _states(scene)
    m = _monitor(scene, st)
    hold = m.cfg.rest_hold
    assert not m.record(0.0, state)
    assert m.record(hold, state) and m.verdict.status == "survived"


def test_a_small_tilt_turns_the_whole_structure_rigidly():
    # The threshold search's 1e-6 rad plumb error: every body turns about the
    # footprint's bottom-left corner, so the distances between centres are kept.
    scene = load_scene("drums")
    flat, tilted = geometry.structure_of(scene), geometry.structure_of(scene, 1e-6)
    a, b = flat.bodies, tilted.bodies
    for i in range(len(a)):
        assert b[i].start[2] == 1e-6
        for j in range(i):
            d0 = math.dist(a[i].start[:2], a[j].start[:2])
            # Rounding of a rotation of metre-sized coordinates: ~1e-15 m.
            assert math.dist(b[i].start[:2], b[j].start[:2]) == pytest.approx(d0, abs=1e-12)
    # Beyond a plumb error: a release below the kind's limit only, none for unequal columns.
    with pytest.raises(ValueError, match="theta0 must be in"):
        geometry.structure_of(scene, 1.01 * geometry.release_limit(scene))
    with pytest.raises(ValueError, match="the unequal kind has no free-rocking release"):
        geometry.structure_of(load_scene("unequal"), 0.1)


def test_a_release_tilts_each_column_of_drums_as_a_rigid_stack_under_the_lintel():
    scene = load_scene("drums")
    theta0 = 0.5 * geometry.release_limit(scene)
    flat, tilted = geometry.structure_of(scene), geometry.structure_of(scene, theta0)
    upright = {x.name: x for x in flat.bodies}
    bodies = {x.name: x for x in tilted.bodies}
    for side in ("left", "right"):
        column = [n for n in bodies if n.startswith(f"column_{side}_")]
        for i, n in enumerate(column):
            assert bodies[n].start[2] == theta0
            for m in column[:i]:  # rigid: distances between centres kept
                assert math.dist(bodies[n].start[:2], bodies[m].start[:2]) == pytest.approx(
                    math.dist(upright[n].start[:2], upright[m].start[:2]), abs=1e-12)
    # The lintel rests level on the top drums' highest corners (zero gap).
    top, lintel = bodies["column_left_2"], bodies["lintel"]
    x, y, a = top.start
    corner_y = y + math.sin(a) * 0.5 * top.b + math.cos(a) * 0.5 * top.h
    assert lintel.start[2] == 0.0
    assert lintel.start[1] - 0.5 * lintel.h == pytest.approx(corner_y, abs=1e-12)


# DART (dartpy 6.20) puts bodies to sleep (World.getDeactivationOptions: enabled,
# below 0.01 m/s and 0.05 rad/s for 0.5 s): 0.5 s after this pulse every velocity
# is set to 0 and the bob stops mid-swing (measured: frozen from t = 1.2856 s, the
# same in the trilith fig5 under this pulse; the engine keeps dartpy's default).
# With deactivation off DART's bob follows the reference to 1.4e-4 of the swing.
_SLEEPS = pytest.mark.xfail(strict=True, reason="DART's body deactivation freezes the bob "
                            "0.5 s after the pulse")


# Drake's contact is compliant: the swinging bob tilts the drums elastically by
# 2.1e-5 rad (measured; the trilith's own check names 3.3e-6 rad, a known failure of
# engines.testing), over the 1e-6 rad of a rigid base, though under the 1e-4 rad of
# uplift; its psi follows the reference to 1.0e-3 of the swing.
_COMPLIANT = pytest.mark.xfail(strict=True, reason="Drake's compliant contact tilts the "
                               "drums by 2.1e-5 rad under the swinging bob")
_BOB_MARKS = {"dart": _SLEEPS, "drake": _COMPLIANT}


@pytest.mark.parametrize("engine", [pytest.param(e, marks=_BOB_MARKS[e]) if e in _BOB_MARKS
                                    else e for e in geometry.STRUCTURE_ENGINES])
def test_below_uplift_the_drums_bob_is_a_pendulum_on_a_rigid_base(engine):
    _bob_on_a_rigid_base(engine)


def test_dart_awake_bob_is_a_pendulum_on_a_rigid_base():
    # The same check with DART's body deactivation off (Settings.deactivation): the
    # freeze above is deactivation alone, not DART's contact or joints.
    _bob_on_a_rigid_base("dart", deactivation=False)


def _bob_on_a_rigid_base(engine, **settings):
    # Where a limit is exact: the frame does not uplift (1 m/s^2 against g b/H = 1.96),
    # so the bob swings on a rigidly moving hinge, psi'' = -(g sin psi + a(t) cos psi)/l,
    # whatever the columns are made of.  Integrated here independently of the model.
    import numpy as np
    from scipy.integrate import solve_ivp

    from trilith_xval.analytic.kinds import Drums
    scene = Drums(b=0.6, heights=(1.5, 1.5), mu=1.0, gamma=0.3, name="drums_bob")
    pulse = Pulse(1.0, 8.0)
    backend = get_backend(engine)
    tr = backend.simulate(scene, pulse, backend.Settings(t_max=2.0, **settings))
    assert tr.verdict.status == "survived" and tr.max_abs_theta < 1e-6
    l, g = scene.base.pendulum_length, scene.g
    ref = solve_ivp(lambda t, y: (y[1], -(g * np.sin(y[0]) + pulse.acceleration(t)
                                          * np.cos(y[0])) / l),
                    (0.0, tr.t[-1]), (0.0, 0.0), t_eval=tr.t, rtol=1e-10, atol=1e-12,
                    max_step=1e-3)
    peak = np.max(np.abs(ref.y[0]))
    # 1 % of the swing: the engines' bob has a small own inertia (1e-4 and 1e-6 of
    # m l^2) and a compliant hinge; measured 2.8e-4 (Pymunk) and 1.5e-4 (MuJoCo) of the swing.
    assert np.max(np.abs(tr.psi - ref.y[0])) <= 1e-2 * peak
