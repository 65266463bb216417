"""A small campaign result built in about a second, for tests of the report's
writing and rendering (the real campaign takes 20 s to minutes).

Time histories are real analytic runs at the paper's points A and B; the
"engines" are those runs shifted by a few milliseconds (so their error panels
show something).  Restitution, spectra and timings are made-up numbers with
the campaign's structure, including a failing threshold point that carries the
newer ``cause``/``cause_detail``/``convergence`` fields.  Verdicts are computed
from them by :func:`compare.campaign.verdicts.build_verdicts`, as in a real campaign.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from trilith_xval.analytic.excitation import Pulse
from trilith_xval.compare.measure import trajectories as metrics
from trilith_xval.compare.campaign.validation import CampaignConfig, CampaignResult
from trilith_xval.compare.campaign.verdicts import build_verdicts
from trilith_xval.scenes import POINTS, load_scene

ENGINES = ("pybullet", "pymunk")
SHIFT = {"pybullet": 0.004, "pymunk": -0.0002}  # s: the fake engines' time offsets


def _shifted(traj, name: str):
    dt = SHIFT[name]
    theta = np.interp(traj.t - dt, traj.t, traj.theta)
    psi = np.interp(traj.t - dt, traj.t, traj.psi)
    cpu = 0.4 if name == "pymunk" else 1.1
    return dataclasses.replace(traj, backend=name, theta=theta, psi=psi,
                               settings={"dt": 1e-4}, wall_time=cpu,
                               diagnostics={**(traj.diagnostics or {}), "cpu_time": cpu})


def _threshold(omega, a_ref, err, mode="after-impact", **extra):
    return {"omega": omega, "kind": "sine", "a_reference": a_ref, "a_engine": a_ref * (1 + err),
            "a_survives": a_ref * (1 + err - 0.002), "mode_reference": mode, "mode_engine": mode,
            "n_runs": 7, "irregular_runs": 0, "rel_tol": 0.002, "rel_error": err,
            "bracketed": True, "cpu_s": 3.0,
            "provenance": {"backend": "x", "version": "x", "dt": 1e-4, "settings": {},
                           "wall_time": 3.0}, **extra}


def _spectrum(scale: float, jump_at: float) -> dict:
    omega = np.arange(4.5, 27.0, 0.5)
    a = scale * (1.0 + 0.12 * (omega - 4.5)) ** 1.6
    a[omega > jump_at] *= 1.3
    mode = ["no-impact" if w > jump_at else "after-impact" for w in omega]
    i = int(np.searchsorted(omega, jump_at))
    jump = {"omega_lo": float(omega[i - 1]), "omega_hi": float(omega[i]),
            "omega": float(0.5 * (omega[i - 1] + omega[i])), "a_lo": float(a[i - 1]),
            "a_hi": float(a[i]), "mode_lo": mode[i - 1], "mode_hi": mode[i], "rel_step": 0.3}
    return {"omega": omega.tolist(), "a": a.tolist(), "mode": mode, "jumps": [jump],
            "jump": None, "backend": "analytic-fast", "tol": 0.01}


@functools.lru_cache(maxsize=1)
def synthetic_result() -> CampaignResult:
    """The small campaign result (cached: treat as read-only)."""
    from trilith_xval.engines import get_backend

    config = CampaignConfig(engines=ENGINES, points=("A", "B"), workers=1)
    scene = load_scene("fig5")
    scenes = {True: scene, False: scene.without_pendulum()}
    analytic = get_backend("analytic")
    result = CampaignResult(config=config, scene=scene,
                            settings={"analytic": {"rtol": 1e-10},
                                      "pybullet": {"dt": 1e-4, "solver_iterations": 50},
                                      "pymunk": {"dt": 1e-4, "iterations": 30}},
                            versions={"analytic": "analytic-scipy", "pybullet": "pybullet 3",
                                      "pymunk": "pymunk 7"})
    for point in config.points:
        for pend, sc in scenes.items():
            ref = analytic.simulate(sc, Pulse(*POINTS[point]), analytic.Settings())
            result.histories[(point, pend, "analytic")] = ref
            for name in ENGINES:
                traj = _shifted(ref, name)
                result.histories[(point, pend, name)] = traj
                comp = metrics.compare_trajectories(ref, traj, sc.alpha)
                result.comparisons.append({"point": point, "pendulum": pend, "backend": name,
                                           **comp.to_dict()})
    for name, errs in (("pybullet", (0.0012, -0.006)), ("pymunk", (0.0006, 0.0004))):
        for lam, err in zip((3.0, 5.0), errs):
            impacts = [{"t": 0.5 * k, "side": (-1) ** k, "psi": 0.0, "measured": 0.8 * (1 + e),
                        "predicted": 0.8, "rel_error": e} for k, e in
                       enumerate((err / 2, err, -err / 3), start=1)]
            result.restitution.append({"backend": name, "pendulum": lam == 5.0, "lam": lam,
                                       "mu": 1.0, "gamma": 0.3 if lam == 5.0 else 0.0,
                                       "equation": "Eq. 19" if lam == 5.0 else "Eq. 20",
                                       "impacts": impacts, "max_rel_error": abs(err)})
    result.spectra = {"pendulum": _spectrum(5.0, 10.2), "no_pendulum": _spectrum(3.0, 17.7)}
    conv = [{"dt": dt, "a_engine": 60.0, "rel_error": e}
            for dt, e in ((1e-4, -0.066), (5e-5, -0.064), (2.5e-5, -0.065))]
    result.spectra["no_pendulum"]["engines"] = {
        "pybullet": [_threshold(8.0, 9.0, 0.001, cause="agrees"),
                     _threshold(14.0, 25.0, -0.004, cause="agrees"),
                     _threshold(21.0, 60.0, -0.066, cause="contact",
                                cause_detail="columns slide at the base", convergence=conv)],
        "pymunk": [_threshold(8.0, 9.0, 0.0), _threshold(14.0, 25.0, 0.002),
                   _threshold(21.0, 60.0, 0.012)]}
    result.spectra["pendulum"]["engines"] = {
        "pybullet": [_threshold(13.0, 30.0, 0.003, mode="no-impact")],
        "pymunk": [_threshold(13.0, 30.0, -0.001, mode="no-impact")]}
    result.verdicts = build_verdicts(result)
    result.timings = {"reference_spectra": 17.3, "engine_runs_wall": 67.1, "total": 87.4,
                      "cpu_by_job": {"threshold:pybullet": 40.4, "history:pymunk": 4.3}}
    return result
