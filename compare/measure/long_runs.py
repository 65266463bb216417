"""Long runs: every backend over the same fixed window, no early stop.

A threshold probe stops as soon as its verdict is certain, and a time history at
the end of the pulse plus a rest hold; neither shows what an engine does to a
frame left standing for tens of seconds: pivots that creep, a frame that drifts
after a pulse.  A long run fixes ``t_max`` and turns ``early_stop`` off, so every
backend covers the same window and the monitor still calls a collapse.

Pass rule: the run ends with the model's verdict (its status over the same
window) and its pivots slid less than :data:`MAX_CREEP` [m].
"""
from __future__ import annotations

import math

__all__ = ["LONG_RUNS", "LONG_T_MAX", "MAX_CREEP", "long_run", "long_run_excitation"]

# (label, scene, amplitude [m/s^2], omega [rad/s]): the trilith at rest, and the
# README's Fig. 8 record (lam 3, gamma 0.1) after a 19 m/s^2, 15 rad/s pulse.
LONG_RUNS = (("rest", "fig5", 0.0, 0.0),
             ("after pulse", "fig8_lam3_gamma0.1", 19.0, 15.0))
LONG_T_MAX = 20.0  # s: ~30 rocking periods of the Fig. 8 frame's small swings after the pulse
# 1 mm: a tenth of the monitor's collapse limit (pivot sliding 0.01 b = 6 mm at b = 0.6 m).
MAX_CREEP = 1e-3


def long_run_excitation(amplitude: float, omega: float):
    """The ground motion of a long run: a sine pulse, or none (:class:`Still`) at
    zero amplitude."""
    from trilith_xval.analytic.excitation import Pulse, Still
    return Pulse(amplitude, omega) if amplitude > 0.0 else Still()


def long_run(run, label: str, scene_name: str, t_max: float = LONG_T_MAX) -> dict:
    """One fixed-window run of ``run`` (a :class:`compare.run.spec.RunSpec` on the
    scene named ``scene_name``, under :func:`long_run_excitation`) and of the
    model; the row of the trust table's long-run line
    (:class:`compare.campaign.summary.LongRun`)."""
    from trilith_xval.engines import configure
    from trilith_xval.compare.run import runs
    backend, scene, exc = run.backend, run.scene, run.excitation
    s = run.with_options("the long run's window", t_max=t_max, early_stop=False).settings
    tr = runs.simulate(backend, scene, exc, s)
    # The scipy path: the compiled one always stops once its verdict is certain.
    model = runs.simulate("analytic", scene, exc,
                          configure("analytic", t_max=t_max, early_stop=False))
    amplitude, omega = float(getattr(exc, "amplitude", 0.0)), float(getattr(exc, "omega", 0.0))
    slide = tr.diagnostics.get("pivot_sliding_max")
    slide = float(slide) if slide is not None else math.nan
    passed = tr.verdict.status == model.verdict.status and slide < MAX_CREEP
    detail = (f"{tr.verdict.status} at {tr.t[-1]:.3g} s of {t_max:g} s (model: "
              f"{model.verdict.status}); pivots slid {slide:.3g} m")
    if tr.verdict.status == "collapsed":
        detail += f" ({tr.verdict.reason})"
    cpu = tr.diagnostics.get("cpu_time")
    return {"backend": backend, "case": label, "scene": scene_name, "amplitude": amplitude,
            "omega": omega, "t_max": t_max, "t_end": float(tr.t[-1]) if len(tr.t) else 0.0,
            "status": tr.verdict.status, "model_status": model.verdict.status,
            "pivot_sliding": slide,
            "theta_final": float(tr.theta[-1]) if len(tr.theta) else None,
            "psi_final": float(tr.psi[-1]) if len(tr.psi) else None,
            "cpu_s": float(cpu) if cpu is not None else None,
            "cpu_per_sim_s": (float(cpu) / float(tr.t[-1])
                              if cpu is not None and len(tr.t) and tr.t[-1] > 0 else None),
            "passed": bool(passed), "detail": detail}
