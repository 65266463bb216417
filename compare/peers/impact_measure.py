"""A first measurement: the measured rocking impacts of a square block against
Housner's ratio and against engines replaying each measured pre-impact state.

:func:`measure` reads a user's copy of the drop files (:mod:`.impact_data`),
keeps the rocking-like impacts, replays each in every engine of
:data:`.impact_replay.ENGINES` at the :data:`FRICTIONS` and returns the per-impact
rows; :func:`summarise` turns rows into the stated numbers.  The stored document
(``docs/validation/impact_measurement.json``, written by
``benchmarks/impact_measurement.py``) holds both, so its summary can be checked
against its own rows.
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from . import impact_data as data
from . import impact_replay as replay

__all__ = ["FRICTIONS", "DATA_SOURCE", "measure", "summarise", "files_digest", "engine_key",
           "estimator_sensitivity"]

# The project's engines' default (no sliding: Housner's assumption) and a low
# coefficient at which the pivots slide as the measured ones do (the data show
# the centre barely moving sideways while the pivot slides); 0.1 is an
# illustration of that end, not a fitted value.
FRICTIONS = (replay.DEFAULT_FRICTION, 0.1)

DATA_SOURCE = {
    "what": "500 planar drops of a square block (side 0.06 m) tracked by motion capture at "
            "250 Hz: traj_<n>.csv with x, z, th, vx, vz, vth",
    "collected_by": "MIT MCube Lab (Nima Fazeli, Alberto Rodriguez); attributed in the "
                    "DAIRLab README ('data from Nima Fazeli', square s = 0.06 m)",
    "redistributed_in": "https://github.com/DAIRLab/ImpactModeling, folder 'IRB Bound/IRB "
                        "Square/' (the same files in 'Visualize and Read Data/' and "
                        "'Wang/Wang-Mason Square/dice-data-processed/'); snapshot read at "
                        "commit f6c2889",
    "cite": [
        "N. Fazeli et al., 'Fundamental limitations in performance and interpretability of "
        "common planar rigid-body contact models', preprint, 13 October 2017",
        "N. Fazeli, S. Zapolsky, E. Drumwright, A. Rodriguez, 'Learning data-efficient "
        "rigid-body contact models: case study of planar impact', Proc. 1st Conference on "
        "Robot Learning, PMLR 78:388-397, 2017",
    ],
    "licence": "the DAIRLab repository's root LICENSE is BSD 3-Clause (Copyright 2020 DAIR "
               "Lab), covering that repository; no licence statement of the data's "
               "collectors was found. Only derived numbers are stored here; the loader "
               "reads the user's own copy.",
}


def engine_key(engine: str, friction: float) -> str:
    """The rows' key of one engine run, e.g. ``'pymunk_mu10'``."""
    return f"{engine}_mu{friction:g}"


def files_digest(folder) -> str:
    """SHA-256 over the ``traj_<n>.csv`` files of ``folder`` (names and bytes, in
    :func:`.impact_data.load_folder` order): says whether a copy is the one measured."""
    h = hashlib.sha256()
    for tr in data.load_folder(folder):
        h.update(tr.name.encode())
        h.update((Path(folder) / tr.name).read_bytes())
    return h.hexdigest()


def measure(folder, flt: data.Filter = data.Filter(), engines=replay.ENGINES,
            frictions=FRICTIONS) -> dict:
    """Rows and context of every rocking-like impact in ``folder``.

    Returns ``{'rows', 'rejected', 'files', 'theta_offset', 'angle_noise',
    'housner', 'filter'}``; each row is :meth:`.impact_data.Impact.to_dict`
    (without the replay's start) plus ``engines``: ``{engine_key: ratio}`` and
    ``engines_direct``: the engines' own step-resolution ratios.
    """
    trajectories = data.load_folder(folder)
    offset = data.theta_offset(trajectories)
    rejected: dict = {}
    rows = []
    for tr in trajectories:
        for imp in data.find_impacts(tr, offset, flt, rejected):
            row = imp.to_dict()
            row.pop("state")
            row["engines"], row["engines_direct"] = {}, {}
            for engine in engines:
                for mu in frictions:
                    out = replay.replay(engine, imp, mu, flt)
                    row["engines"][engine_key(engine, mu)] = out["ratio"]
                    row["engines_direct"][engine_key(engine, mu)] = out["ratio_direct"]
            rows.append(row)
    return {"rows": rows, "rejected": dict(sorted(rejected.items())),
            "files": len(trajectories), "theta_offset": offset,
            "angle_noise": data.angle_noise(trajectories), "housner": data.housner_ratio(),
            "filter": flt.to_dict()}


