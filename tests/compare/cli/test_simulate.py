"""``trilith simulate`` prints and writes the events of the shared rule with their resolution."""
from __future__ import annotations

import json
import re

from trilith_xval.compare.cli.main import main


def test_simulate_prints_rule_events_with_resolution(capsys):
    assert main(["simulate", "-A", "25", "-w", "11"]) == 0  # point D: overturns, no impact
    out = capsys.readouterr().out
    up = re.search(r"uplift \(\|theta\| = 0.0001 rad\): (\S+) s \+- (\S+) s", out)
    over = re.search(r"past alpha for good \(exceeds_alpha_time\) at (\S+) s \+- (\S+) s", out)
    assert up and over, out
    # The model's 1 ms samples bound both times to a millisecond.
    assert 0.0 < float(up.group(2)) <= 1e-3 and float(over.group(2)) <= 1e-3
    assert "impacts (theta = 0 crossed faster than 0.01 rad/s): 0" in out
    assert "model's exact events: lift-off 0.0082 s" in out  # Eq. 9's root, kept apart


def test_simulate_json_has_rule_times_and_the_verdict_time(capsys):
    assert main(["simulate", "-A", "25", "-w", "11", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["uplift_time"] - doc["uplift_resolution"] <= 0.0262
    # Past alpha for good, then the topple angle: two times, two names.
    assert 0.0 <= doc["exceeds_alpha_time"] < doc["overturn_time"] == doc["verdict_time"]
    assert 0.0 <= doc["exceeds_alpha_resolution"] <= 1e-3
    assert doc["sampled_events"]["rule"] == {"uplift_angle": 1e-4, "impact_speed": 1e-2}
    assert doc["n_impacts"] == doc["sampled_events"]["n_impacts"] == 0


def test_overturn_time_is_one_quantity_in_json_python_and_record(capsys, tmp_path):
    """`overturn_time` names the verdict's time in simulate --json, in Python's
    Trajectory and in record's line; the last rise past alpha has its own name."""
    from trilith_xval import engines
    from trilith_xval.scenes import load_scene, point_pulse

    traj = engines.simulate("analytic", load_scene("fig5"), point_pulse("D"))
    assert main(["simulate", "-A", "25", "-w", "11", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["overturn_time"] == traj.overturn_time == traj.verdict.time
    assert doc["exceeds_alpha_time"] == traj.sampled_events().exceeds_alpha.t
    assert "overturn" not in doc["sampled_events"]  # its last rise is 'exceeds_alpha'
    assert doc["sampled_events"]["exceeds_alpha"]["t"] == doc["exceeds_alpha_time"]
    assert main(["simulate", "-A", "25", "-w", "11"]) == 0
    assert f"overturn_time = {traj.overturn_time:.4f} s" in capsys.readouterr().out
    assert main(["record", "-A", "25", "-w", "11", "--duration", "2", "--width", "64",
                 "--height", "64", "--out", str(tmp_path / "d.gif")]) == 0
    assert f"analytic: overturned, overturn_time = {traj.overturn_time:.3f} s" in \
        capsys.readouterr().out
