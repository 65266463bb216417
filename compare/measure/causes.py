"""Why an engine's threshold disagrees with the model: every candidate cause is
evaluated, and one primary is chosen by a stated rule.

Candidates (all evaluated; ``causes`` lists every one that applies):

``model``
    the model's own assumptions fail at the *decisive* amplitude, the lower of
    the model's threshold and the amplitude where the engine departs from it
    (its robust first overturn, or its first collapse below that): a negative
    normal force at the ground or the lintel-column contacts, a friction demand
    above the engine's coefficient (:func:`analytic.bounds.check_model`), or
    the bob meeting a column (:func:`analytic.clearance.check_clearance`).
    Validity is also checked at both ends of the engine's bracket; a failure
    only above the decisive amplitude is reported in ``validity``, not blamed.
``collapse``
    the engine's frame collapsed (columns out of step, a pivot slid, the lintel
    turned: no longer the model's mechanism) below its first overturn, where
    the model holds; the diagnostic farthest beyond its noise level is named.
``no-bracket``
    no robust first overturn within the widened bracket.
``window``
    the engine overturns above the model, and in between the model survives
    again (an overturning window then a safe island, Zhang and Makris 2001).
``jump``
    a mode jump of the model lies within ``JUMP_REL`` of the frequency (located
    on the model's own threshold curve, never inferred from the frequency grid)
    and the engine's threshold lies between the jump's levels.
``discretisation``
    the robust threshold at ``dt/2`` and ``dt/4`` meets the tolerance.
``iterations``
    the robust threshold with doubled solver iterations at the same step meets it.
``contact``
    the error shrinks neither with the step nor with the iterations (the
    diagnostic farthest beyond its noise level is named).
``sensitivity``
    a perturbation of :data:`compare.measure.thresholds.PERTURBATIONS` flipped a
    verdict at the bracket's ends (``isolated`` overturns, or ``flips``: e.g. a
    tilted twin that collapsed).

Primary rule: the first applying cause in :data:`PRIMARY_ORDER`: the model before
any engine (no engine is blamed where the model is invalid), then a collapse of
the engine's frame (it explains a missing bracket), then what makes the
comparison itself ill-posed (no bracket, window, jump), then the engine's
numerics from the cheapest remedy (step, iterations) to none (contact), then
sensitivity; ``unknown`` when none applies.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from trilith_xval.engines import configure, supports

from trilith_xval.compare.measure.threshold_point import ThresholdPoint
from trilith_xval.compare.measure.thresholds import SEARCH, Search, engine_threshold

__all__ = ["Classification", "classify", "model_validity", "model_jump", "model_island",
           "explain_isolated", "sensitivity_detail", "PRIMARY_ORDER", "JUMP_REL"]

PRIMARY_ORDER = ("model", "collapse", "no-bracket", "window", "jump", "discretisation",
                 "iterations", "contact", "sensitivity")
# Frequency neighbourhood searched for a jump of the model, relative: 2.5 % is
# 0.25 rad/s at Omega 10, eight times PyBullet's measured shift of Fig. 5's
# Omega_1 jump (-0.03 rad/s) and far below the model's jump spacing (~7 rad/s).
JUMP_REL = 0.025


@dataclass(frozen=True)
class Classification:
    """``cause`` (primary), ``detail`` (its evidence), ``causes`` (every applying
    one: dicts name/detail), ``valid`` (the model at the decisive amplitude),
    ``validity`` (every amplitude checked) and ``convergence`` (rerun rows:
    kind 'dt' or 'iterations', dt, iterations, a_engine, a_survives, rel_error)."""

    cause: str
    detail: str
    causes: tuple = ()
    valid: bool | None = None
    validity: tuple = ()
    convergence: tuple = ()


def model_validity(scene, omega: float, kind: str, amplitudes: dict, friction) -> list[dict]:
    """The model's validity at each ``{where: amplitude}``: contact forces and
    friction (:func:`analytic.bounds.check_model`) and the bob's clearance."""
    from trilith_xval.analytic.clearance import check_clearance
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.analytic.bounds import check_model
    from trilith_xval.analytic.simulate import simulate
    out, seen = [], {}
    for where, a in amplitudes.items():
        if not (a is not None and math.isfinite(a)):
            continue
        if a in seen:  # the same amplitude under another name: one model run
            out.append({**seen[a], "where": where})
            continue
        pulse = pulse_of(kind, float(a), omega)
        forces = check_model(scene, pulse, friction=friction)
        reasons = [forces["reason"]] if not forces["valid"] else []
        if scene.has_pendulum:
            clear = check_clearance(scene, simulate(scene, pulse))
            if not clear["valid"]:
                reasons.append(clear["reason"])
        out.append({"amplitude": float(a), "where": where, "valid": not reasons,
                    "reason": "; ".join(reasons)})
        seen[a] = out[-1]
    return out


