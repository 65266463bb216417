"""The calibration design: seeded, inside its ranges, each scene at its own band;
its ranges are a domain the shipped calibration reader accepts."""
from __future__ import annotations

import pytest

from trilith_xval.compare.campaign.design import RANGES, design_scenes, domain_table, scene_omegas
from trilith_xval.compare.cli.main import main
from trilith_xval.engines.calibration import Domain, scene_coordinates


def test_the_design_is_seeded_and_inside_its_ranges():
    a, b = design_scenes(8, 34), design_scenes(8, 34)
    assert [s.to_dict() for s in a] == [s.to_dict() for s in b]
    held = design_scenes(6, 35)
    assert not {(s.lam, s.b) for s in a} & {(s.lam, s.b) for s in held}
    domain = Domain.from_table(domain_table(), "design")
    for sc in a + held:
        c = scene_coordinates(sc)
        for key, (lo, hi) in RANGES.items():
            # 4-decimal rounding of the sampled sizes: 1e-3 relative slack.
            assert lo * (1 - 1e-3) <= c[key] <= hi * (1 + 1e-3), key
    from trilith_xval.scenes import load_scene
    assert domain.outside(load_scene("fig5")) is None  # the paper's trilith is inside
    assert "outside" in domain.outside(load_scene("fig5").replace(lam=8.0))


def test_frequencies_follow_the_scene():
    small, large = design_scenes(8, 34)[6], design_scenes(8, 34)[4]  # b 0.25 m vs 0.8 m
    assert min(scene_omegas(small)) > min(scene_omegas(large))
    assert len(scene_omegas(small)) == 4


@pytest.mark.parametrize("argv, word", [
    (["--design", "8"], "--design must be N,M"),
    (["--design", "0,3"], "--design: N and M"),
    (["--design", "4,2", "--scene", "fig5"], "--design: the design gives the scenes"),
    (["--seed", "3"], "--seed: only with --design"),
    (["--design", "4,2", "--metric", "restitution"], "--design: only for --metric thresholds"),
])
def test_bad_design_options_are_refused_at_the_door(argv, word, capsys):
    assert main(["calibrate", "--engine", "pymunk", *argv]) == 2
    err = capsys.readouterr().err
    assert word in err and err.count("\n") == 1
