"""Engine settings files: one TOML table per engine, as ``trilith calibrate`` writes them.

::

    # trilith calibrate --engine pymunk --metric thresholds
    [pymunk]
    dt = 0.0005

The calibrated threshold settings of each engine ship in its folder with the
domain they hold in (:mod:`engines.calibration`; :func:`threshold_options`):
every threshold search on a scene inside that domain starts from them, outside
it from the engine's reference settings; restitution and time histories keep the
engine's defaults, which are calibrated for them.  A calibration file (with its
``[domain]`` and ``[calibration]`` tables) is also a settings file.

Every key is a field of that engine's ``Settings`` and is validated by it
(:func:`engines.configure`), so a file is refused as a whole, before any run, with
the file, the table and the key named.  Data only: nothing in the file is
evaluated.
"""
from __future__ import annotations

import hashlib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["SettingsFile", "load_settings_file", "read_settings_file", "settings_toml",
           "threshold_options", "domain_notes", "RUN_FIELDS"]

# Larger files are not settings files (a handful of keys per engine).
MAX_BYTES = 64 * 1024
# Fields each command sets per run (the release tilt of a free-rocking run, the
# window and stop rule of a verdict, the overturning criterion of a spectrum): a
# settings file holding them would silently change what is measured, not how.
RUN_FIELDS = ("theta0", "psi0", "t_max", "early_stop", "verdict_only", "criterion")


@dataclass(frozen=True)
class SettingsFile:
    """A settings file as read: its path, the SHA-256 of its bytes (which settings
    produced a number, even after the file is edited) and its tables
    ``{engine: {field: value}}``, each validated by the engine's ``Settings``."""

    path: str
    sha256: str
    tables: dict = field(default_factory=dict)
    domain: object = None  # engines.calibration.Domain of its [domain] table, or None

    def options(self, engine: str) -> dict:
        """The fields ``engine``'s table sets (empty when the file has no table for it)."""
        return dict(self.tables.get(engine, {}))

    def check_scene(self, scene) -> None:
        """ValueError naming the file when its ``[domain]`` is of another kind than
        ``scene`` (a step calibrated on a column of drums says nothing of a trilith,
        nor the reverse); a file without a ``[domain]`` is not checked.  Only the
        kind is enforced here: a trilith design's ranges are the shipped
        calibrations' rule (:func:`engines.calibration.threshold_choice`)."""
        if self.domain is None:
            return
        kind = getattr(scene, "kind", "trilith")
        if kind != self.domain.kind:
            raise ValueError(f"--settings: {self.path!r} was calibrated on the "
                             f"{self.domain.kind} kind ([domain] of the file); scene "
                             f"{scene.name!r} is of the {kind} kind: refused, the file says "
                             f"nothing of it")

    def describe(self) -> dict:
        return {"file": self.path, "sha256": self.sha256,
                "tables": {k: dict(v) for k, v in self.tables.items()}}


def load_settings_file(path) -> dict[str, dict]:
    """``{engine: {field: value}}`` from a settings TOML file, each table checked by
    the engine's ``Settings`` (:func:`read_settings_file`)."""
    return read_settings_file(path).tables


def read_settings_file(path) -> SettingsFile:
    """A settings TOML file, read once, each table checked by the engine's ``Settings``.

    Raises
    ------
    ValueError
        Unreadable, not TOML, too large, an unknown engine (naming the known
        ones), a field the engine does not have (naming its fields), a field set
        per run (:data:`RUN_FIELDS`), a value the engine refuses or a malformed
        ``[domain]``; the message starts with the file's name.
    """
    from trilith_xval.scenes.safe_read import read_bytes
    p = Path(path)
    where = f"settings file {str(p)!r}"
    data = read_bytes(p, where, MAX_BYTES)
    try:
        doc = tomllib.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError) as exc:
        raise ValueError(f"{where}: not TOML ({str(exc).splitlines()[0]})") from None
    domain = None
    if "domain" in doc:
        from trilith_xval.engines.calibration import Domain
        if not isinstance(doc["domain"], dict):
            raise ValueError(f"{where}: [domain] must be a table")
        domain = Domain.from_table(doc["domain"], where)
    return SettingsFile(str(p), hashlib.sha256(data).hexdigest(), _checked_tables(doc, where),
                        domain)


def _checked_tables(doc: dict, where: str) -> dict[str, dict]:
    from trilith_xval import engines
    from trilith_xval.engines.calibration import RESERVED_TABLES
    known = engines.engine_names()
    out = {}
    for name, table in doc.items():
        if name in RESERVED_TABLES:  # a calibration's domain and record: not settings
            continue
        if name not in known:
            raise ValueError(f"{where}: unknown engine table [{name}]; allowed: "
                             f"{', '.join(known)}")
        if not isinstance(table, dict):
            raise ValueError(f"{where}: [{name}] must be a table of settings")
        # A TOML array is a list; the Settings' sequence fields (MuJoCo's solimp)
        # are tuples, as frozen dataclasses keep them hashable.
        table = {k: tuple(v) if isinstance(v, list) else v for k, v in table.items()}
        for key, value in table.items():
            if key in RUN_FIELDS:
                raise ValueError(f"{where}: [{name}] {key} is set by each command for its "
                                 f"runs, not by a settings file (refused: "
                                 f"{', '.join(RUN_FIELDS)})")
            if isinstance(value, float) and not math.isfinite(value):
                raise ValueError(f"{where}: [{name}] {key} must be finite, got {value!r}")
        try:
            engines.configure(name, **table)
        except (TypeError, ValueError, OverflowError) as exc:
            raise ValueError(f"{where}: [{name}] {exc}") from None
        out[name] = dict(table)
    return out


def threshold_options(engine: str, scene) -> dict:
    """The options a threshold search of ``engine`` on ``scene`` starts from: the
    engine's calibrated threshold settings when ``scene`` lies in their domain,
    else none (the reference settings; :func:`engines.calibration.threshold_choice`).
    A ``--settings`` file and ``--dt`` go over them."""
    from trilith_xval.engines.calibration import threshold_choice
    return threshold_choice(engine, scene).options


def domain_notes(engines, scenes) -> list[str]:
    """One line per (engine, scene) whose calibrated threshold step does not hold
    there (the reference step runs), for a command to print before it works."""
    from trilith_xval.engines.calibration import threshold_choice
    out = []
    for e in engines:
        for sc in scenes:
            note = threshold_choice(e, sc).note
            if note and note not in out:
                out.append(note)
    return out


def settings_toml(engine: str, options: dict, comment: str = "") -> str:
    """A settings file holding ``options`` for ``engine`` (floats written with
    ``repr``: they read back bit-identical)."""
    lines = [f"# {line}" for line in comment.splitlines()] + [f"[{engine}]"]
    for key, value in options.items():
        if isinstance(value, bool):
            text = "true" if value else "false"
        elif isinstance(value, (int, float)):
            text = repr(value)
        elif isinstance(value, str):
            text = '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
        elif isinstance(value, (tuple, list)) and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
            text = "[" + ", ".join(repr(x) for x in value) + "]"
        else:
            raise TypeError(f"setting {key!r}: cannot write a {type(value).__name__}")
        lines.append(f"{key} = {text}")
    return "\n".join(lines) + "\n"