def _model_threshold(scene, omega, kind):
    from trilith_xval.analytic.first_overturn import first_overturn_amplitude
    from trilith_xval.analytic.spectrum import SpectrumSettings
    a, _, mode, _, _ = first_overturn_amplitude(scene, omega, SpectrumSettings(pulse=kind))
    return a, mode


def model_jump(scene, omega: float, kind: str, a_engine: float, tol: float) -> str | None:
    """A mode jump of the model within ``omega (1 +/- JUMP_REL)`` whose levels
    enclose ``a_engine`` (within ``tol``): where, located by bisection on the
    model to ``JUMP_REL omega / 16``; None otherwise, and for the pulse shapes the
    compiled search does not cover (Ricker, M-P: only sine and cosine)."""
    if not _compiled(kind):
        return None
    w = [omega * (1.0 - JUMP_REL), omega, omega * (1.0 + JUMP_REL)]
    th = [_model_threshold(scene, x, kind) for x in w]
    levels = [a for a, _ in th if math.isfinite(a)]
    for (w0, (a0, m0)), (w1, (a1, m1)) in zip(zip(w, th), zip(w[1:], th[1:])):
        if m0 == m1 and math.isfinite(a0) == math.isfinite(a1):
            continue
        if not levels or not (min(levels) * (1 - tol) <= a_engine <= max(levels) * (1 + tol)):
            return None
        for _ in range(4):
            mid = 0.5 * (w0 + w1)
            if _model_threshold(scene, mid, kind)[1] == m0:
                w0 = mid
            else:
                w1 = mid
        return (f"the model's overturning mode changes from {m0} to {m1} at Omega = "
                f"{0.5 * (w0 + w1):.4g} rad/s (+/- {0.5 * (w1 - w0):.2g}; located on the model), "
                f"within {100 * JUMP_REL:g} % of {omega:g}; its thresholds there span "
                f"{min(levels):.4g}-{max(levels):.4g} m/s^2")
    return None


def model_island(scene, omega, point: ThresholdPoint, kind, n: int = 40) -> str | None:
    """Where the engine's threshold is above the model's: does the model survive
    somewhere in between (a safe island)?  ``n`` compiled verdicts (~0.1 ms each)
    resolve islands down to ``(a_engine - a_reference) / n``; None for the shapes
    the compiled kernels do not cover (Ricker, M-P)."""
    from trilith_xval.analytic import fast
    from trilith_xval.analytic.excitation import Pulse
    if not _compiled(kind):
        return None
    lo, hi = point.a_reference, point.a_engine
    if not hi > lo:
        return None
    safe = [a for a in np.linspace(lo, hi, n + 1)[1:-1]
            if not fast.verdict_for(scene, Pulse(float(a), omega, kind)).overturned]
    if not safe:
        return None
    return (f"the model overturns in a window from A = {lo:.4g} m/s^2 and survives again at "
            f"{min(safe):.4g}-{max(safe):.4g} m/s^2 (a safe island); the engine's "
            f"first overturn {hi:.4g} is the next onset")


def _compiled(kind) -> bool:
    """True for the shapes of the compiled model (one-sine, one-cosine)."""
    from trilith_xval.analytic.excitation import PULSE_KINDS
    return isinstance(kind, str) and kind in PULSE_KINDS


