"""Why PyBullet got *worse* as its step shrank: a dt sweep.

Not part of ``make bench`` (a study, ~5 min on one core)::

    python -m benchmarks.pybullet_small_step            # both parts
    python -m benchmarks.pybullet_small_step --quick    # part 1 at dt 1e-4 and 2.5e-5 only

Part 1 runs every case at ``dt`` in {1e-4, 5e-5, 2.5e-5} s with the harness's
per-step solver settings as they were (``old``: ``frictionERP`` 0.2 and
``solverResidualThreshold`` 1e-7 (m/s)^2 at every step) and as they are now
(``new``: both scaled below 1e-4 s, ``engines.pybullet_.world``).  Part 2 changes
one suspect at a time at dt = 2.5e-5 s.  Cases:

* where the analytic model is valid: the Fig. 5 trilith at 0.97 and 1.03 of the
  analytic threshold at Omega = 12 rad/s (pendulum, A* = 19.95 m/s^2) and
  Omega = 16 rad/s (no pendulum, A* = 18.93 m/s^2), and free rocking from
  alpha/2 (lam 3, 5, 7, mu 1, no pendulum; restitution vs Eq. 20, 4 impacts);
* where the failures were first seen: Omega = 24 rad/s, A = 55, 60, 64 m/s^2 with
  the pendulum, and ``lam = 30``, A = 19 m/s^2, Omega = 15 rad/s.

Each run records the verdict, max |theta| / alpha, the world's diagnostics
(``pivot_sliding_max``, ``penetration_max``, ``column_mismatch_max``,
``lintel_rotation_max``, ``out_of_plane_rotation_max``) and, read from the
contacts at every sample, when the lintel first loses its seat: the sum of the
column-top normal forces on it below 1 % of the lintel + bob weight
(``lintel_lift_t``; the analytic model assumes it never does), and the pivot
sliding up to that moment (``slide_before_lift``), both while the trilith
stands (no column past alpha yet).  An undecided run stops 5 s after the pulse
(the monitor's ``t_cap``; 60 s by default): parted columns may otherwise rest
tilted for the whole minute.
"""
from __future__ import annotations

import argparse
import math
import sys
import time

from trilith_xval.engines._quiet_pybullet import pybullet as pb

from trilith_xval import engines
from trilith_xval.analytic.excitation import Pulse
from trilith_xval.compare.run.jsonable import plain
from trilith_xval.compare.measure.restitution import measure_restitution
from trilith_xval.engines.pybullet_ import PyBulletEngine
from trilith_xval.scenes import load_scene

from . import machine, write

DTS = (1e-4, 5e-5, 2.5e-5)
T_CAP = 5.0  # s after the pulse before a run ends 'undecided' (the monitor's default: 60 s)
LIFT = 0.01  # lintel seat force / (lintel + bob weight) counted as lifted
OLD = {"friction_erp": 0.2, "solver_residual_threshold": 1e-7}  # before the fix, any dt
NEW: dict = {}  # the defaults
# Analytic thresholds (analytic.spectrum.first_overturn_amplitude, fig5 scene).
A_STAR = {(12.0, True): 19.948, (16.0, False): 18.932}


class LiftRun(PyBulletEngine):
    """A PyBullet run that also reads the lintel's seat force at every sample."""

    def build(self):
        super().build()
        sc = self.scene
        self.weight = (sc.m3 + (sc.m4 if sc.has_pendulum else 0.0)) * sc.g
        self.lift = dict(lintel_lift_t=math.nan, slide_before_lift=0.0, seat_force_min=math.inf)

    def read(self):
        state = super().read()
        d, b = self.lift, self.bodies
        if b.lintel is not None and self.diagnostics.standing and math.isnan(d["lintel_lift_t"]):
            force = sum(p[9] for col in b.columns
                        for p in pb.getContactPoints(b.lintel, col, physicsClientId=self.client))
            d["slide_before_lift"] = self.diagnostics.values["pivot_sliding_max"]
            if self.step_index > 0:  # no contact exists before the first step
                d["seat_force_min"] = min(d["seat_force_min"], force / self.weight)
                if force < LIFT * self.weight:
                    d["lintel_lift_t"] = self.step_index * self.settings.dt
        return state


def pulse_run(scene, pulse, dt: float, settings: dict) -> dict:
    s = engines.configure("pybullet", dt=dt, monitor={"t_cap": T_CAP}, **settings)
    run = LiftRun(scene, pulse, s)
    tr = run.run()
    d = {**tr.diagnostics, **run.lift}
    keys = ("pivot_sliding_max", "penetration_max", "column_mismatch_max",
            "lintel_rotation_max", "out_of_plane_rotation_max", "lintel_lift_t",
            "slide_before_lift", "seat_force_min")
    return {"status": tr.verdict.status, "t_verdict": tr.verdict.time,
            "max_theta_over_alpha": float(max(abs(tr.theta))) / scene.alpha,
            **{k: float(d[k]) for k in keys}, "wall_s": tr.wall_time}


