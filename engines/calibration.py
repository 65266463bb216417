"""An engine's calibrated settings ship with it, with the domain they hold in.

Each engine folder holds ``thresholds.toml`` (package data, read with
:mod:`importlib.resources`): the settings its overturning-threshold searches
start from, the *domain* of scenes the calibration was trained and validated on,
and the held-out result::

    # trilith calibrate --engine pymunk --metric thresholds --design ...
    [pymunk]
    dt = 0.0005

    [domain]            # [lo, hi] of each coordinate (scene_coordinates)
    lam = [3.0, 7.0]
    ...

    [calibration]       # what the settings were chosen and checked on
    seed = 34
    held_out_worst_error = 0.0071
    ...

A calibrated setting holds only where it was measured: :func:`threshold_choice`
gives a scene the calibrated settings only when every coordinate lies in the
domain (and the values the calibration kept fixed are the scene's too);
otherwise the engine's reference settings (its ``Settings`` defaults), with one
line saying why.  A file whose table sets nothing (PyBullet, Drake: no coarser
step kept a Fig. 5 threshold within 1 %, and no step, the reference included, met
2 % on the sampled design) is a calibration that chose the reference.  A missing
or malformed file is an error, never a silent fallback.
"""
from __future__ import annotations

import functools
import math
import tomllib
from dataclasses import dataclass, field

from trilith_xval.analytic.parameters import G_STANDARD

__all__ = ["Domain", "Calibrated", "StepChoice", "calibrated", "threshold_choice", "reference_dt",
           "scene_coordinates", "COORDINATES", "FIXED", "RESERVED_TABLES"]

# What a user changes in a trilith, as the calibration design samples it: the
# pendulum length, the gap and the lintel's thickness as ratios, which is how
# they enter the dynamics (the model scales with the column).
COORDINATES = {
    "lam": "column slenderness h/b",
    "b": "column width [m]",
    "mu": "lintel / column mass ratio",
    "gamma": "pendulum / column mass ratio (0: no pendulum)",
    "l_over_h": "pendulum length / column height",
    "gap_over_h": "clear gap between the columns / column height",
    "lintel_height_over_b": "lintel thickness / column width",
}
# Values no calibration design varies: a scene must have these.
FIXED = {"J_G_over_uniform": 1.0, "hinge_x": 0.0, "g": G_STANDARD}
RESERVED_TABLES = ("domain", "calibration")
# Slack of a domain's bounds, relative: a value written with 15 digits is inside.
_REL_SLACK = 1e-9


def scene_coordinates(scene) -> dict:
    """The scene's coordinates of :data:`COORDINATES` and :data:`FIXED`
    (``l_over_h`` None without a pendulum)."""
    uniform = scene.m1 * (scene.b ** 2 + scene.h ** 2) / 12.0
    j_g = scene.J_G if scene.J_G is not None else uniform
    return {"lam": scene.lam, "b": scene.b, "mu": scene.mu, "gamma": scene.gamma,
            "l_over_h": scene.pendulum_length / scene.h if scene.has_pendulum else None,
            "gap_over_h": scene.d / scene.h,
            "lintel_height_over_b": scene.lintel_thickness / scene.b,
            "J_G_over_uniform": j_g / uniform, "hinge_x": scene.hinge_x, "g": scene.g}


@dataclass(frozen=True)
class Domain:
    """``ranges``: coordinate -> (lo, hi), inclusive; a coordinate absent from
    ``ranges`` was not varied, so no scene is inside for it.  ``kind``: the kind of
    scene calibrated on (``[domain] kind``, default the parametric trilith); a
    scene of another kind is outside, and a domain of another kind than the
    trilith holds over that kind's scenes (they have none of the trilith's
    coordinates; :mod:`analytic.kinds`)."""

    ranges: tuple = ()  # ((name, (lo, hi)), ...)
    no_pendulum: bool = False  # the pendulum-free curve (gamma = 0) was calibrated too
    kind: str = "trilith"

    @classmethod
    def from_table(cls, table: dict, where: str) -> "Domain":
        from trilith_xval.analytic.kinds import KINDS
        out = []
        table = dict(table)
        no_pendulum = table.pop("no_pendulum", False)
        if not isinstance(no_pendulum, bool):
            raise ValueError(f"{where}: [domain] no_pendulum must be true or false")
        kind = table.pop("kind", "trilith")
        if kind != "trilith" and kind not in KINDS:
            raise ValueError(f"{where}: [domain] kind must be one of "
                             f"{', '.join(['trilith', *KINDS])}, got {kind!r}")
        if kind != "trilith" and (table or no_pendulum):
            raise ValueError(f"{where}: [domain] of the {kind} kind takes no trilith "
                             f"coordinate, got {', '.join(table) or 'no_pendulum'}")
        for name, value in table.items():
            if name not in COORDINATES:
                raise ValueError(f"{where}: [domain] {name} is not a coordinate; allowed: "
                                 f"{', '.join(COORDINATES)}")
            if not (isinstance(value, list) and len(value) == 2
                    and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                            and math.isfinite(v) for v in value) and value[0] <= value[1]):
                raise ValueError(f"{where}: [domain] {name} must be [lo, hi] with finite "
                                 f"lo <= hi, got {value!r}")
            out.append((name, (float(value[0]), float(value[1]))))
        return cls(tuple(out), no_pendulum, kind)

    def as_dict(self) -> dict:
        if self.kind != "trilith":
            return {"kind": self.kind}
        return {**{k: list(v) for k, v in self.ranges}, "no_pendulum": self.no_pendulum}

    def outside(self, scene) -> str | None:
        """Why ``scene`` is outside (another kind, or the first coordinate that
        leaves it), or None."""
        kind = getattr(scene, "kind", "trilith")  # a Scene has no kind: the trilith
        if kind != self.kind:
            return (f"{scene.name} is of the {kind} kind, the calibration's of the "
                    f"{self.kind} kind")
        if kind != "trilith":
            return None
        coords = scene_coordinates(scene)
        ranges = dict(self.ranges)
        for name in COORDINATES:
            value = coords[name]
            if value is None:  # no pendulum: its length does not enter
                continue
            if name == "gamma" and value == 0.0:
                if not self.no_pendulum:
                    return "no pendulum (gamma = 0) was not calibrated"
                continue
            if name not in ranges:
                return f"{name} = {value:.4g} was not varied by the calibration"
            lo, hi = ranges[name]
            slack = _REL_SLACK * max(abs(lo), abs(hi), 1.0)
            if not lo - slack <= value <= hi + slack:
                return (f"{name} = {value:.4g} ({COORDINATES[name]}) is outside the "
                        f"calibrated {lo:g}-{hi:g}")
        for name, fixed in FIXED.items():
            if not math.isclose(coords[name], fixed, rel_tol=1e-9, abs_tol=1e-12):
                return f"{name} = {coords[name]:.4g} (the calibration kept {fixed:g})"
        return None


