"""Scene files of the other kinds (analytic.kinds): drums, unequal columns, a block
on a block.  The shipped examples load and stand; one drum is the parametric
trilith bit for bit; a geometry that cannot stand is refused at the door with one
line naming the field."""
from __future__ import annotations

import math

import numpy as np
import pytest

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.analytic.kinds import (DRUM_COUNT, MAX_WIDENING, BlockOnBlock, Drums,
                                         Unequal)
from trilith_xval.analytic.parameters import Scene
from trilith_xval.compare.cli.main import main
from trilith_xval.engines import geometry
from trilith_xval.engines.pymunk_ import PymunkEngine, Settings
from trilith_xval.scenes import SCENE_DIR, load_scene

EXAMPLES = {"drums": Drums, "unequal": Unequal, "block_on_block": BlockOnBlock}


def _write(tmp_path, body: str, name: str = "mine"):
    path = tmp_path / f"{name}.toml"
    path.write_text(f"# test scene\n[scene]\n{body}\n")
    return path


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_shipped_example_loads_as_its_kind_and_stands(name):
    scene = load_scene(name)
    assert isinstance(scene, EXAMPLES[name]) and scene.name == name
    assert f'kind = "{name}"' in (SCENE_DIR / f"{name}.toml").read_text()
    st = geometry.structure_of(scene)
    assert st.kind == name and not st.is_trilith
    # Every body rests on the ground or on another body, and the boxes are the layout's.
    held = {upper for upper, _ in st.supports}
    assert held == {box.name for box in st.bodies}
    for box, rect in zip(st.bodies, scene.layout()):
        assert (box.b, box.h, box.upright, box.mass) == (rect.b, rect.h, (rect.x, rect.y),
                                                         rect.mass)
        # Stone: the mass is the density times the body's volume (rounding only); a
        # lintel's is mu times a column's.
        if box.name != "lintel":
            assert box.mass == pytest.approx(2500.0 * box.b * box.h * scene.depth, rel=1e-12)


def test_drums_stack_on_each_other_and_carry_the_lintel():
    scene = load_scene("drums")
    st = geometry.structure_of(scene)
    n = len(scene.heights)
    for side in ("left", "right"):
        assert (f"column_{side}_0", "ground") in st.supports
        for i in range(1, n):
            assert (f"column_{side}_{i}", f"column_{side}_{i - 1}") in st.supports
        assert ("lintel", f"column_{side}_{n - 1}") in st.supports
    lintel = st.body("lintel")
    # The lintel's underside is the columns' top, the sum of the drum heights.
    assert lintel.upright[1] - 0.5 * lintel.h == pytest.approx(sum(scene.heights), abs=1e-12)


def test_one_drum_is_the_parametric_trilith_bit_for_bit(tmp_path):
    # The same numbers as a trilith file giving h: the same Scene, structure and run.
    common = "b = 0.6\nmu = 1.0\ngamma = 0.3"
    drum = load_scene(_write(tmp_path, f'kind = "drums"\nheights = [3.0]\n{common}', "one"))
    trilith = load_scene(_write(tmp_path, f"h = 3.0\n{common}", "one_trilith"))
    assert isinstance(drum, Scene)
    assert drum == trilith.replace(name="one")
    assert geometry.structure_of(drum) == geometry.structure_of(trilith)
    s, pulse = Settings(t_max=0.5), Pulse(6.0, 9.0)
    a, b = PymunkEngine.simulate(drum, pulse, s), PymunkEngine.simulate(trilith, pulse, s)
    assert a.max_abs_theta > 1e-3  # it rocked
    for field in ("t", "theta", "theta_dot", "psi", "psi_dot"):
        assert np.array_equal(getattr(a, field), getattr(b, field))
    assert a.verdict == b.verdict


