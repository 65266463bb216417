"""The restitution map: each engine's effective rocking restitution and threshold
error against the slenderness ``lam``, over the settings that matter.

For every engine, every settings variant of :func:`grid` and every scene of the
block family (``block_lam1.5`` ... ``block_lam10``, mu = gamma = 0, each column
an independent Housner block) plus the trilith at the paper's lam (``fig5``:
Eq. 20 with the lintel and no pendulum, Eq. 19 with the pendulum), one *cell*:

* ``r_ratio`` = r_eff / r_H: the mean over the first :data:`N_IMPACTS` impacts
  of the measured velocity ratio ``theta_dot+ / theta_dot-`` divided by the
  model's (Eq. 20, which for a block is Housner's ``1 - 1.5 sin^2 alpha``; Eq. 19
  at the measured psi with the pendulum), and ``r_worst`` the largest
  ``|measured / predicted - 1|`` of those impacts
  (:func:`compare.measure.restitution.free_rocking`: free rocking from
  ``alpha / 2``, the run ends halfway to impact ``N_IMPACTS + 1``, before rest);
* ``thr_error``: the engine's first-overturning one-sine amplitude at
  ``Omega = OMEGA_RATIO p`` (``p = sqrt(3 g / (4 R))`` of one column, ``R``
  its half-diagonal) over the model's, minus 1 (the robust search of
  :func:`compare.measure.thresholds.engine_threshold`, 0.5 % bracket).

Every run goes through the run store (:mod:`compare.run.runs`), so a killed map
resumes.  A variant *passes* a lam range when every cell in it has
``r_worst <= R_TOL`` and ``|thr_error| <= THR_TOL``; :func:`cheapest` picks the
variant of least CPU per range.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

__all__ = ["Variant", "MapCell", "STEP_VARIANTS", "grid", "grids", "LAMS", "TRILITH", "LAM_RANGES", "OMEGA_RATIO",
           "N_IMPACTS", "R_TOL", "THR_TOL", "cell_scene", "measure_cell", "restitution_map",
           "cheapest", "not_exposed"]

LAMS = (1.5, 2.0, 3.0, 5.0, 8.0, 10.0)
# The paper's trilith (fig5, lam 5, mu 1): without the pendulum Eq. 20 holds
# (with the lintel's mu), with it Eq. 19 at the measured pendulum angle.
TRILITH = ("fig5_eq20", "fig5_eq19")
# Stocky (alpha 0.59-0.32 rad, r_H 0.53-0.86) and slender (0.20-0.10 rad, 0.94-0.99)
# blocks: engines that hold one need not hold the other (a stocky block's impact
# loses up to half its velocity, a slender one's a few percent).
LAM_RANGES = ((1.5, 3.0), (5.0, 10.0))
# Omega / p = 3: a short pulse, well inside the spectrum where the one-sine
# threshold depends on the impacts (Zhang & Makris 2001, fig. 6) yet far from the
# uplift floor g/lam, which any engine reproduces (statics).
OMEGA_RATIO = 3.0
# Four impacts: two on each side while the rocking is still large (as
# compare.measure.restitution.DEFAULT_N_IMPACTS).
N_IMPACTS = 4
# 0.5 %: the engines' measured restitution spread at their defaults is <= 0.24 %
# (engines/base.py), and 0.5 % in r shifts the one-sine threshold by < 1 %.
R_TOL = 0.005
# 2 %: the project's threshold agreement tolerance (engine_spectrum.DEFAULT_TOL).
THR_TOL = 0.02


@dataclass(frozen=True)
class Variant:
    """One settings variant: ``name`` (a label), the ``options`` it sets over the
    engine's defaults (Settings fields) and ``why`` it is in the grid."""

    name: str
    options: dict = field(default_factory=dict)
    why: str = ""

    def to_dict(self) -> dict:
        return {"name": self.name, "options": dict(self.options), "why": self.why}


def _v(name, why, **options) -> Variant:
    return Variant(name, options, why)


