"""The model's validity along a threshold curve: does the analytic model hold on
the run that decides each point of an overturning spectrum (Section 5.2, Fig. 5)?

The model (Eq. 1, 8, A.1) keeps the columns on their pivot corners and the
lintel on the column tops without any force enforcing it.  At high amplitude
and frequency it predicts motions in which the ground would have to pull the
columns down (they would hop) or the column tops would have to pull the lintel
(it would be thrown off, e.g. A = 74.9 m/s^2 = 7.6 g at Omega = 26 rad/s =
4.1 Hz on the Fig. 5 trilith).  A threshold read there is the model's number,
not a property of a trilith, and no engine may be blamed for missing it.

Each point is checked on one accurate run (:func:`analytic.simulate.simulate`)
at the curve's first-overturning amplitude, the run whose verdict the threshold
reports: its contact forces (:func:`analytic.reactions.validity_diagnostics`,
judged by :func:`analytic.contact_forces.violations`, as
:func:`analytic.reactions.check_model` does) and, with a pendulum, the bob's
clearance from the columns (:func:`analytic.clearance.check_clearance`).  Only
the normal forces and the clearance decide validity here (a pull is invalid for
every friction coefficient); the friction demands are returned for a caller
who knows a coefficient.
"""
from __future__ import annotations

import math

import numpy as np

from ._workers import map_measured
from .clearance import check_clearance
from .contact_forces import violations
from .parameters import Scene

__all__ = ["point_validity", "curve_validity", "spectrum_validity", "invalid_spans",
           "VALIDITY_FIELDS"]

# The per-point fields, in CSV column order.
VALIDITY_FIELDS = ("model_valid", "ground_min_normal", "lintel_min_normal",
                   "ground_max_friction", "lintel_max_friction", "bob_min_clearance",
                   "model_reason")


def point_validity(scene: Scene, amplitude: float, omega: float, kind: str = "sine",
                   restitution_factor: float = 1.0) -> dict:
    """The model's contact checks on the run at ``amplitude`` [m/s^2] and
    ``omega`` [rad/s] of a one-sine (Eq. 22) or one-cosine (Eq. 23) pulse, with
    the impacts scaled by ``restitution_factor`` (Eq. 19/20 times it; 1 = exact)
    as in the threshold's own search.

    Returns
    -------
    dict
        :data:`VALIDITY_FIELDS`: ``model_valid`` (True: no pull at the ground
        or at the column tops; None when ``amplitude`` is not finite, e.g. no
        overturning up to the search's ``a_max``), ``ground_min_normal``
        (fraction of the total weight), ``lintel_min_normal`` (fraction of the
        lintel and bob's weight; None without them), the two friction demands
        ``|F_x|/F_y``, ``bob_min_clearance`` [m] (distance of the bob from the
        nearer inner column face, < 0 inside it; None without a pendulum) and
        ``model_reason`` (the violated assumptions in words, "" when valid).
    """
    if amplitude is None or not math.isfinite(amplitude):
        return {k: None for k in VALIDITY_FIELDS[:-1]} | {"model_reason": ""}
    from .pulses import pulse_of
    from .simulate import simulate  # simulate imports the contact checks

    from .events import Settings
    settings = None if restitution_factor == 1.0 else Settings(
        restitution_factor=restitution_factor)
    tr = simulate(scene, pulse_of(kind, float(amplitude), float(omega)), settings)
    d = tr.diagnostics
    if "model_valid" not in d:  # non-finite samples: nothing to judge
        return {k: None for k in VALIDITY_FIELDS[:-1]} | {
            "model_reason": f"the model run ended {tr.verdict.status!r} (not checked)"}
    reasons = violations(d)
    clear = check_clearance(scene, tr)
    if not clear["valid"]:
        reasons.append(clear["reason"])
    return {"model_valid": not reasons, "ground_min_normal": d["min_vertical_reaction"],
            "lintel_min_normal": d["min_lintel_normal"],
            "ground_max_friction": d["max_friction_demand"],
            "lintel_max_friction": d["max_lintel_friction_demand"],
            "bob_min_clearance": clear["min_clearance"], "model_reason": "; ".join(reasons)}


def _job_validity(job: tuple) -> dict:
    return point_validity(*job)