# (file body, the field the one-line message must name first).
BAD = [
    ('kind = "drums"\nheights = [1.0, 1.0, 1.0, 1.0, 1.0]', "heights"),
    ('kind = "drums"\nheights = []', "heights"),
    ('kind = "drums"\nheights = [1.0, 0.0]', "heights[1]"),
    ('kind = "drums"\nheights = [1.0, -2.0]', "heights[1]"),
    ('kind = "drums"\nb = 0.6\nheights = [1.5, 1.5]\nwidths = [0.6, 0.7]', "widths[1]"),
    ('kind = "drums"\nb = 0.6\nheights = [1.5, 1.5]\nwidths = [0.6, 0.62]\nmu = 0.0\ngap = 0.0',
     "gap"),
    ('kind = "drums"\nb = 0.6\nheights = [1.5, 1.5]\nwidths = [0.6, 0.62]', "widths[1]"),
    ('kind = "unequal"\nleft_h = 3.0\nright_h = 2.5', "right_h"),
    ('kind = "unequal"\nleft_b = 0.6\nright_b = 0.8\ngap = 3.0\nlintel_length = 4.0',
     "lintel_length"),
    ('kind = "unequal"\nleft_b = 0.0', "left_b"),
    ('kind = "block_on_block"\nlower_b = 0.8\noffset = 0.4', "offset"),
    ('kind = "block_on_block"\nupper_h = -1.0', "upper_h"),
    ('kind = "block_on_block"\nlam = 3.0', "unknown key 'lam'"),
    ('kind = "pyramid"', "kind must be one of"),
]


@pytest.mark.parametrize("body, field", BAD, ids=[f"{i}-{f}" for i, (_, f) in enumerate(BAD)])
def test_a_geometry_that_cannot_stand_is_refused_in_one_line(tmp_path, body, field):
    path = _write(tmp_path, body)
    with pytest.raises(ValueError) as info:
        load_scene(path)
    message = str(info.value)
    assert len(message.splitlines()) == 1
    assert message.startswith(f"{path}: {field}"), message


def test_allowed_ranges_are_named():
    lo, hi = DRUM_COUNT
    with pytest.raises(ValueError, match=rf"{lo} to {hi} drums"):
        Drums(heights=(1.0,) * (hi + 1))
    # Exactly at the allowed widening it stands (the limit itself is allowed).
    ok = Drums(b=0.6, heights=(1.5, 1.5), widths=(0.6, 0.6 * (1 + MAX_WIDENING)), mu=0.0)
    assert ok.drum_widths[1] > ok.drum_widths[0]
    with pytest.raises(ValueError, match=r"offset must be in \(-0\.4, 0\.4\)"):
        BlockOnBlock(lower_b=0.8, offset=-0.4)
    # The offset's limit is the lower block's top face: just inside it stands.
    assert BlockOnBlock(lower_b=0.8, offset=0.399).offset == 0.399


def test_tapering_drums_share_the_column_mass_by_volume():
    scene = Drums(b=0.6, heights=(1.0, 2.0), widths=(0.6, 0.5), column_mass=1000.0, mu=0.5)
    left = [r for r in scene.layout() if r.name.startswith("column_left")]
    assert sum(r.mass for r in left) == pytest.approx(1000.0, rel=1e-12)
    assert left[1].mass / left[0].mass == pytest.approx(2.0 * 0.5 / 0.6, rel=1e-12)
    lintel = scene.layout()[-1]
    assert lintel.mass == pytest.approx(500.0, rel=1e-12)  # mu times the column mass
    assert scene.alpha == pytest.approx(math.atan2(0.5, 2.0), rel=1e-15)


def test_cli_refuses_a_bad_scene_with_exit_2_and_one_line(tmp_path, capsys, no_work):
    path = _write(tmp_path, 'kind = "drums"\nheights = [1.0, 1.0, 1.0, 1.0, 1.0]')
    code = main(["simulate", "--scene", str(path), "--engine", "pymunk", "--amplitude", "5",
                 "--omega", "8"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1 and "heights" in err, err