# Per engine: the defaults, the step at two coarser values (where the cost is)
# and one or two values of each named parameter the engine exposes, one at a
# time (the engine class's ``impact_variants``; docs/restitution-map.md).  Finer
# steps are left out: every engine's error at 1e-4 s is already below R_TOL and
# they double the cost.
STEP_VARIANTS = (_v("default", "calibrated defaults (dt 1e-4 s)"),
                 _v("dt=2e-4", "step x2", dt=2e-4),
                 _v("dt=5e-4", "step x5", dt=5e-4))


def grid(engine: str) -> tuple[Variant, ...]:
    """``engine``'s settings variants: :data:`STEP_VARIANTS`, then its class's
    ``impact_variants`` (every registered engine, entry-point ones included)."""
    from trilith_xval.engines import get_backend
    return STEP_VARIANTS + tuple(Variant(name, dict(options), why) for name, why, options
                                 in get_backend(engine).impact_variants)


def grids(engines=None) -> dict[str, tuple[Variant, ...]]:
    """:func:`grid` of each of ``engines`` (default: every registered engine)."""
    from trilith_xval.engines import engine_names
    return {e: grid(e) for e in (engine_names() if engines is None else engines)}


def not_exposed(engines=None) -> dict[str, str]:
    """Per engine, the impact parameters its Settings do not expose, and why (the
    class's ``impact_fixed``)."""
    from trilith_xval.engines import engine_names, get_backend
    fixed = {e: get_backend(e).impact_fixed
             for e in (engine_names() if engines is None else engines)}
    return {e: text for e, text in fixed.items() if text}


def cell_scene(scene_name: str):
    """The scene of a cell: ``'block_lamX'`` or one of :data:`TRILITH`."""
    from trilith_xval.scenes import load_scene
    if scene_name == "fig5_eq20":
        return load_scene("fig5", gamma=0.0)
    if scene_name == "fig5_eq19":
        return load_scene("fig5")
    return load_scene(scene_name)


def block_name(lam: float) -> str:
    return f"block_lam{lam:g}"


def omega_of(scene) -> float:
    """``OMEGA_RATIO p`` [rad/s], ``p = sqrt(3 g / (4 R))`` of one column."""
    r = 0.5 * math.hypot(scene.b, scene.h)
    return OMEGA_RATIO * math.sqrt(3.0 * scene.g / (4.0 * r))


def model_point(scene_name: str) -> tuple[float, float, str | None]:
    """``(omega, a_model, mode)`` of a cell's scene, through the run store."""
    from trilith_xval.compare.measure.map_thresholds import model_thresholds
    from trilith_xval.compare.run import runs
    scene = cell_scene(scene_name)
    w = omega_of(scene)

    def compute():
        a, mode = model_thresholds(scene, [w])[0]
        return [float(a), mode]
    a, mode = runs.memo("restitution_map_model", {"scene": scene.to_dict(), "omega": w},
                        compute, label=f"model threshold {scene_name}")
    return w, float(a), mode


@dataclass(frozen=True)
class MapCell:
    """One cell: ``engine`` with its variant named ``variant`` (of :func:`grid`) on
    the scene named ``scene`` (:func:`cell_scene`), the one-sine pulse at
    ``omega`` [rad/s] where the model's threshold is ``a_model`` [m/s^2] (mode
    ``mode``)."""

    engine: str
    variant: str
    scene: str
    omega: float
    a_model: float
    mode: str | None

    def values(self) -> list:
        """The cell's fields, in order (its store key's ``cell``)."""
        return [self.engine, self.variant, self.scene, self.omega, self.a_model, self.mode]

    def grid_variant(self) -> Variant:
        return next(v for v in grid(self.engine) if v.name == self.variant)

    def run(self):
        """The cell's run (:class:`compare.run.spec.RunSpec`): the engine's
        defaults, then the variant's options, on the cell's scene with no base
        motion; its threshold search resolves it again at its largest pulse."""
        from trilith_xval.compare.run.spec import RunSpec
        variant = self.grid_variant()
        return RunSpec.resolve(self.engine, cell_scene(self.scene),
                               overrides=dict(variant.options),
                               overrides_from=f"the variant {variant.name}")