def _many_validity(jobs: list[tuple], workers: int) -> list[dict]:
    """:func:`point_validity` of every ``(scene, amplitude, omega, kind)``, in
    order; the checked ones in one :func:`analytic._workers.map_measured`."""
    from . import simulate  # noqa: F401 - loaded once here, inherited by forked workers

    todo = [k for k, job in enumerate(jobs) if math.isfinite(job[1])]
    out: list = [point_validity(jobs[0][0], math.nan, 0.0)] * len(jobs) if jobs else []
    for k, res in zip(todo, map_measured(_job_validity, [jobs[k] for k in todo], workers)):
        out[k] = res
    return out


def _jobs(scene: Scene, omegas, amplitudes, kind: str, rf: float = 1.0) -> list[tuple]:
    w = [float(x) for x in np.atleast_1d(omegas)]
    a = [math.nan if x is None else float(x) for x in np.atleast_1d(amplitudes)]
    if len(w) != len(a):
        raise ValueError(f"omegas and amplitudes must have equal lengths, got {len(w)} "
                         f"and {len(a)}")
    return [(scene, a[i], w[i], kind, rf) for i in range(len(w))]


def _check_workers(workers) -> None:
    if not (isinstance(workers, int) and 1 <= workers <= 256):
        raise ValueError(f"workers must be an integer in [1, 256], got {workers!r}")


def curve_validity(scene: Scene, omegas, amplitudes, kind: str = "sine",
                   workers: int = 1, restitution_factor: float = 1.0) -> list[dict]:
    """:func:`point_validity` at every ``(amplitudes[i], omegas[i])``, in order.

    Parameters
    ----------
    scene : Scene
        The curve's scene (with or without its pendulum).
    omegas, amplitudes : array_like
        Equal lengths; amplitudes [m/s^2] may be NaN/None (point left unchecked).
    kind : {'sine', 'cosine'}
    workers : int
        The most forked processes, in [1, 256] (one accurate run per point,
        ~0.05-0.5 s): :func:`analytic._workers.map_measured` runs the first
        point here and starts the workers the rest is worth.
    """
    jobs = _jobs(scene, omegas, amplitudes, kind, restitution_factor)
    _check_workers(workers)
    return _many_validity(jobs, workers)


def spectrum_validity(spectrum, workers: int = 1) -> dict[str, list[dict]]:
    """Every curve of an :class:`analytic.spectrum.Spectrum` (``spectrum.curves``):
    ``{"no_pendulum": [...], "pendulum": [...]}``, or only ``"no_pendulum"`` for a
    scene without a pendulum; one :func:`point_validity` per frequency, each
    checked on its own scene (the no-pendulum curve on
    ``scene.without_pendulum()``); both curves share one set of workers."""
    _check_workers(workers)
    sc, kind = spectrum.scene, spectrum.settings.pulse
    rf = spectrum.settings.fast.restitution_factor  # the model the thresholds came from
    jobs = _jobs(sc.without_pendulum(), spectrum.omega, spectrum.a_no_pendulum, kind, rf)
    if sc.gamma != 0.0:
        jobs += _jobs(sc, spectrum.omega, spectrum.a_pendulum, kind, rf)
    checked = _many_validity(jobs, workers)
    n = len(spectrum.omega)
    out = {"no_pendulum": checked[:n]}
    if sc.gamma != 0.0:
        out["pendulum"] = checked[n:]
    return out


def invalid_spans(omegas, valid, step: float | None = None) -> list[tuple[float, float]]:
    """Frequency intervals [rad/s] to shade where ``valid`` is False: each run
    of invalid points widened by half a grid step either side (the boundary
    lies somewhere between an invalid point and its valid neighbour).
    ``step`` defaults to the smallest spacing of ``omegas``."""
    w = np.asarray(omegas, dtype=float)
    if w.size == 0:
        return []
    if step is None:
        step = float(np.min(np.diff(np.sort(w)))) if w.size > 1 else 0.5
    bad = [v is False for v in valid]
    spans, start = [], None
    for i, b in enumerate(bad + [False]):
        if b and start is None:
            start = i
        elif not b and start is not None:
            spans.append((float(w[start] - step / 2), float(w[i - 1] + step / 2)))
            start = None
    return spans