def _iterations(settings) -> int | None:
    return getattr(settings, "solver_iterations", None)


def _row(kind, settings, p: ThresholdPoint) -> dict:
    return {"kind": kind, "dt": settings.dt, "iterations": _iterations(settings),
            "a_engine": p.a_engine, "a_survives": p.a_survives, "rel_error": p.rel_error,
            "n_isolated": len(p.isolated), "cpu_s": p.cpu_s}


def convergence_rows(engine, scene, omega, point: ThresholdPoint, settings, kind,
                     search: Search) -> list[dict]:
    """The robust threshold at dt, dt/2, dt/4 (kind 'dt') and with doubled solver
    iterations at dt (kind 'iterations', when the engine has them)."""
    rows = [_row("dt", settings, point)]
    for factor in (2, 4):
        finer = configure(engine, settings, dt=settings.dt / factor)
        rows.append(_row("dt", finer, engine_threshold(
            engine, scene, omega, point.a_reference, finer, kind=kind, search=search)))
    if supports(engine, "solver_iterations"):
        more = settings.with_solver_iterations(2 * _iterations(settings))
        rows.append(_row("iterations", more, engine_threshold(
            engine, scene, omega, point.a_reference, more, kind=kind, search=search)))
    return rows


# Noise levels of the engines' contact diagnostics while the model is valid
# (fig5 points A-D, both engines, docs/engine-trust.md): sliding < 1e-5 m,
# penetration < 1e-4 m, lintel rotation and column mismatch < 1e-5 rad.
_NOISE = {"pivot_sliding_max": 1e-5, "penetration_max": 1e-4, "lintel_rotation_max": 1e-5,
          "column_mismatch_max": 1e-5}


def contact_detail(engine, scene, omega, amplitude, settings, kind) -> str:
    """The diagnostic farthest beyond its noise level in a run at ``amplitude``
    (and the verdict's own reason when that run collapsed)."""
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.compare.run import runs
    tr = runs.simulate(engine, scene, pulse_of(kind, amplitude, omega),
                       configure(engine, settings, verdict_only=True))
    ratios = {k: (tr.diagnostics.get(k) or 0.0) / n for k, n in _NOISE.items()}
    key = max(ratios, key=ratios.get)
    what = (f"at A = {amplitude:.4g} the run {tr.verdict.status}"
            + (f" ({tr.verdict.reason})" if tr.verdict.status == "collapsed" else ""))
    return (f"{what}; {key} = {tr.diagnostics.get(key) or 0.0:.3g} ({ratios[key]:.3g}x its "
            f"noise level)")


def explain_isolated(engine, scene, omega, iso: dict, settings, kind) -> str:
    """What made an isolated overturn: the impact of a full run at its amplitude
    (same perturbation) whose restitution is farthest off Eq. 19/20."""
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.compare.measure.restitution import restitution_from_trajectory
    from trilith_xval.compare.measure.thresholds import TILT
    from trilith_xval.compare.run import runs
    extra = {"theta0": TILT} if iso.get("perturbation") == "tilt" else {}
    run = configure(engine, settings, verdict_only=False, **extra)
    tr = runs.simulate(engine, scene, pulse_of(kind, iso["amplitude"], omega), run)
    rows = [r for r in restitution_from_trajectory(tr, scene) if math.isfinite(r.rel_error)]
    if not rows:
        return f"full run {tr.verdict.status}; no impact measured before it"
    worst = max(rows, key=lambda r: abs(r.rel_error))
    eq = "Eq. 19" if scene.has_pendulum else "Eq. 20"
    return (f"full run {tr.verdict.status}; impact at t = {worst.t:.3g} s is "
            f"{100 * worst.rel_error:+.2g} % off {eq} (worst of {len(rows)})")


def sensitivity_detail(point: ThresholdPoint) -> str:
    """The isolated overturns and the perturbed runs that flipped an end's verdict."""
    parts = []
    if point.isolated:
        parts.append(f"{len(point.isolated)} isolated overturn(s) at A = "
                     + ", ".join(f"{i['amplitude']:.6g}" for i in point.isolated))
    if point.flips:
        parts.append("perturbed runs at the ends: " + ", ".join(
            f"{p.perturbation} at {p.amplitude:.6g} {p.status}" for p in point.flips))
    return "; ".join(parts)


