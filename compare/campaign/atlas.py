"""The trust atlas: where each engine's first-overturning amplitude agrees with the
model's, over every scene of the paper, and at which time step.

Points: the scenes of Figs. 8, 9 and 11 under one-sine pulses (Eq. 22) and the
Fig. 5 scene under one-cosine pulses (Eq. 23, Fig. 10), with and without the
pendulum, Omega = 4..28 rad/s by 2.  At each point the model's threshold
(:func:`compare.campaign.study.run_reference`) and the model's validity on that
run (:func:`analytic.threshold_validity.point_validity`); then per engine the
one threshold measurement (:func:`compare.measure.engine_spectrum.measure_point`
through :func:`compare.campaign.study.run_threshold`) at the engine's calibrated
threshold step where every atlas scene lies in its domain, else its reference step
(:func:`base_step`), and at 2x, 5x and 10x that step.  A point that fails at a
step is first remeasured at finer steps down to the reference
(:mod:`compare.measure.step_rule`); at the coarser steps those finer steps are the
atlas's own, served by the run store.

Nothing is simulated that a verdict does not need: a point where the model is
invalid is recorded as such and no engine is compared with the model there (no
engine is to blame; the engines' consensus there is a pass of its own,
:mod:`compare.campaign.atlas_consensus`);
identical tricks (the no-pendulum frames of the Fig. 8 scenes differ only in the
pendulum) are one job (the store key leaves the scene's name out); a coarser
step runs only where the finer one agreed.  Every job goes through the run
store, so a killed atlas resumes.
"""
from __future__ import annotations

import fnmatch
import math
import os
import resource
import time
from dataclasses import dataclass, field

import numpy as np

from trilith_xval.compare.run import runs

__all__ = ["AtlasConfig", "ATLAS_SCENES", "atlas_scenes", "run_atlas", "base_step"]

# (scene name or glob, pulse): the paper's Figs. 8, 9, 11 (one-sine) and Fig. 10
# (the Fig. 5 trilith under a one-cosine pulse).
ATLAS_SCENES = (("fig8_*", "sine"), ("fig9_*", "sine"), ("fig11_*", "sine"),
                ("fig5", "cosine"))
FIGURE = {"fig8": "Fig. 8", "fig9": "Fig. 9", "fig11": "Fig. 11", "fig5": "Fig. 10"}


@dataclass(frozen=True)
class AtlasConfig:
    """What the atlas measures (module docstring)."""

    engines: tuple[str, ...] = field(default_factory=lambda: _default_engines())
    scenes: tuple = ATLAS_SCENES
    omegas: tuple[float, ...] = tuple(float(w) for w in np.arange(4.0, 28.5, 2.0))
    factors: tuple[float, ...] = (1.0, 2.0, 5.0, 10.0)  # x the calibrated threshold step
    cases: tuple[str, ...] = ("pendulum", "no_pendulum")
    rel_bracket: float = 0.03  # as the campaigns: engines within ~1-2 % of the model
    rel_tol: float = 4e-3  # final bracket / A_model: a fifth of the tolerance
    tol: float = 0.02  # agreement tolerance (the report's)
    settings: tuple = ()  # (engine, ((field, value), ...)): a settings file's tables
    # (scene, case, pulse, omega) of the points to measure; empty: every point of the
    # grid (a restep remeasures some points of a stored atlas, atlas_restep.py).
    only: tuple = ()

    def __post_init__(self) -> None:
        from trilith_xval.engines import ENGINES
        for e in self.engines:
            if e not in ENGINES:
                raise ValueError(f"engines: unknown engine {e!r}; allowed: {', '.join(ENGINES)}")
        if not self.factors or any(not (math.isfinite(f) and 1.0 <= f <= 50.0)
                                   for f in self.factors):
            raise ValueError(f"factors must be step multiples in [1, 50], got {self.factors!r}")
        if list(self.factors) != sorted(set(self.factors)):
            raise ValueError(f"factors must increase, got {self.factors!r}")

    def options(self, engine: str) -> dict:
        return dict(dict(self.settings).get(engine, ()))

    def describe(self) -> dict:
        return {"engines": list(self.engines), "scenes": [list(s) for s in self.scenes],
                "omegas": list(self.omegas), "factors": list(self.factors),
                "cases": list(self.cases), "rel_bracket": self.rel_bracket,
                "rel_tol": self.rel_tol, "tol": self.tol,
                "settings": {e: dict(o) for e, o in self.settings},
                **({"only": [list(p) for p in self.only]} if self.only else {})}


