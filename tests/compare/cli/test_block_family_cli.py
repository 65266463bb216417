"""The rocking block family through the commands: listed by ``trilith scenes``,
run by simulate (model and an engine), spectrum, map and restitution, selected by
a glob."""
from __future__ import annotations

import json
import math

import pytest

from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import load_scene

FAMILY = ("block_lam1.5", "block_lam2", "block_lam3", "block_lam5", "block_lam8",
          "block_lam10")


def _json(argv, capsys) -> dict:
    assert main(argv) == 0, argv
    return json.loads(capsys.readouterr().out)


def test_scenes_lists_the_family_and_a_glob_selects_it(capsys):
    shown = _json(["scenes", "--scene", "block_lam*", "--json"], capsys)["scenes"]
    assert sorted(s["name"] for s in shown) == sorted(FAMILY)
    assert all(s["mu"] == 0.0 and s["gamma"] == 0.0 and s["b"] == 0.6 for s in shown)


@pytest.mark.parametrize("name", FAMILY)
@pytest.mark.parametrize("engine", ["analytic", "analytic-fast"])
def test_simulate_runs_every_block(name, engine, capsys):
    s = load_scene(name)
    a = 1.5 * s.g * math.tan(s.alpha)  # well above uplift (Eq. 11)
    doc = _json(["simulate", "--scene", name, "--engine", engine, "-A", f"{a:.6g}", "-w",
                 "6", "--json"], capsys)
    assert doc["inputs"]["scene"]["lam"] == s.lam
    assert doc["status"] in ("overturned", "survived")
    assert doc["uplift_time"] is not None


def test_an_engine_runs_a_block(capsys):
    doc = _json(["simulate", "--scene", "block_lam3", "--engine", "pymunk", "-A", "5", "-w",
                 "6", "--json"], capsys)
    assert doc["status"] in ("overturned", "survived")


def test_spectrum_map_and_restitution_take_the_family(capsys):
    spec = _json(["spectrum", "--scene", "block_lam10", "--omega", "3,6", "--workers", "1",
                  "--no-cache", "--json"], capsys)
    assert "a_pendulum" not in spec  # no pendulum: one curve, no gain
    assert all(a > 9.81 / 10 for a in spec["a_no_pendulum"])  # above uplift, g/lam
    maps = _json(["map", "--scene", "block_lam1.5", "--omega", "4:6:1", "--amplitude",
                  "5:15:5", "--workers", "1", "--json"], capsys)["maps"]
    assert len(maps) == 1
    res = _json(["restitution", "--scene", "block_lam2", "--engine", "analytic",
                 "--n-impacts", "2", "--no-cache", "--json"], capsys)
    housner = 1.0 - 1.5 * math.sin(load_scene("block_lam2").alpha) ** 2
    assert [i["predicted"] for i in res["impacts"]] == pytest.approx([housner] * 2, rel=1e-12)