def _depart(point: ThresholdPoint) -> float:
    """Where the engine leaves the model: its first overturn or first collapse."""
    collapsed = [p.amplitude for p in point.probes
                 if p.status == "collapsed" and not p.perturbation]
    cands = [a for a in (point.a_engine, *collapsed) if math.isfinite(a)]
    return min(cands) if cands else math.nan


def classify(engine: str, scene, omega: float, point: ThresholdPoint, settings, *,
             kind: str = "sine", tol: float = 0.02, search: Search = SEARCH,
             convergence: bool = True) -> Classification:
    """Every applying cause of a disagreement and the primary one (module docstring).

    ``convergence`` False skips the step and iteration reruns (then neither
    'discretisation' nor 'iterations' nor the no-convergence 'contact' can apply).
    """
    depart = _depart(point)
    decisive = min(point.a_reference, depart) if math.isfinite(depart) else point.a_reference
    validity = model_validity(scene, omega, kind,
                              {"decisive": decisive, "model threshold": point.a_reference,
                               "engine survives": point.a_survives,
                               "engine overturns": point.a_engine}, settings.friction)
    valid = validity[0]["valid"]
    causes: dict[str, str] = {}
    if not valid:
        causes["model"] = f"at A = {decisive:.4g} m/s^2: {validity[0]['reason']}"
    if not point.bracketed:
        causes["no-bracket"] = "no robust overturning amplitude within the widened bracket"
    else:
        island = model_island(scene, omega, point, kind)
        if island:
            causes["window"] = island
        jump = model_jump(scene, omega, kind, point.a_engine, tol)
        if jump:
            causes["jump"] = jump
    if point.isolated or point.flips:
        causes["sensitivity"] = sensitivity_detail(point)
    collapsed = [p.amplitude for p in point.probes if p.status == "collapsed"
                 and not p.perturbation and p.amplitude < (point.a_engine if point.bracketed
                                                           else math.inf)]
    if collapsed and valid:
        causes["collapse"] = ("the engine's frame collapsed (not overturned) where the model "
                              "holds; " + contact_detail(engine, scene, omega, min(collapsed),
                                                         settings, kind))
    rows: tuple = ()
    if convergence and point.bracketed and abs(point.rel_error) > tol:
        rows = tuple(convergence_rows(engine, scene, omega, point, settings, kind, search))
        dts = [r for r in rows if r["kind"] == "dt"]
        steps = ", ".join(f"{100 * r['rel_error']:+.2g} %" for r in dts)
        finer = next((dts[k]["dt"] for k in (1, 2)
                      if all(abs(r["rel_error"]) <= tol for r in dts[k:])), None)
        if finer is not None:
            causes["discretisation"] = (f"robust error {steps} at dt, dt/2, dt/4; dt <= "
                                        f"{finer:.3g} s meets {100 * tol:g} %")
        more = [r for r in rows if r["kind"] == "iterations"]
        if more and abs(more[0]["rel_error"]) <= tol:
            causes["iterations"] = (f"{more[0]['iterations']} solver iterations at dt: "
                                    f"{100 * more[0]['rel_error']:+.2g} %, meets "
                                    f"{100 * tol:g} %")
        if finer is None and not (more and abs(more[0]["rel_error"]) <= tol):
            causes["contact"] = (f"robust error {steps} at dt, dt/2, dt/4 does not meet "
                                 f"{100 * tol:g} %; " + contact_detail(
                                     engine, scene, omega, point.a_engine, settings, kind))
    primary = next((c for c in PRIMARY_ORDER if c in causes), "unknown")
    if primary == "sensitivity" and point.bracketed and abs(point.rel_error) <= tol:
        primary = "unknown"  # agreeing point: the caller labels it; sensitivity stays listed
    return Classification(primary, causes.get(primary, "none of the candidate causes applies"),
                          tuple({"name": k, "detail": v} for k, v in causes.items()), valid,
                          tuple(validity), rows)