@dataclass(frozen=True)
class Calibrated:
    """An engine's calibrated settings as shipped: ``options`` (its table),
    ``domain``, ``record`` (the [calibration] table), ``source`` (the package
    resource read) and its ``command`` (the file's first comment)."""

    engine: str
    metric: str
    options: dict = field(default_factory=dict)
    domain: Domain = Domain()
    record: dict = field(default_factory=dict)
    source: str = ""
    command: str = ""

    def describe(self) -> dict:
        return {"engine": self.engine, "metric": self.metric, "options": dict(self.options),
                "domain": self.domain.as_dict(), "calibration": dict(self.record),
                "source": self.source, "command": self.command}


@dataclass(frozen=True)
class StepChoice:
    """The settings a threshold search of ``engine`` on a scene starts from:
    ``options`` (the calibrated ones inside the domain, else empty: the
    reference), ``inside`` and ``note`` (one line when outside)."""

    engine: str
    options: dict
    inside: bool
    note: str = ""


def _resource(engine: str, metric: str):
    from importlib import resources

    from trilith_xval.engines import get_backend
    package = get_backend(engine).__module__
    return resources.files(package).joinpath(f"{metric}.toml")


@functools.lru_cache(maxsize=None)
def calibrated(engine: str, metric: str = "thresholds") -> Calibrated:
    """``engine``'s shipped calibration for ``metric`` (module docstring).

    Raises
    ------
    ValueError
        The file is missing from the engine's folder, not TOML, or holds a
        setting the engine refuses or a malformed domain.
    """
    from trilith_xval import engines
    res = _resource(engine, metric)
    where = f"{engine}'s calibration {metric}.toml"
    try:
        text = res.read_text(encoding="utf-8")
    except (FileNotFoundError, OSError) as exc:
        raise ValueError(f"{where}: missing from the engine's package ({exc}); every engine "
                         f"ships one (trilith calibrate --settings-out writes it)") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where}: not TOML ({exc})") from None
    options = doc.get(engine, {})
    if not isinstance(options, dict):
        raise ValueError(f"{where}: [{engine}] must be a table of settings")
    try:
        engines.configure(engine, **options)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: [{engine}] {exc}") from None
    extra = set(doc) - {engine, *RESERVED_TABLES}
    if extra:
        raise ValueError(f"{where}: unknown table(s) {', '.join(sorted(extra))}")
    domain = Domain.from_table(doc.get("domain", {}), where)
    if options and not domain.ranges:
        raise ValueError(f"{where}: calibrated settings without a [domain]")
    first = text.splitlines()[0] if text else ""
    return Calibrated(engine, metric, dict(options), domain, dict(doc.get("calibration", {})),
                      str(res), first.lstrip("# ").strip() if first.startswith("#") else "")


def threshold_choice(engine: str, scene) -> StepChoice:
    """The calibrated threshold settings of ``engine`` for ``scene`` when the scene
    lies inside their domain (and its pendulum-free twin, for the second curve,
    always does when the scene does); else the reference, with a note."""
    cal = calibrated(engine, "thresholds")
    if not cal.options:
        return StepChoice(engine, {}, True)
    kind = getattr(scene, "kind", "trilith")  # a Scene has no kind: the trilith
    if kind != "trilith":  # calibrated on parametric triliths only
        return StepChoice(engine, {}, False,
                          f"{engine}: {scene.name} is of the {kind} kind, outside the domain "
                          f"of its calibrated threshold step (parametric triliths); the "
                          f"reference step dt = {reference_dt(engine):g} s runs")
    why = cal.domain.outside(scene)
    if why is None:
        return StepChoice(engine, dict(cal.options), True)
    ref = reference_dt(engine)
    return StepChoice(engine, {}, False,
                      f"{engine}: {scene.name} is outside the domain of its calibrated "
                      f"threshold step ({why}); the reference step dt = {ref:g} s runs")


def reference_dt(engine: str) -> float:
    """The engine's reference step [s]: the default ``dt`` of its ``Settings``, at
    which its accuracy for every metric was measured (docs/engine-trust.md)."""
    from trilith_xval import engines
    return float(engines.configure(engine).dt)