def _default_engines() -> tuple[str, ...]:
    from trilith_xval.engines import default_engines
    return default_engines()


def atlas_scenes(config: AtlasConfig) -> list[tuple[str, str]]:
    """``(scene name, pulse)`` of every atlas scene, globs resolved."""
    from trilith_xval.scenes import scene_names
    out = []
    for pattern, pulse in config.scenes:
        hits = [n for n in scene_names() if fnmatch.fnmatchcase(n, pattern)]
        if not hits:
            raise ValueError(f"scenes: {pattern!r} matches no scene")
        out += [(n, pulse) for n in hits if (n, pulse) not in out]
    from trilith_xval.scenes import load_scene
    for n in {n for n, _ in out}:  # the atlas measures engines against the model
        kind = getattr(load_scene(n), "kind", "trilith")
        if kind != "trilith":
            raise ValueError(f"scenes: {n!r} is of the {kind} kind, which the analytic model "
                             f"does not cover (docs/geometry.md)")
    return out


def base_step(engine: str, config: AtlasConfig) -> float:
    """The engine's threshold step [s] for the atlas: its calibrated step when every
    atlas scene lies in the calibration's domain, else its reference step (a
    settings file's step over either)."""
    from trilith_xval.engines import configure

    from trilith_xval.compare.campaign.settings_file import threshold_options
    from trilith_xval.compare.campaign.study import _scene
    per_scene = [threshold_options(engine, _scene(n, c)) for n, _ in atlas_scenes(config)
                 for c in config.cases]
    common = per_scene[0] if all(o == per_scene[0] for o in per_scene) else {}
    return float(configure(engine, **{**common, **config.options(engine)}).dt)


def _validity(job: tuple) -> dict:
    """The model's validity on its run at the threshold, through the store."""
    from trilith_xval.analytic.threshold_validity import point_validity

    from trilith_xval.compare.campaign.study import _scene
    from trilith_xval.compare.run.keys import scene_dict
    name, case, pulse, omega, a_ref = job
    scene = _scene(name, case)
    return runs.memo("point-validity", {"scene": scene_dict(scene), "omega": float(omega),
                                        "amplitude": float(a_ref), "pulse": pulse},
                     lambda: point_validity(scene, a_ref, omega, pulse))


def _bar(total: int, desc: str):
    from trilith_xval.compare.run.progress import bar
    return bar(total, desc, "points")


def _many(fn, jobs: list, workers: int, chunk: int, desc: str,
          deadline: float | None = None) -> list:
    """``fn`` over ``jobs`` in order, in chunks of ``chunk``; once ``deadline``
    (``perf_counter``) has passed no new chunk starts and the jobs left are None
    (not run)."""
    out: list = [None] * len(jobs)
    bar = _bar(len(jobs), desc)
    try:
        for start in range(0, len(jobs), chunk):
            if deadline is not None and time.perf_counter() > deadline:
                break
            part = jobs[start:start + chunk]
            out[start:start + len(part)] = runs.run_many(
                fn, part, workers=workers, on_done=lambda i, r: bar.update(1))
    finally:
        bar.close()
    return out


def _compact(row: dict) -> dict:
    """The numbers a map and a table need from a threshold job's row."""
    keep = ("dt_used", "a_engine", "rel_error", "rel_resolution", "cause", "agreeing_dt",
            "valid", "n_runs", "isolated", "cpu_s", "sim_s", "from_store", "error")
    out = {k: row[k] for k in keep if k in row}
    out["dt"] = out.pop("dt_used", row.get("dt"))
    return out


