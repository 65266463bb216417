"""``trilith record`` on a scene of another kind: every body drawn from each
engine's own poses, panels side by side on one time base; the model refused."""
from __future__ import annotations

import numpy as np
import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.show.draw import COLORS


def _stone_columns(frame: np.ndarray) -> np.ndarray:
    """Pixel columns of ``frame`` holding the bodies' colour.  Tolerance 12 per
    channel: the GIF's 128-colour palette keeps a colour that fills this much
    of every frame to a few units."""
    stone = np.array([int(COLORS["column"][i:i + 2], 16) for i in (1, 3, 5)])
    return np.nonzero(np.all(np.abs(frame.astype(int) - stone) <= 12, axis=2).any(axis=0))[0]


def test_record_block_on_block_shows_both_engines(tmp_path, capsys):
    from PIL import Image
    out = tmp_path / "b.gif"
    assert main(["record", "--scene", "block_on_block", "--engine", "pymunk,mujoco", "-A", "12",
                 "-w", "8", "--out", str(out), "--width", "160", "--height", "120",
                 "--fps", "10"]) == 0
    said = capsys.readouterr().out
    # 12 m/s^2 at 8 rad/s overturns the upper block in every engine (docs/geometry.md).
    assert "pymunk: overturned" in said and "mujoco: overturned" in said
    with Image.open(out) as gif:
        n = gif.n_frames
        assert n > 5
        for k in (0, n // 2, n - 1):
            gif.seek(k)
            frame = np.asarray(gif.convert("RGB"))
            assert frame.shape == (120, 320, 3)
            cols = _stone_columns(frame)
            # Stone in both panels (left half: pymunk, right half: mujoco).
            assert (cols < 160).any() and (cols >= 160).any()


def test_outlines_of_the_upright_structure_are_its_rest_boxes():
    from trilith_xval.compare.show.kind_record import structure_outlines
    from trilith_xval.engines.geometry import structure_of
    from trilith_xval.scenes import load_scene
    st = structure_of(load_scene("drums"))
    pose = np.array([[*box.upright, 0.0] for box in st.bodies])
    boxes, hinge, bob = structure_outlines(st, pose, 0.0, ground_x=0.3)
    for box, outline in zip(st.bodies, boxes):
        x, y = box.upright
        assert np.allclose(outline[0], [x - 0.3 - box.b / 2, y - box.h / 2])
        assert np.allclose(outline[2], [x - 0.3 + box.b / 2, y + box.h / 2])
    assert hinge is None and bob is None  # the shipped drums have no pendulum


@pytest.mark.parametrize("command", ["record", "view"])
@pytest.mark.parametrize("engine", [None, "analytic,pymunk"])
def test_the_model_is_refused_on_a_kind(command, engine, capsys, no_work, tmp_path):
    extra = ["--out", str(tmp_path / "x.gif")] if command == "record" else []
    given = [] if engine is None else ["--engine", engine]
    assert main([command, "--scene", "block_on_block", "-A", "5", "-w", "8", *given,
                 *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "no model of the block_on_block kind" in err
