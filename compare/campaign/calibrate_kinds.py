"""``trilith calibrate`` on a scene the model does not cover (:mod:`analytic.kinds`):
an engine's step against its own reference step (self-convergence).

There is no model threshold to agree with, so the ``thresholds`` metric's target
is the engine's own: at each pulse frequency its first *failing* amplitude (an
overturn or a collapse, :mod:`engines.structure_monitor`) at the reference step
``dt_ref`` (the finest step asked, or the engine's reference step), found as
``trilith spectrum --consensus`` finds it without a model: a scan from the
structure's static uplift bound (:func:`compare.measure.kind_scan.scan_guess`),
then the one robust bracket (:func:`compare.measure.thresholds.engine_threshold`
with :data:`compare.measure.consensus.FAILURE_SEARCH`).  A candidate's error at a
frequency is ``|A_candidate - A_ref| / A_ref``, its bracket centred on ``A_ref``.

This measures how far a cheaper step moves the engine from itself, never how
close either is to the truth or to another engine (``trilith spectrum
--consensus`` does that).  The ``restitution`` and ``histories`` metrics have no
target on another kind (no Eq. 19/20, no model theta) and are refused.
"""
from __future__ import annotations

import math

__all__ = ["scene_kind", "kind_reference", "own_reference", "self_thresholds"]


def scene_kind(scenes) -> str:
    """The one kind of ``scenes`` ('trilith' for parametric triliths); ValueError
    naming ``scene`` when they mix kinds (a calibration holds over one domain)."""
    kinds = sorted({getattr(sc, "kind", "trilith") for sc in scenes})
    if len(kinds) > 1:
        raise ValueError(f"scene: one calibration holds over one kind of scene, got "
                         f"{', '.join(kinds)}; calibrate each kind apart")
    return kinds[0]


def kind_reference(scene_runs, omegas, dt_ref: float | None, reference: dict) -> dict:
    """The engine's own reference thresholds (:func:`own_reference`) of each
    ``(scene, run)`` pair of ``scene_runs`` into ``reference`` (by ``id`` of the
    scene), at ``dt_ref`` [s] (None: the engine's reference step); returns what the
    calibration reports: ``dt_ref`` and per scene name the thresholds by frequency."""
    from trilith_xval.engines.calibration import reference_dt
    dt_ref = float(dt_ref) if dt_ref is not None else reference_dt(scene_runs[0][1].backend)
    for sc, run in scene_runs:
        reference[id(sc)] = own_reference(run, omegas, dt_ref)
    return {"dt_ref": dt_ref, "thresholds": {
        sc.name: {str(w): r for w, r in reference[id(sc)].items()} for sc, _ in scene_runs}}


def own_reference(run, omegas, dt_ref: float) -> dict:
    """``{omega: row}``: ``run``'s engine's own first failing amplitude on its scene
    at each of ``omegas`` [rad/s] at the step ``dt_ref`` [s] (module docstring).
    ``row``: ``a_fails``, ``a_survives`` [m/s^2] (None without a bracket),
    ``failure``, ``guess`` (the scan's), ``n_runs``, ``cpu_s``.  Memoised whole
    in the run store."""
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict, settings_dict
    ref = run.with_options("the reference step", dt=dt_ref)
    what = {"backend": ref.backend, "scene": scene_dict(ref.scene),
            "settings": settings_dict(ref.settings), "omegas": [float(w) for w in omegas]}
    rows = runs.memo("kind-calibration-reference", what, lambda: _reference(ref, omegas),
                     label=f"own reference {ref.backend} {ref.scene.name}", code=runs.ALL_CODE)
    return {float(w): row for w, row in zip(omegas, rows)}


def _reference(ref, omegas) -> list[dict]:
    from trilith_xval.compare.measure.kind_scan import scan_guess
    from trilith_xval.compare.measure.consensus import FAILURE_SEARCH, _failing_status
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.thresholds import engine_threshold
    out = []
    for w in omegas:
        guess, n = scan_guess(ref, float(w), "sine")
        if guess is None:
            out.append({"a_fails": None, "a_survives": None, "failure": None, "guess": None,
                        "n_runs": n, "cpu_s": None})
            continue
        spec = point_spec(ref, ref.scene, float(w), guess, "sine", FAILURE_SEARCH)
        p = engine_threshold(spec.backend, spec.scene, float(w), guess, spec.settings,
                             search=FAILURE_SEARCH)
        out.append({"a_fails": p.a_engine if p.bracketed else None,
                    "a_survives": p.a_survives if p.bracketed else None,
                    "failure": _failing_status(p), "guess": guess, "n_runs": n + p.n_runs,
                    "cpu_s": p.cpu_s})
    return out


def self_thresholds(run, reference: dict):
    """A candidate's ``(errors, engine CPU s, simulated s, runs)`` against the
    engine's own ``reference`` (:func:`own_reference`): per frequency the relative
    difference of its first failing amplitude from the reference's (NaN: no
    bracket; a frequency whose reference found no failure is not counted)."""
    from trilith_xval.compare.measure.consensus import FAILURE_SEARCH
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.thresholds import engine_threshold
    errors, engine_cpu, simulated, n = [], 0.0, 0.0, 0
    for w, ref in reference.items():
        a_ref = ref["a_fails"]
        if a_ref is None:
            continue
        spec = point_spec(run, run.scene, w, a_ref, "sine", FAILURE_SEARCH)
        p = engine_threshold(spec.backend, spec.scene, w, a_ref, spec.settings,
                             search=FAILURE_SEARCH)
        n += p.n_runs
        engine_cpu += p.cpu_s
        if math.isfinite(p.sim_s):
            simulated += p.sim_s
        error = abs(p.a_engine - a_ref) / a_ref if p.bracketed else math.nan
        errors.append((f"Omega {w:g} (own dt_ref)", error))
    return errors, engine_cpu, simulated, n
