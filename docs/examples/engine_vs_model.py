"""One engine against the model: the paper's point A, theta(t) error and restitution.

Run: .venv/bin/python docs/examples/engine_vs_model.py [ENGINE]   (default pymunk)
"""
import sys

from trilith_xval import engines
from trilith_xval.compare.measure.trajectories import compare_trajectories
from trilith_xval.compare.measure.restitution import measure_restitution
from trilith_xval.scenes import load_scene, point_pulse

engine = sys.argv[1] if len(sys.argv) > 1 else "pymunk"
scene = load_scene("fig5")
model = engines.simulate("analytic", scene, point_pulse("A"))
run = engines.simulate(engine, scene, point_pulse("A"))
cmp = compare_trajectories(model, run, scene.alpha)
print(f"{engine} at point A: {run.verdict.status} (model: {model.verdict.status}); "
      f"theta RMS error before the first impact = {cmp.theta_rms_first:.2e} alpha")
res = measure_restitution(engine, scene.without_pendulum(), n_impacts=3)
print(f"restitution vs {res.equation}: worst impact {100 * res.max_rel_error:.3f} %")