def restitution_run(scene, dt: float, settings: dict) -> dict:
    r = measure_restitution("pybullet", scene, dt=dt, **settings)
    return {"status": r.status, "n_impacts": r.n_impacts,
            "rel_errors": [i.rel_error for i in r.impacts],
            "max_abs_rel_error": r.max_rel_error,
            "pivot_sliding_max": r.diagnostics["pivot_sliding_max"],
            "column_mismatch_max": r.diagnostics["column_mismatch_max"], "wall_s": r.wall_time}


def cases() -> dict:
    fig5 = load_scene("fig5")
    bare = fig5.without_pendulum()
    out = {}
    for (omega, pend), a_star in A_STAR.items():
        sc = fig5 if pend else bare
        tag = "pend" if pend else "nopend"
        for f in (0.97, 1.03):
            out[f"valid W{omega:g} {tag} {f:.2f}A*"] = ("pulse", sc, Pulse(f * a_star, omega))
    for lam in (3.0, 5.0, 7.0):
        out[f"valid free lam{lam:g}"] = ("free", bare.replace(lam=lam), None)
    for a in (55.0, 60.0, 64.0):
        out[f"fail W24 A{a:g} pend"] = ("pulse", fig5, Pulse(a, 24.0))
    out["fail lam30 W15 A19 pend"] = ("pulse", fig5.replace(lam=30.0), Pulse(19.0, 15.0))
    return out


def run_case(kind, scene, pulse, dt, settings) -> dict:
    return (restitution_run(scene, dt, settings) if kind == "free"
            else pulse_run(scene, pulse, dt, settings))


def _line(name, variant, dt, r) -> str:
    if "rel_errors" in r:
        errs = " ".join(f"{100 * e:+.2f}" for e in r["rel_errors"])
        return (f"{name:28} {variant:24} {dt:7.1e}  {r['status']:10} restitution % [{errs}] "
                f"slide {r['pivot_sliding_max']:.1e} mism {r['column_mismatch_max']:.1e}")
    tv = "" if r["t_verdict"] is None else f"{r['t_verdict']:.3f}"
    return (f"{name:28} {variant:24} {dt:7.1e}  {r['status']:10} t {tv:6} "
            f"max|th|/a {r['max_theta_over_alpha']:6.3f} slide {r['pivot_sliding_max']:.1e} "
            f"pen {r['penetration_max']:.1e} mism {r['column_mismatch_max']:.1e} "
            f"lrot {r['lintel_rotation_max']:.1e} oop_rot {r['out_of_plane_rotation_max']:.1e} "
            f"lift_t {r['lintel_lift_t']:.3f} slide<lift {r['slide_before_lift']:.1e}")


# Part 2: one suspect at a time at dt = 2.5e-5 s (name -> settings).
SUSPECTS = {
    "old + residual ~ dt^2": {"friction_erp": 0.2},
    "old + frictionERP ~ dt": {"solver_residual_threshold": 1e-7},
    "new, slop 1e-4 fixed": {"contact_slop": 1e-4},
    "new, 100 iterations": {"solver_iterations": 100},
    "new, breaking 0.02 m": {"contact_breaking_threshold": 0.02},
    "new, contact_erp 0.05": {"contact_erp": 0.05},
    "new, no friction anchor": {"friction_anchor": False},
}
PART2_CASES = ("valid W16 nopend 0.97A*", "valid free lam3", "fail W24 A60 pend")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="part 1 at dt 1e-4 and 2.5e-5 only")
    args = ap.parse_args(argv)
    info = machine()
    t0 = time.perf_counter()
    rows = []
    all_cases = cases()
    dts = (DTS[0], DTS[-1]) if args.quick else DTS
    for name, (kind, scene, pulse) in all_cases.items():
        for variant, settings in (("old", OLD), ("new", NEW)):
            for dt in dts:
                if variant == "new" and dt >= 1e-4:
                    continue  # identical to 'old' at the calibrated step (bit for bit)
                r = run_case(kind, scene, pulse, dt, settings)
                rows.append({"part": 1, "case": name, "variant": variant, "dt": dt, **r})
                print(_line(name, variant, dt, r), flush=True)
    if not args.quick:
        for name in PART2_CASES:
            kind, scene, pulse = all_cases[name]
            for variant, settings in SUSPECTS.items():
                r = run_case(kind, scene, pulse, DTS[-1], settings)
                rows.append({"part": 2, "case": name, "variant": variant, "dt": DTS[-1], **r})
                print(_line(name, variant, DTS[-1], r), flush=True)
    path = write("pybullet_small_step", plain({
        "machine": info, "engine_version": PyBulletEngine.version(), "t_cap": T_CAP,
        "lift_fraction": LIFT, "old": OLD, "rows": rows,
        "wall_s": time.perf_counter() - t0}))
    print(f"{time.perf_counter() - t0:.0f} s; wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