def _stats(x) -> dict:
    x = np.asarray(x, dtype=float)
    p10, p25, p75, p90 = (float(v) for v in np.percentile(x, [10, 25, 75, 90]))
    return {"n": int(x.size), "mean": float(np.mean(x)), "median": float(np.median(x)),
            "std": float(np.std(x)), "p10": p10, "p25": p25, "p75": p75, "p90": p90,
            "mad": float(np.median(np.abs(x - np.median(x))))}


def estimator_sensitivity(folder, windows=(3, 5)) -> dict:
    """The measured ratios' statistics with other fit windows (no engines): how
    much the stated numbers owe to the 4-frame choice."""
    trajectories = data.load_folder(folder)
    offset = data.theta_offset(trajectories)
    out = {}
    for w in windows:
        flt = data.Filter(window=w)
        ratios = [imp.ratio for tr in trajectories for imp in data.find_impacts(tr, offset, flt)]
        out[f"window_{w}"] = _stats(ratios) if ratios else {"n": 0}
    return out


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def summarise(rows: list[dict], housner: float, rate_noise: float) -> dict:
    """The stated numbers from per-impact ``rows`` (:func:`measure`).

    ``rate_noise`` [rad/s] is the estimator's rate noise (the generator's
    ``rate_noise``: 2.54 x angle noise x frame rate for the 4-frame parabola);
    each ratio's uncertainty is ``rate_noise / |theta_dot-| * sqrt(1 + ratio^2)``.

    ``floor_any_single_value``: the smallest RMS error any model predicting one
    ratio for this square can have, the measured ratios' standard deviation
    (attained at their mean); ``floor_any_single_value_mad``: its robust twin,
    the smallest median absolute error (attained at the median);
    ``spread_beyond_noise``: the standard deviation with the estimator's noise
    taken out in quadrature.
    """
    measured = np.array([r["ratio"] for r in rows])
    before = np.array([abs(r["rate_before"]) for r in rows])
    unc = rate_noise / before * np.sqrt(1.0 + measured ** 2)
    spread = float(np.std(measured))
    out = {
        "impacts": len(rows),
        "files_with_impacts": len({r["name"] for r in rows}),
        "measured": _stats(measured),
        "fraction_continuing": float(np.mean(measured > 0.0)),
        "fraction_rebounding": float(np.mean(measured <= 0.0)),
        "continuing_median": float(np.median(measured[measured > 0.0]))
        if np.any(measured > 0.0) else None,
        "rebounding_median": float(np.median(measured[measured <= 0.0]))
        if np.any(measured <= 0.0) else None,
        "ratio_uncertainty_median": float(np.median(unc)),
        "housner": housner,
        "housner_rms_error": _rms(measured - housner),
        "housner_median_abs_error": float(np.median(np.abs(measured - housner))),
        "floor_any_single_value": spread,
        "floor_any_single_value_mad": float(np.median(np.abs(measured - np.median(measured)))),
        "fraction_above_one": float(np.mean(np.abs(measured) > 1.0)),
        "spread_beyond_noise": float(math.sqrt(max(spread ** 2 - float(np.mean(unc ** 2)), 0.0))),
        "rate_before_median": float(np.median(before)),
        "slip_median": float(np.median([abs(r["slip"]) for r in rows])),
        "engines": {},
    }
    for key in (rows[0]["engines"] if rows else {}):
        ratio = np.array([r["engines"][key] for r in rows])
        direct = [r["engines_direct"][key] for r in rows if r["engines_direct"][key] is not None]
        out["engines"][key] = {**_stats(ratio), "rms_error": _rms(measured - ratio),
                               "median_abs_error": float(np.median(np.abs(measured - ratio))),
                               "direct_median": float(np.median(direct)) if direct else None,
                               "direct_n": len(direct)}
    return out