def measure_cell(cell: MapCell) -> dict:
    """One cell (:class:`MapCell`) measured: a dict (plain data).  Module-level:
    workers pickle it."""
    from trilith_xval.compare.measure.engine_spectrum import point_spec
    from trilith_xval.compare.measure.restitution import free_rocking
    from trilith_xval.compare.measure.thresholds import engine_threshold
    engine, variant_name, scene_name, w, a_model, mode = cell.values()
    c0 = time.process_time()
    run = cell.run()
    scene = run.scene
    out = {"engine": engine, "variant": variant_name, "scene": scene_name, "lam": scene.lam,
           "omega": w, "a_model": a_model, "mode_model": mode, "error": None}
    # An engine that fails a run (Drake's SAP not converging) fails its cell, not
    # the map: the cell is kept with the engine's message and counts as failing.
    try:
        res = free_rocking(run, n_impacts=N_IMPACTS)
        ratios = [i.measured / i.predicted for i in res.impacts if i.predicted]
        r_cpu = float(res.diagnostics.get("cpu_time", math.nan))
        out.update(equation=res.equation, n_impacts=res.n_impacts, complete=res.complete,
                   r_ratio=math.fsum(ratios) / len(ratios) if ratios else math.nan,
                   r_worst=res.max_rel_error, r_status=res.status, r_cpu_s=r_cpu)
    except RuntimeError as exc:
        out.update(equation=None, n_impacts=0, complete=False, r_ratio=math.nan,
                   r_worst=math.nan, r_status="error", r_cpu_s=math.nan,
                   error=f"free rocking: {str(exc).splitlines()[0]}")
    out.update(a_engine=math.nan, a_survives=math.nan, thr_error=math.nan,
               mode_engine=None, thr_runs=0, thr_cpu_s=0.0)
    if math.isfinite(a_model):
        try:
            spec = point_spec(run, scene, w, a_model)  # at the search's largest pulse
            p = engine_threshold(engine, scene, w, a_model, spec.settings, mode_reference=mode)
            out.update(a_engine=p.a_engine, a_survives=p.a_survives, thr_error=p.rel_error,
                       mode_engine=p.mode_engine, thr_runs=p.n_runs, thr_cpu_s=p.cpu_s)
        except RuntimeError as exc:
            out["error"] = "; ".join(filter(None, (out["error"], "threshold: "
                                                   + str(exc).splitlines()[0])))
    r_cpu = out["r_cpu_s"]
    out["cpu_s"] = (r_cpu if math.isfinite(r_cpu) else 0.0) + float(out["thr_cpu_s"])
    out["cpu_s_spent"] = time.process_time() - c0
    return out


def _cells(engines, scenes, models, variants=None) -> list[MapCell]:
    return [MapCell(e, v.name, s, *models[s]) for e in engines for v in grid(e)
            if variants is None or v.name in variants for s in scenes]


