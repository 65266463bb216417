"""Your own trilith from Python: a squat stone frame under a one-sine pulse.

Run: .venv/bin/python docs/examples/own_scene.py
"""
from trilith_xval.analytic import Pulse, Scene
from trilith_xval import engines

# Columns 0.4 m wide, lam = h/b = 4, lintel mass ratio 1.5, pendulum mass ratio 0.2 of a column.
scene = Scene(b=0.4, lam=4.0, mu=1.5, gamma=0.2, name="my_frame")
print(f"alpha = {scene.alpha:.4f} rad, uplift needs about g*tan(alpha) = "
      f"{scene.g * scene.b / scene.h:.2f} m/s^2")
for amplitude in (2.0, 3.0, 15.0):
    traj = engines.simulate("analytic", scene, Pulse(amplitude, omega=10.0))
    v = traj.verdict
    print(f"A = {amplitude:4.1f} m/s^2: {v.status} ({v.mode or '-'}), impacts {traj.n_impacts}, "
          f"max |theta| = {traj.max_abs_theta:.3f} rad")
