"""The body list (engines.geometry.Structure): the trilith built from it is the
trilith built before it existed, bit for bit, in Pymunk and MuJoCo.

The reference builders are verbatim copies of the pre-body-list code
(tests/support/legacy); trajectories are compared with ``np.array_equal``: the
same operations on the same numbers, so no tolerance is due."""
from __future__ import annotations

import numpy as np
import pytest

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.engines import geometry
from trilith_xval.engines.mujoco_ import MujocoEngine
from trilith_xval.engines.mujoco_ import Settings as MujocoSettings
from trilith_xval.engines.mujoco_.world import mjcf
from trilith_xval.engines.pymunk_ import PymunkEngine
from trilith_xval.engines.pymunk_ import Settings as PymunkSettings
from trilith_xval.scenes import load_scene
from tests.support.legacy import mujoco_world
from tests.support.legacy.engines import LegacyMujoco, LegacyPymunk

FIELDS = ("t", "theta", "theta_dot", "psi", "psi_dot")


def _same(a, b) -> None:
    for name in FIELDS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.verdict == b.verdict
    assert [(e.kind, e.t) for e in a.events] == [(e.kind, e.t) for e in b.events]
    for key in ("pivot_sliding_max", "lintel_rotation_max", "penetration_max",
                "column_mismatch_max", "n_samples"):
        assert a.diagnostics[key] == b.diagnostics[key], key


def test_structure_of_the_trilith_lists_its_bodies(fig5):
    st = geometry.structure_of(fig5)
    assert [box.name for box in st.bodies] == ["column_left", "column_right", "lintel"]
    assert st.bob is not None and st.bob.parent == "lintel"
    assert st.is_trilith and st.kind == "trilith"
    assert ("lintel", "column_left") in st.supports and ("column_left", "ground") in st.supports
    poses = geometry.rest_poses(fig5)
    assert st.bodies[0].start[:2] == poses.columns[0]
    assert st.bodies[2].h == fig5.lintel_thickness and st.bodies[0].alpha == fig5.alpha
    block = geometry.structure_of(load_scene("single_block"))
    assert block.kind == "block" and len(block.bodies) == 2 and block.bob is None


@pytest.mark.parametrize("scene_name, motion", [("fig5", "gravity"), ("no_pendulum", "ground"),
                                                ("single_block", "gravity")])
def test_mjcf_text_is_unchanged(scene_name, motion):
    scene = load_scene(scene_name)
    s = MujocoSettings(base_motion=motion)
    assert mjcf(scene, s, 10.0) == mujoco_world.mjcf(scene, s, 10.0)


# A free-rocking release (a tilt, no pulse) and a one-sine run, in both engines.
RUNS = [
    ("free", dict(theta0=0.05, t_max=0.6, early_stop=False), Pulse(0.0, 9.0)),
    ("sine", dict(t_max=0.6), Pulse(6.0, 9.0)),
]


@pytest.mark.parametrize("label, options, pulse", RUNS, ids=[r[0] for r in RUNS])
@pytest.mark.parametrize("new, old, settings", [(PymunkEngine, LegacyPymunk, PymunkSettings),
                                                (MujocoEngine, LegacyMujoco, MujocoSettings)],
                         ids=["pymunk", "mujoco"])
def test_trajectory_is_bit_identical(fig5, label, options, pulse, new, old, settings):
    s = settings(**options)
    a, b = new.simulate(fig5, pulse, s), old.simulate(fig5, pulse, s)
    assert a.max_abs_theta > 1e-3  # it rocked: the comparison is not of two still frames
    _same(a, b)


def test_overturn_is_seen_the_same(fig5):
    # A pulse that overturns (fig5 at Omega 9 overturns well above 10 m/s^2 in the
    # model): the diagnostics and the monitor must see the same event at the same time.
    s = PymunkSettings(verdict_only=True)
    a, b = PymunkEngine.simulate(fig5, Pulse(25.0, 9.0), s), LegacyPymunk.simulate(
        fig5, Pulse(25.0, 9.0), s)
    assert a.verdict.status in ("overturned", "collapsed")
    _same(a, b)