def _van_der_corput(n: int) -> list[int]:
    """0..n-1 coarse to fine: each prefix spreads over the range (bit-reversed
    order, e.g. 0, 8, 4, 12, 2, ... for 16)."""
    bits = max(1, (n - 1).bit_length())
    return sorted(range(n), key=lambda i: int(format(i, f"0{bits}b")[::-1], 2))


def spread_order(indices: list[int], points: list[dict]) -> list[int]:
    """``indices`` (into ``points``) reordered so that any prefix covers every scene,
    case and pulse on a coarse Omega grid: round robin over the (scene, case,
    pulse) groups, each group's Omegas coarse to fine.  A time budget then cuts the
    resolution of the measured map, not whole figures."""
    groups: dict[tuple, list[int]] = {}
    for i in indices:
        pt = points[i]
        groups.setdefault((pt["scene"], pt["case"], pt["pulse"]), []).append(i)
    queues = []
    for members in groups.values():
        members = sorted(members, key=lambda i: points[i]["omega"])
        queues.append([members[k] for k in _van_der_corput(len(members))])
    out = []
    for rank in range(max((len(q) for q in queues), default=0)):
        out.extend(q[rank] for q in queues if rank < len(q))
    return out


def _run_round(todo0: list[int], points: list[dict], config: AtlasConfig, steps: dict,
               workers: int, chunk: int, deadline: float | None, done: dict,
               not_run: dict) -> None:
    """Points ``todo0`` (indices) through every step of every engine, a coarser
    step only where the finer one agreed; rows appended to the points.  A job left
    by ``deadline`` is counted in ``not_run`` at its step (its coarser steps are
    not run either); a job in ``done`` (an identical trick measured before) runs
    once."""
    from trilith_xval.compare.campaign.study import ThresholdJob, run_threshold
    from trilith_xval.compare.run.keys import digest

    for e in config.engines:
        todo = list(todo0)
        opts = tuple(sorted(config.options(e).items()))
        for dt in steps[e]:
            keys, fresh = [], {}
            for i in todo:
                pt = points[i]
                job = ThresholdJob(pt["scene"], pt["case"], pt["pulse"], pt["omega"],
                                   pt["a_reference"], pt["mode"], e, dt, config.rel_bracket,
                                   config.rel_tol, opts)
                key = digest(job.description())
                keys.append(key)
                if key not in done:
                    fresh.setdefault(key, job)
            rows = _many(run_threshold, list(fresh.values()), workers, chunk,
                         f"atlas: {e} dt={dt:g} s", deadline)
            done.update((k, r) for k, r in zip(fresh, rows) if r is not None)
            agreed = []
            for i, key in zip(todo, keys):
                if key not in done:
                    not_run[e][repr(dt)] = not_run[e].get(repr(dt), 0) + 1
                    continue
                row = _compact(done[key])
                points[i]["engines"][e].append(row)
                if row.get("cause") == "agrees":
                    agreed.append(i)
            todo = agreed


