"""``trilith restitution`` on a scene the model does not cover: free rocking from a
tilt, each engine's measured velocity ratio per impact, the engines against each
other; no Eq. 19/20."""
from __future__ import annotations

import json

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.compare.measure.restitution_kinds import impact_ratios


def test_block_on_block_gives_each_engines_ratios_and_their_median(capsys):
    assert main(["restitution", "--scene", "block_on_block", "--engine", "pymunk,mujoco",
                 "--n-impacts", "2", "--json", "--no-cache"]) == 0
    doc = json.loads(capsys.readouterr().out)
    body = doc.get("result", doc)
    assert body["kind"] == "block_on_block" and body["model"] is None
    for e in ("pymunk", "mujoco"):
        r = body["engines"][e]
        assert r["body"] == "lower" and len(r["impacts"]) == 2
        # a rocking impact loses energy and keeps the sense of rotation
        assert all(0.0 < i["ratio"] < 1.0 for i in r["impacts"])
        rot = r["max_rotation"]
        assert r["as_one"] == (abs(rot["upper"] - rot["lower"]) <= 0.05 * rot["lower"])
    for k, p in enumerate(body["impacts"]):
        ratios = [body["engines"][e]["impacts"][k]["ratio"] for e in ("pymunk", "mujoco")]
        assert p["median"] == pytest.approx(sum(ratios) / 2)  # two engines: the mean
    assert main(["restitution", "--scene", "block_on_block", "--engine", "pymunk,mujoco",
                 "--n-impacts", "1", "--no-cache"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("scene block_on_block (block_on_block): no model (no Eq. 19/20)")
    assert "the ratio is of lower" in out


def test_the_ratio_is_read_at_the_zero_crossing_not_at_the_window():
    # A synthetic impact at t = 1 s: theta_dot -1 + 2 (t - 1) before it (gravity
    # slows it), then 0.8 times that after; the reading at the window edge would
    # be off by 2 x 1e-3 / 1 = 0.2 %, the extrapolation hits the exact ratio.
    import numpy as np
    t = np.arange(0.9, 1.1, 1e-5)
    theta_dot = np.where(t < 1.0, -1.0 + 2.0 * (t - 1.0), -0.8 + 2.0 * (t - 1.0))
    theta = np.where(t < 1.0, -(t - 1.0) + (t - 1.0) ** 2, -0.8 * (t - 1.0) + (t - 1.0) ** 2)
    (row,) = impact_ratios(t, theta, theta_dot, [1.0 + 2e-4], window=1e-3)
    assert row["t"] == pytest.approx(1.0, abs=1e-5)
    assert row["ratio"] == pytest.approx(0.8, rel=1e-6)


@pytest.mark.parametrize("scene, extra, text", [
    ("drums", ["--engine", "pymunk"], "--engine: there is no Eq. 19/20 for the drums kind"),
    ("unequal", ["--engine", "pymunk,mujoco"], "the unequal kind has no free-rocking release"),
    ("drums", ["--engine", "pymunk,mujoco", "--theta0", "0.3"], "--theta0 must satisfy"),
    ("drums", ["--engine", "pymunk,mujoco", "--psi0", "0.1"], "--psi0: the drums kind"),
    ("block_on_block", ["--engine", "pymunk,mujoco", "--restitution-factor", "0.9"],
     "--restitution-factor: there is no model"),
])
def test_restitution_on_a_kind_refuses_bad_input_before_work(scene, extra, text, capsys,
                                                             no_work):
    assert main(["restitution", "--scene", scene, *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and text in err
