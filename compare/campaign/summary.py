"""The typed schema of ``summary.json``: one place that says what the validation
summary holds, read by every consumer (report, README findings, trust table).

``summary.json`` is strict JSON (non-finite numbers are ``null``); :func:`load`
and :meth:`Summary.from_dict` turn it into frozen views below, with ``None``
(or an empty tuple) where a field is absent, so a summary written by an older
campaign still reads: its new fields say "not measured" instead of raising.

Views and their fields (names stable: the report reads them):

* :class:`Summary` - ``schema_version``, ``quick``, ``provenance``, ``config``,
  ``scene``, ``settings`` (per backend), ``versions``, ``comparisons``,
  ``restitution``, ``spectra`` (case -> :class:`SpectrumCase`), ``verdicts``
  (:class:`Verdict`), ``timings`` (:class:`Timings`), ``errors``, ``trust``
  (engine -> the trust-table row, :mod:`compare.report.trust`) and
  ``long_runs`` (:class:`LongRun`).
* :class:`ThresholdResult` - one engine threshold point of the one search
  (:func:`compare.measure.thresholds.engine_threshold`) with its causes
  (:func:`compare.measure.engine_spectrum.classify`): the robust bracket
  ``a_survives < A* <= a_engine``, its resolution, the ``isolated`` overturns
  (:class:`Isolated`), the primary ``cause`` and every applying one
  (``causes``, :class:`Cause`), the model's validity (``valid``), and the
  cost (``cpu_s`` when computed, ``from_store``).

The dicts stay available as ``raw`` on every view, for fields not typed here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

__all__ = ["SCHEMA_VERSION", "Probe", "Isolated", "Cause", "Validity", "ThresholdResult",
           "JumpShift", "SpectrumCase", "Verdict", "Timings", "LongRun", "Summary", "load",
           "num"]

# 3: robust thresholds (a_survives/isolated/causes/valid/cpu_s), CPU timings, long runs.
SCHEMA_VERSION = 3


def num(value) -> float | None:
    """A finite float, or None (JSON null, NaN, inf, bool, missing)."""
    if value is None or isinstance(value, bool):
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def _tuple(values, cls) -> tuple:
    return tuple(cls.from_dict(v) for v in (values or ()))


@dataclass(frozen=True)
class Probe:
    """One engine run of a threshold search.

    ``perturbation`` is '' for a probe of the search itself, else what was
    perturbed around it (:data:`compare.measure.thresholds.PERTURBATIONS`);
    ``cpu_s`` the CPU seconds the run cost when it was computed (None: not
    measured); ``from_store`` True when it was served by the run store.
    """

    amplitude: float | None
    status: str
    mode: str | None
    perturbation: str = ""
    cpu_s: float | None = None
    from_store: bool = False
    sim_s: float | None = None

    @classmethod
    def from_dict(cls, d) -> "Probe":
        if isinstance(d, (list, tuple)):  # schema 2: [amplitude, status, mode]
            return cls(num(d[0]), d[1], d[2] if len(d) > 2 else None)
        return cls(num(d.get("amplitude")), d.get("status", ""), d.get("mode"),
                   d.get("perturbation", ""), num(d.get("cpu_s")), bool(d.get("from_store")),
                   num(d.get("sim_s")))


@dataclass(frozen=True)
class Isolated:
    """An overturn that its perturbed neighbours do not reproduce: reported,
    never the threshold.  ``detail`` says what made it (e.g. the impact whose
    restitution is off Eq. 19/20, and by how much)."""

    amplitude: float | None
    mode: str | None
    neighbours: tuple = ()  # Probe
    detail: str = ""

    @classmethod
    def from_dict(cls, d) -> "Isolated":
        return cls(num(d.get("amplitude")), d.get("mode"), _tuple(d.get("neighbours"), Probe),
                   d.get("detail", ""))


@dataclass(frozen=True)
class Cause:
    """One explanation that applies to a point (``name`` in
    :data:`compare.measure.engine_spectrum.CAUSES`), with its evidence."""

    name: str
    detail: str = ""

    @classmethod
    def from_dict(cls, d) -> "Cause":
        return cls(d.get("name", ""), d.get("detail", ""))


@dataclass(frozen=True)
class Validity:
    """The analytic model's validity at one amplitude (:mod:`analytic.reactions`,
    :mod:`analytic.clearance`): ``where`` names the amplitude ('model threshold',
    'engine threshold', 'engine bracket')."""

    amplitude: float | None
    where: str
    valid: bool
    reason: str = ""

    @classmethod
    def from_dict(cls, d) -> "Validity":
        return cls(num(d.get("amplitude")), d.get("where", ""), bool(d.get("valid")),
                   d.get("reason", ""))


@dataclass(frozen=True)
class ThresholdResult:
    """One engine threshold point (see the module docstring).

    ``rel_error`` is ``(a_engine - a_reference)/a_reference``, known to
    ``rel_resolution`` (``(a_engine - a_survives)/a_reference``).  ``valid`` is
    None when the model was not checked.  ``cpu_s`` sums the CPU seconds of
    every probe (and cause reruns) when it was computed, ``cpu_per_sim_s`` is
    the search's CPU seconds per simulated second; ``cpu_s_spent`` what this campaign spent
    (0 for a point served whole by the store, then ``from_store`` is True).
    """

    case: str | None
    omega: float | None
    kind: str
    a_reference: float | None
    a_engine: float | None
    a_survives: float | None
    rel_error: float | None
    rel_resolution: float | None
    mode_reference: str | None
    mode_engine: str | None
    bracketed: bool
    collapsed_below: bool
    isolated: tuple = ()  # Isolated
    cause: str | None = None
    cause_detail: str = ""
    causes: tuple = ()  # Cause
    valid: bool | None = None
    validity: tuple = ()  # Validity
    convergence: tuple = ()  # dicts: dt, iterations, a_engine, rel_error
    n_runs: int = 0
    cpu_s: float | None = None
    cpu_s_spent: float | None = None
    from_store: bool = False
    rel_tol: float | None = None
    probes: tuple = ()  # Probe
    cpu_per_sim_s: float | None = None
    flips: tuple = ()  # Probe: perturbed runs that flipped an end's verdict
    raw: Mapping = field(default_factory=dict, repr=False, compare=False)

    @property
    def agrees(self) -> bool:
        return self.cause == "agrees"

    @property
    def dt(self) -> float | None:
        """The engine time step [s] the search ran at (its runs' provenance)."""
        return num((self.raw.get("provenance") or {}).get("dt"))

    @classmethod
    def from_dict(cls, d, case: str | None = None) -> "ThresholdResult":
        a_eng, a_ref = num(d.get("a_engine")), num(d.get("a_reference"))
        a_surv = num(d.get("a_survives"))
        res = num(d.get("rel_resolution"))
        if res is None and None not in (a_eng, a_surv, a_ref):
            res = (a_eng - a_surv) / a_ref
        return cls(case if case is not None else d.get("case"), num(d.get("omega")),
                   d.get("kind", "sine"), a_ref, a_eng, a_surv, num(d.get("rel_error")), res,
                   d.get("mode_reference"), d.get("mode_engine"),
                   bool(d.get("bracketed", a_eng is not None)), bool(d.get("collapsed_below")),
                   _tuple(d.get("isolated"), Isolated), d.get("cause"),
                   d.get("cause_detail", ""), _tuple(d.get("causes"), Cause), d.get("valid"),
                   _tuple(d.get("validity"), Validity), tuple(d.get("convergence") or ()),
                   int(d.get("n_runs") or 0), num(d.get("cpu_s")), num(d.get("cpu_s_spent")),
                   bool(d.get("from_store")), num(d.get("rel_tol")),
                   _tuple(d.get("probes"), Probe), num(d.get("cpu_per_sim_s")),
                   _tuple(d.get("flips"), Probe), d)


@dataclass(frozen=True)
class JumpShift:
    """Where an engine's verdict flips across the model's mode jump."""

    amplitude: float | None
    omega_reference: float | None
    omega_engine: float | None
    shift: float | None
    n_runs: int = 0
    cpu_s: float | None = None

    @classmethod
    def from_dict(cls, d) -> "JumpShift":
        return cls(num(d.get("amplitude")), num(d.get("omega_reference")),
                   num(d.get("omega_engine")), num(d.get("shift")), int(d.get("n_runs") or 0),
                   num(d.get("cpu_s")))


@dataclass(frozen=True)
class SpectrumCase:
    """One curve ('pendulum' or 'no_pendulum'): the model's spectrum (``omega``,
    ``a``, ``mode``, its ``jumps``), the engines' points and jump shifts."""

    name: str
    omega: tuple
    a: tuple
    mode: tuple
    jumps: tuple  # dicts: omega_lo, omega_hi, a_lo, a_hi, mode_lo, mode_hi
    engines: Mapping  # engine -> tuple[ThresholdResult]
    jump_shifts: Mapping  # engine -> JumpShift
    raw: Mapping = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def from_dict(cls, name: str, d) -> "SpectrumCase":
        return cls(name, tuple(num(w) for w in d.get("omega", ())),
                   tuple(num(a) for a in d.get("a", ())), tuple(d.get("mode", ())),
                   tuple(d.get("jumps", ())),
                   {e: tuple(ThresholdResult.from_dict(p, name) for p in pts)
                    for e, pts in (d.get("engines") or {}).items()},
                   {e: JumpShift.from_dict(j) for e, j in (d.get("jump_shifts") or {}).items()},
                   d)


@dataclass(frozen=True)
class Verdict:
    """One row of the verdict table (:mod:`compare.campaign.verdicts`)."""

    id: str
    metric: str
    backend: str
    value: float | None
    tolerance: float | None
    passed: bool
    unit: str = ""
    reason: str = ""
    detail: str = ""

    @classmethod
    def from_dict(cls, d) -> "Verdict":
        return cls(d.get("id", ""), d.get("metric", ""), d.get("backend", ""),
                   num(d.get("value")), num(d.get("tolerance")), bool(d.get("passed")),
                   d.get("unit", ""), d.get("reason", ""), d.get("detail", ""))


@dataclass(frozen=True)
class Timings:
    """Costs of the campaign.  ``cpu_by_job`` maps ``'kind:backend'`` to CPU
    seconds when computed (None in a schema-2 summary, whose ``cpu_by_job``
    held wall time: then ``wall_by_job`` has it); ``spent_by_job`` the CPU
    seconds this campaign spent (0 for jobs served by the store);
    ``from_store`` counts the jobs served by the store; ``load_average`` is
    the 1-minute load at the start and end."""

    total_wall_s: float | None
    cpu_by_job: Mapping
    spent_by_job: Mapping
    wall_by_job: Mapping
    from_store: int | None
    n_jobs: int | None
    load_average: tuple

    @classmethod
    def from_dict(cls, d, schema: int) -> "Timings":
        d = d or {}
        if schema < 3:  # its cpu_by_job was wall time
            return cls(num(d.get("total")), {}, {}, dict(d.get("cpu_by_job") or {}), None,
                       None, ())
        return cls(num(d.get("total")), dict(d.get("cpu_by_job") or {}),
                   dict(d.get("spent_by_job") or {}), dict(d.get("wall_by_job") or {}),
                   d.get("from_store"), d.get("n_jobs"), tuple(d.get("load_average") or ()))


@dataclass(frozen=True)
class LongRun:
    """A fixed-window run of one engine (no early stop): free rest or rest after
    a pulse, over tens of seconds; pivot creep and drift of the frame."""

    backend: str
    case: str
    t_max: float | None
    status: str
    pivot_sliding: float | None
    theta_final: float | None
    psi_final: float | None
    cpu_s: float | None
    passed: bool | None
    detail: str = ""
    scene: str = ""
    model_status: str = ""
    t_end: float | None = None
    cpu_per_sim_s: float | None = None

    @classmethod
    def from_dict(cls, d) -> "LongRun":
        return cls(d.get("backend", ""), d.get("case", ""), num(d.get("t_max")),
                   d.get("status", ""), num(d.get("pivot_sliding")), num(d.get("theta_final")),
                   num(d.get("psi_final")), num(d.get("cpu_s")), d.get("passed"),
                   d.get("detail", ""), d.get("scene", ""), d.get("model_status", ""),
                   num(d.get("t_end")), num(d.get("cpu_per_sim_s")))


@dataclass(frozen=True)
class Summary:
    """The whole ``summary.json`` (see the module docstring)."""

    schema_version: int
    quick: bool
    provenance: Mapping
    config: Mapping
    scene: Mapping
    settings: Mapping
    versions: Mapping
    comparisons: tuple  # dicts (compare.measure.trajectories.TrajectoryComparison)
    restitution: tuple  # dicts (compare.measure.restitution.RestitutionResult)
    spectra: Mapping  # case -> SpectrumCase
    verdicts: tuple  # Verdict
    timings: Timings
    errors: tuple
    trust: Mapping  # engine -> trust row (compare.report.trust.trust_table)
    long_runs: tuple = ()  # LongRun
    raw: Mapping = field(default_factory=dict, repr=False, compare=False)

    @property
    def engines(self) -> tuple:
        return tuple(self.config.get("engines", ()))

    @property
    def threshold_tolerance(self) -> float:
        return float(self.config.get("tolerances", {}).get("threshold", 0.02))

    def points(self, engine: str) -> list[ThresholdResult]:
        """Every threshold point of ``engine``, both curves."""
        return [p for case in self.spectra.values() for p in case.engines.get(engine, ())]

    @classmethod
    def from_dict(cls, d: Mapping) -> "Summary":
        schema = int(d.get("schema_version") or 1)
        return cls(schema, bool(d.get("quick")), d.get("provenance") or {},
                   d.get("config") or {}, d.get("scene") or {}, d.get("settings") or {},
                   d.get("versions") or {}, tuple(d.get("comparisons") or ()),
                   tuple(d.get("restitution") or ()),
                   {k: SpectrumCase.from_dict(k, v) for k, v in (d.get("spectra") or {}).items()},
                   _tuple(d.get("verdicts"), Verdict), Timings.from_dict(d.get("timings"), schema),
                   tuple(d.get("errors") or ()), d.get("trust") or {},
                   _tuple(d.get("long_runs"), LongRun), d)


def load(path: str | Path) -> Summary:
    """Read ``summary.json`` at ``path`` into a :class:`Summary`; ``ValueError``
    naming the file when it is not a regular file, too large, nested too deep,
    of a schema this version does not read, or not shaped like a summary."""
    from trilith_xval.scenes.safe_read import read_json
    where = f"summary file {str(path)!r}"
    doc = read_json(path, where, schema_versions=range(1, SCHEMA_VERSION + 1))
    try:
        return Summary.from_dict(doc)
    except (KeyError, TypeError, AttributeError, ValueError, IndexError) as exc:
        raise ValueError(f"{where}: not a summary ({type(exc).__name__}: {exc})") from None