def run_atlas(config: AtlasConfig, workers: int = 1, budget_s: float | None = None) -> dict:
    """Measure the atlas (module docstring); returns the ``atlas.json`` document.

    ``budget_s``: wall seconds after which no new chunk of engine jobs starts
    (the model's references and validity are always complete); the points whose
    job was left are counted in ``not_run`` per engine and step, and carry no row
    for that step (nor for any coarser one).  Points run in rounds in
    :func:`spread_order`, each round through every step, so a budget leaves a
    coarser Omega grid on every scene, measured at every step.
    """
    from trilith_xval.compare.campaign.study import run_reference
    from trilith_xval.compare.run.keys import backend_version, project_version

    t0, c0, load0 = time.perf_counter(), time.process_time(), os.getloadavg()[0]
    w0 = _workers_cpu_s()
    deadline = None if budget_s is None else t0 + budget_s
    pairs = atlas_scenes(config)
    ref_jobs = [(n, c, p, w) for n, p in pairs for c in config.cases for w in config.omegas]
    if config.only:
        wanted = set(config.only)
        ref_jobs = [job for job in ref_jobs if job in wanted]
    # Four jobs or points per job slot (a local worker or a cluster thread), at least
    # ten; the cluster is asked once.
    size = max(10, 4 * runs.parallel_slots(workers))
    refs = _many(run_reference, ref_jobs, workers, size, "atlas: model")
    finite = [i for i, (a, _) in enumerate(refs) if math.isfinite(a)]
    checks = _many(_validity, [(*ref_jobs[i], refs[i][0]) for i in finite], workers, size,
                   "atlas: validity")
    points = []
    for (n, c, p, w), (a_ref, mode) in zip(ref_jobs, refs):
        points.append({"scene": n, "case": c, "pulse": p, "omega": w,
                       "a_reference": a_ref if math.isfinite(a_ref) else None, "mode": mode,
                       "valid": None, "model_reason": "no overturning (nothing to bracket)",
                       "engines": {e: [] for e in config.engines}})
    for i, v in zip(finite, checks):
        points[i].update(valid=v["model_valid"], model_reason=v["model_reason"])
    # Engines run where the model is valid (or its check had nothing to say).
    valid = spread_order([i for i in finite if points[i]["valid"] is not False], points)
    steps = {e: [f * base_step(e, config) for f in config.factors] for e in config.engines}
    not_run: dict = {e: {} for e in config.engines}
    done: dict[str, dict] = {}  # threshold key -> row: one job per identical trick
    # Rounds of points, each through every step before the next round starts: a
    # budget then leaves a coarser Omega grid measured at every step, never the
    # calibrated step alone.
    bar = _bar(len(valid), f"atlas: {', '.join(config.engines)}")
    try:
        for start in range(0, len(valid), size):
            part = valid[start:start + size]
            _run_round(part, points, config, steps, workers, size, deadline, done,
                       not_run)
            bar.update(len(part))
    finally:
        bar.close()
    return {"schema_version": 1,
            "what": "engine first-overturning amplitude vs the model over the paper's scenes",
            "config": config.describe(),
            "versions": {"project": project_version(),
                         "analytic-fast": backend_version("analytic-fast"),
                         **{e: backend_version(e) for e in config.engines}},
            "steps": steps, "points": points, "cost": cost_table(points, config.engines),
            "budget_s": budget_s,
            "not_run": {e: n for e, n in not_run.items() if n},
            "wall_s": time.perf_counter() - t0, "parent_cpu_s": time.process_time() - c0,
            # On a Dask cluster the workers are not this process's children.
            "local_cpu_s": (None if runs._SCHEDULER is not None
                            else time.process_time() - c0 + _workers_cpu_s() - w0),
            "load_average": [load0, os.getloadavg()[0]], "workers": workers}


def _workers_cpu_s() -> float:
    """CPU seconds of this process's finished child processes: the local workers,
    each pool of which is joined when its chunk ends (a Dask cluster's workers are
    not children and are not counted)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cost_table(points: list[dict], engines) -> list[dict]:
    """Per engine and step: points measured, jobs (identical tricks are one job: the
    same case, pulse, Omega, model threshold and engine result), CPU seconds of the
    jobs (when computed), CPU s per job and per simulated second."""
    out = []
    for e in engines:
        by_dt: dict[float, dict] = {}
        for pt in points:
            for row in pt["engines"].get(e, ()):
                job = (pt["case"], pt["pulse"], pt["omega"], pt["a_reference"],
                       row.get("a_engine"), row.get("n_runs"), row.get("cpu_s"))
                seen = by_dt.setdefault(row["dt"], {"points": 0, "jobs": {}})
                seen["points"] += 1
                seen["jobs"][job] = row
        for dt in sorted(by_dt):
            rows = [r for r in by_dt[dt]["jobs"].values() if "error" not in r]
            cpu = math.fsum(r["cpu_s"] for r in rows if r.get("cpu_s") is not None)
            sim = math.fsum(r.get("sim_s") or 0.0 for r in rows)
            out.append({"engine": e, "dt": dt, "points": by_dt[dt]["points"],
                        "jobs": len(by_dt[dt]["jobs"]),
                        "errors": len(by_dt[dt]["jobs"]) - len(rows), "cpu_s": cpu,
                        "cpu_s_per_point": cpu / len(rows) if rows else None,
                        "cpu_s_per_sim_s": cpu / sim if sim > 0 else None})
    return out