def restitution_map(engines=None, lams=LAMS, *, trilith: bool = True,
                    workers: int = 1, variants=None) -> dict:
    """Measure the map (module docstring): plain data, cells in job order.

    Parameters
    ----------
    engines : sequence of str, optional
        Registered engines (default: every one).
    lams : sequence of float
        Members of :data:`LAMS` (the block scenes).
    trilith : bool
        Also the fig5 trilith (Eq. 20 and Eq. 19).
    workers : int
        Local processes (:func:`compare.run.runs.run_many`).
    variants : sequence of str, optional
        Only the variants of these names (default: every variant of each grid).

    Returns
    -------
    dict
        ``cells``, ``grids``, ``cheapest``, ``cpu_s`` (this process and the
        workers' cells, as spent now), ``cells_cpu_s`` (the cells' runs as
        computed), ``load_average`` (at the end).
    """
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.progress import bar
    from trilith_xval.engines import engine_names
    engines = engine_names() if engines is None else tuple(engines)
    for e in engines:
        if e not in engine_names():
            raise ValueError(f"engine must be one of {', '.join(engine_names())}, got {e!r}")
    for lam in lams:
        if lam not in LAMS:
            raise ValueError(f"lam must be one of {', '.join(f'{x:g}' for x in LAMS)}, got {lam!r}")
    if variants is not None:
        known = {v.name for e in engines for v in grid(e)}
        for name in variants:
            if name not in known:
                raise ValueError(f"variant must be one of {', '.join(sorted(known))}, "
                                 f"got {name!r}")
    c0, k0 = time.process_time(), _children_cpu()
    scenes = [block_name(lam) for lam in lams] + (list(TRILITH) if trilith else [])
    with bar(len(scenes), "model thresholds", "scene") as b:
        models = {}
        for s in scenes:
            models[s] = model_point(s)
            b.update()
    jobs = _cells(engines, scenes, models, variants)
    cells = []
    with bar(len(jobs), "restitution map", "cell") as b:
        for out in runs.run_many(_cell_memo, jobs, workers=workers,
                                 on_done=lambda i, o: b.update()):
            cells.append(out)
    spent = time.process_time() - c0 + _children_cpu() - k0
    return {"engines": list(engines), "lams": list(lams), "trilith": trilith,
            "omega_ratio": OMEGA_RATIO, "n_impacts": N_IMPACTS, "r_tol": R_TOL,
            "thr_tol": THR_TOL, "grids": {e: [v.to_dict() for v in grid(e)
                                              if variants is None or v.name in variants]
                                          for e in engines},
            "not_exposed": not_exposed(), "cells": cells,
            "cheapest": cheapest(cells), "cpu_s": spent,
            "cells_cpu_s": math.fsum(c["cpu_s"] for c in cells),
            "load_average": list(os.getloadavg())}


# What a cell's result depends on: the model, the engines, the measurements and
# the run layer; not the CLI nor the report, whose edits must not redo the map.
CELL_CODE = ("analytic", "engines", "compare/measure", "compare/run")


def _children_cpu() -> float:
    """CPU seconds (user + system) of this process's finished child processes."""
    import resource
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def _cell_memo(cell: MapCell) -> dict:
    """:func:`measure_cell` through the store (whole cells: a warm rerun is instant)."""
    from trilith_xval.compare.run import runs
    key = {"cell": cell.values(), "options": {k: list(v) if isinstance(v, tuple) else v
                                              for k, v in cell.grid_variant().options.items()},
           "n_impacts": N_IMPACTS}
    return runs.memo("restitution_map_cell", key, lambda: measure_cell(cell),
                     label=f"{cell.engine} {cell.variant} {cell.scene}", code=CELL_CODE)


def passes(cell: dict) -> bool:
    """Within :data:`R_TOL` (worst impact) and :data:`THR_TOL` (threshold)."""
    return (cell["complete"] and math.isfinite(cell["r_worst"]) and cell["r_worst"] <= R_TOL
            and math.isfinite(cell["thr_error"]) and abs(cell["thr_error"]) <= THR_TOL)


def cheapest(cells: list[dict]) -> list[dict]:
    """Per engine and range (each of :data:`LAM_RANGES` on the blocks, and the
    trilith), the passing variant of least total CPU over the range's cells;
    ``variant`` None when none passes every cell of the range."""
    groups = [(f"lam{lo:g}-{hi:g}", lambda c, lo=lo, hi=hi: c["scene"].startswith("block")
               and lo <= c["lam"] <= hi) for lo, hi in LAM_RANGES]
    groups.append(("trilith", lambda c: c["scene"] in TRILITH))
    out = []
    for engine in dict.fromkeys(c["engine"] for c in cells):
        for label, member in groups:
            mine = [c for c in cells if c["engine"] == engine and member(c)]
            if not mine:
                continue
            best = None
            for name in dict.fromkeys(c["variant"] for c in mine):
                these = [c for c in mine if c["variant"] == name]
                if all(passes(c) for c in these):
                    cost = math.fsum(c["cpu_s"] for c in these)
                    if best is None or cost < best[1]:
                        best = (name, cost)
            out.append({"engine": engine, "range": label,
                        "scenes": sorted({c["scene"] for c in mine}),
                        "variant": None if best is None else best[0],
                        "cpu_s": None if best is None else best[1]})
    return out
