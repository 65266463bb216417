"""The three metrics of ``trilith calibrate`` on a parametric trilith
(:mod:`compare.campaign.calibrate`): each returns a candidate's ``(errors, engine
CPU s, simulated s, runs)`` on one scene against the model.

``restitution``: free rocking, the first impacts' velocity ratios against Eq. 19/20;
``thresholds``: the first-overturning amplitudes against the model's spectrum;
``histories``: theta(t) before the first impact at the paper's points A-D.
Each takes the candidate's run and ``vs``, the validation set
(:class:`compare.campaign.calibrate.ValidationSet`; not imported here, as
calibrate imports this module).
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # annotations only
    from trilith_xval.compare.run.spec import RunSpec

__all__ = ["restitution", "thresholds", "histories"]


def restitution(run: RunSpec, vs, rf: float = 1.0):
    from trilith_xval.compare.measure.restitution import free_rocking
    scene = run.scene
    cases = [(f"lam {lam:g} mu {mu:g}", scene.without_pendulum().replace(lam=lam, mu=mu))
             for lam, mu in vs.releases]
    if scene.has_pendulum:
        cases.append((f"lam {scene.lam:g} mu {scene.mu:g} gamma {scene.gamma:g}", scene))
    errors, engine_cpu, simulated, runs = [], 0.0, 0.0, 0
    for label, sc in cases:
        r = free_rocking(run.at(scene=sc), n_impacts=vs.n_impacts, restitution_factor=rf)
        errors.append((label, r.max_rel_error if r.complete else math.nan))
        engine_cpu += r.diagnostics["cpu_time"]
        simulated += r.diagnostics["steps"] * r.settings["dt"]
        runs += 1
    return errors, engine_cpu, simulated, runs


def thresholds(run: RunSpec, reference, workers):
    from trilith_xval.compare.measure.engine_spectrum import engine_spectrum
    es = engine_spectrum(run, reference, workers=workers)
    errors, engine_cpu, simulated, runs = [], 0.0, 0.0, 0
    for curve, points in es.curves.items():
        for p in points:
            runs += p.n_runs
            engine_cpu += p.point.cpu_s  # the candidate's own search, not the step rule's
            if math.isfinite(p.point.sim_s):  # NaN: served by the store (bypassed here)
                simulated += p.point.sim_s
            # The model cannot judge the engine there (named only after the step
            # rule found no finer step that agrees).
            if p.cause == "model":
                continue
            errors.append((f"{curve} Omega {p.omega:g}", abs(p.rel_error)))
    return errors, engine_cpu, simulated, runs


def histories(run: RunSpec, vs, rf: float = 1.0):
    from trilith_xval import engines
    from trilith_xval.compare.measure.trajectories import compare_trajectories
    from trilith_xval.scenes import point_pulse
    scene = run.scene
    errors, engine_cpu, simulated, runs = [], 0.0, 0.0, 0
    for sc in (scene, scene.without_pendulum()) if scene.has_pendulum else (scene,):
        for point in vs.points:
            pulse = point_pulse(point)
            model = {} if rf == 1.0 else {"restitution_factor": rf}
            ref = engines.simulate("analytic", sc, pulse, **model)
            test = engines.simulate(run.backend, sc, pulse, run.at(sc, pulse).settings)
            c = compare_trajectories(ref, test)
            err = c.theta_rms_first if c.verdict_agrees else 1.0
            label = f"{point} {'pendulum' if sc.has_pendulum else 'no pendulum'}"
            errors.append((label, err))
            engine_cpu += test.diagnostics["cpu_time"]
            simulated += test.diagnostics["steps"] * test.settings["dt"]
            runs += 1
    return errors, engine_cpu, simulated, runs
