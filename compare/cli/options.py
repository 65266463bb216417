"""Options and checks shared by the subcommands: scene, overrides, pulse shape,
engines, workers, output paths (:mod:`compare.cli.output_paths`), JSON envelope
and number formatting, run store and engine settings files (a pulse or record and
the run budget: :mod:`compare.cli.excitation_args`).

Every check here runs before any simulation ("at the door") and raises
``ValueError`` naming the option; ``compare.cli.main`` turns it into one
``error: ...`` line and exit code 2.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

from trilith_xval.analytic.parameters import Scene, glossary_text
from trilith_xval.scenes import load_scene

from trilith_xval.compare.campaign.grids import parse_omega_range, parse_range  # noqa: F401  (the CLI's parsers)
from trilith_xval.compare.cli.output_paths import check_output_path  # noqa: F401  (every command's)
from trilith_xval.compare.run.jsonable import plain

SETTABLE = ("b", "lam", "mu", "gamma", "l", "column_mass", "J_G", "gap", "lintel_height",
            "hinge_x", "depth", "g")
# Version of the --json documents (simulate, restitution, spectrum); bumped when a
# key changes meaning or disappears.  1: inputs echoed, 'engine', 'timings' block.
# 2: simulate's 'overturn_time' is the verdict's time (as Trajectory.overturn_time);
# the last rise past alpha it used to mean is 'exceeds_alpha_time'.
SCHEMA_VERSION = 2
# Formats matplotlib writes without extra packages (--plot).
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".tif", ".tiff", ".eps", ".ps",
                 ".webp")
# -q / -v, set by compare.cli.main from the subcommand's flags: -1 quiet, 0 normal, 1 verbose.
VERBOSITY = 0


def info(message: str) -> None:
    """A line for a person (file written, warnings); silenced by ``-q``."""
    if VERBOSITY >= 0:
        print(message)


def step_notes(engines, scenes) -> None:
    """One stderr line per engine whose calibrated threshold step does not hold on a
    scene (outside its calibration's domain: the reference step runs); ``-q``
    silences it."""
    import sys

    from trilith_xval.compare.campaign.settings_file import domain_notes
    if VERBOSITY >= 0:
        for line in domain_notes(engines, scenes):
            print(f"note: {line}", file=sys.stderr)


def detail(message: str) -> None:
    """A line shown only with ``-v`` (timings, versions, settings)."""
    if VERBOSITY > 0:
        print(message)


def add_scene_args(parser: argparse.ArgumentParser, several: bool = False) -> None:
    """``--scene`` (with ``several``: repeatable, globs allowed, default fig5),
    ``--set NAME=VALUE`` and ``--no-pendulum``, in a group whose description
    says what each scene value means (:data:`analytic.parameters.GLOSSARY`)."""
    parser = scene_group(parser)
    if several:
        parser.add_argument("--scene", action="append", default=None,
                            metavar="NAME|FILE|GLOB",
                            help="scene name (see 'trilith scenes'), path to a TOML file, or a "
                                 "glob of names such as 'fig8_*'; repeat for several "
                                 "(default: fig5)")
    else:
        parser.add_argument("--scene", default="fig5",
                            help="scene name (scenes/data/*.toml, see 'trilith scenes') or "
                                 "path to a TOML file")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="NAME=VALUE",
                        help=f"override a scene value; NAME in {', '.join(SETTABLE)}")
    parser.add_argument("--no-pendulum", action="store_true", help="remove the pendulum (gamma = 0)")


def scene_group(parser: argparse.ArgumentParser):
    """An argument group for the scene options, described by the glossary."""
    return parser.add_argument_group("scene (values in 'trilith scenes')",
                                     description=glossary_text())


def parse_overrides(items: list[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}")
        if name not in SETTABLE:
            raise ValueError(f"--set: unknown name {name!r}; allowed: {', '.join(SETTABLE)}")
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"--set {name}: {value!r} is not a number") from None
        if not math.isfinite(number):
            raise ValueError(f"--set {name}: must be finite, got {value!r}")
        out[name] = number
    return out


def scenes_from_args(args: argparse.Namespace) -> list[Scene]:
    """Every scene of a repeatable ``--scene`` (``add_scene_args(several=True)``):
    names, files and globs of names, in the order given, each once; each with
    the ``--set`` overrides and ``--no-pendulum``."""
    import fnmatch

    from trilith_xval.scenes import scene_names
    names: list[str] = []
    for item in args.scene or ["fig5"]:
        if any(c in item for c in "*?[") and not Path(item).exists():
            hits = [n for n in scene_names() if fnmatch.fnmatchcase(n, item)]
            if not hits:
                raise ValueError(f"--scene: {item!r} matches no scene; allowed: "
                                 f"{', '.join(scene_names())}, a file or a glob of names")
        else:
            hits = [item]
        names += [n for n in hits if n not in names]
    return [scene_from_args(argparse.Namespace(**{**vars(args), "scene": n})) for n in names]


def scene_from_args(args: argparse.Namespace) -> Scene:
    """The scene file first (its errors name the file), then the ``--set``
    overrides (their errors name ``--set``), then ``--no-pendulum``."""
    overrides = parse_overrides(args.overrides)
    scene = load_scene(args.scene)
    kind_fields = getattr(scene, "kind", None) and set(scene.field_names())
    for name in overrides if kind_fields else ():
        if name not in kind_fields:
            raise ValueError(f"--set {name}: not a value of the {scene.kind} kind; allowed: "
                             f"{', '.join(sorted(kind_fields & set(SETTABLE)))}")
    if overrides:
        try:
            scene = scene.replace(**overrides)
        except (TypeError, ValueError) as exc:
            shown = " ".join(f"{k}={v:g}" for k, v in overrides.items())
            raise ValueError(f"--set {shown}: {exc}") from None
    if getattr(args, "no_pendulum", False):
        scene = scene.without_pendulum()
    check_kind(scene, getattr(args, "command", None))
    return scene


# The commands that run a scene of another kind (analytic.kinds), which the model
# does not cover: the engines alone (simulate), their consensus (spectrum
# --consensus, trust, report, map, fragility, restitution), the engine against its own
# reference step (calibrate), the drawings (record, view), the listing (scenes).
KIND_COMMANDS = ("simulate", "spectrum", "scenes", "trust", "report", "map", "record", "view",
                 "fragility", "calibrate", "restitution")


def check_structure_engines(names, kind: str, command: str) -> None:
    """One line refusing an engine that builds the parametric trilith only
    (:data:`engines.geometry.STRUCTURE_ENGINES`) for a scene of ``kind``."""
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    for name in names:
        if name not in STRUCTURE_ENGINES:
            raise ValueError(f"trilith {command}: {name} runs the parametric trilith only, not "
                             f"the {kind} kind (engines that run it: "
                             f"{', '.join(STRUCTURE_ENGINES)})")


def check_kind(scene, command: str | None) -> None:
    """One line refusing a scene of another kind than the trilith in a command that
    needs the analytic model (``command``: the subcommand's name; None, e.g. a
    function called from Python, checks nothing)."""
    kind = getattr(scene, "kind", "trilith")
    if kind == "trilith" or command is None or command in KIND_COMMANDS:
        return
    raise ValueError(f"trilith {command}: scene {scene.name!r} is of the {kind} kind, which the "
                     f"analytic model does not cover; {', '.join(KIND_COMMANDS)} run it "
                     f"(docs/geometry.md)")


def add_pulse_kind_arg(parser: argparse.ArgumentParser) -> None:
    """``--pulse`` and the M-P shape options (``compare/cli/pulse_shape.py``)."""
    from .pulse_shape import add_pulse_shape_args
    add_pulse_shape_args(parser)


def add_engine_arg(parser: argparse.ArgumentParser, default: str = "analytic",
                   allowed: tuple[str, ...] | None = None) -> None:
    from trilith_xval.engines import backend_names
    names = allowed or backend_names()
    parser.add_argument("--engine", default=default, metavar="NAME",
                        help=f"backend: {', '.join(names)}")


def add_engine_list_arg(parser: argparse.ArgumentParser, default: tuple[str, ...] | None,
                        none_ok: bool = False) -> None:
    """``--engine NAME[,NAME...]``, ``all`` (and ``none`` where ``none_ok``); read
    with :func:`parse_engine_list`.  ``default`` None: the engines marked
    affordable (:func:`engines.default_engines`), resolved when the command runs
    (reading the flag imports every engine)."""
    from trilith_xval.engines import engine_names
    extra = ", or none" if none_ok else ""
    parser.add_argument("--engine", dest="engine",
                        default=None if default is None else ",".join(default),
                        metavar="NAME[,NAME...]",
                        help=f"comma-separated engines from {', '.join(engine_names())}, "
                             f"all{extra}" + ("" if default is not None else
                                              " (default: the engines marked affordable, "
                                              "about a CPU second per threshold point)"))


def parse_engine_list(text: str | None, option: str = "--engine",
                      none_ok: bool = False) -> tuple[str, ...]:
    """The door's one engine list: ``'a,b'``, ``'all'`` (every registered engine,
    :func:`engines.engine_list`) or, where ``none_ok``, ``'none'``; an empty list,
    an unknown or a repeated name is refused naming ``option``; None (the flag not
    given where its default is None) is :func:`engines.default_engines`."""
    from trilith_xval.engines import default_engines, engine_list, engine_names
    if text is None:
        return default_engines()
    if none_ok and text.strip() == "none":
        return ()
    names = [n.strip() for n in text.split(",")]
    allowed = ", ".join(engine_names()) + ", all" + (", none" if none_ok else "")
    if not any(names):
        raise ValueError(f"{option} must name at least one of {allowed}, got {text!r}")
    unknown = [n for n in names if n not in engine_names() and n != "all"]
    if unknown:
        raise ValueError(f"{option}: unknown engine {unknown[0]!r}; allowed: {allowed}")
    if "all" in names and len(names) > 1:
        raise ValueError(f"{option}: 'all' stands alone, got {text!r}")
    if len(set(names)) != len(names):
        raise ValueError(f"{option}: an engine is named twice in {text!r}")
    return engine_list(text)


def add_workers_arg(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--workers", type=int, default=-1, metavar="N",
                        help="parallel processes; -1 = all cores, -2 = all but one (as "
                             "scikit-learn's n_jobs); results do not depend on it")


def resolve_workers(n: int, option: str = "--workers") -> int:
    """``n >= 1`` as given (at most 256); ``n <= -1``: ``cpu_count + 1 + n``."""
    cores = os.cpu_count() or 1
    if n == 0 or n > 256 or n < -cores:
        raise ValueError(f"{option} must be in [1, 256] or in [-{cores}, -1] (-1 = all "
                         f"{cores} cores), got {n}")
    return n if n > 0 else cores + 1 + n


def envelope(command: str, inputs: dict, body: dict, timings: dict) -> dict:
    """The --json document: schema version, command, inputs, the result's keys,
    and last the wall times, so that everything before ``timings`` is
    byte-identical between reruns."""
    doc = {"schema_version": SCHEMA_VERSION, "command": command, "inputs": inputs}
    doc.update(body)
    doc["timings"] = timings
    return doc


def sig(value, digits: int = 4) -> str:
    """``value`` with ``digits`` significant digits (``'-'`` for None, ``nan`` kept)."""
    if value is None:
        return "-"
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value)
    return f"{float(value):.{digits}g}"


def format_quantity(value, unit: str) -> str:
    """A measured value in its unit for a person: relative errors in percent."""
    if value is None:
        return "not measured"
    if unit == "relative":
        return f"{100.0 * float(value):.3g} %"
    if unit == "count":
        return f"{int(value)}"
    return f"{float(value):.3g} {unit}".rstrip()


def print_json(obj) -> None:
    """``obj`` as strict JSON on stdout (:func:`compare.run.jsonable.plain`)."""
    json.dump(plain(obj), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")




# --- run store, scheduler and interruption ---
def add_store_args(parser: argparse.ArgumentParser, scheduler: bool = False) -> None:
    """``--cache DIR``, ``--no-cache`` and, with ``scheduler``, ``--scheduler ADDRESS``."""
    from trilith_xval.compare.run.store import default_cache_dir

    group = parser.add_mutually_exclusive_group()
    group.add_argument("--cache", metavar="DIR", default=None,
                       help="run store directory: finished runs are reused, a killed run "
                            f"resumes [$TRILITH_CACHE or {default_cache_dir()}]")
    group.add_argument("--no-cache", action="store_true",
                       help="compute everything, store nothing")
    if scheduler:
        parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                            help="run on a Dask distributed cluster, e.g. tcp://host:8786 "
                                 "(default: local processes)")


def use_store(args: argparse.Namespace):
    """Activate the run store (and scheduler) the options ask for; returns the store
    (None with ``--no-cache``).  Call before any work: a bad ``--cache`` or
    ``--scheduler`` is a usage error."""
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.store import RunStore

    address = getattr(args, "scheduler", None)
    if address is not None and not (address.startswith(("tcp://", "tls://", "inproc://",
                                                        "ucx://")) and "://" in address):
        raise ValueError(f"--scheduler must be an address like tcp://host:8786, got {address!r}")
    if address is not None:
        runs.check_scheduler(address)  # an address with no scheduler: refused now
    runs.set_scheduler(address)
    runs.STATS.clear()
    store = None
    if not getattr(args, "no_cache", False):
        directory, source = store_location(args)
        store = RunStore(directory, source=source)
    runs.activate(store)
    return store


def store_location(args: argparse.Namespace) -> tuple[str, str]:
    """The run store's directory and what named it (``'--cache'``,
    ``'TRILITH_CACHE'`` or ``'the default store'``), for messages; an empty
    ``--cache`` is refused (it would silently mean the default store)."""
    from trilith_xval.compare.run.store import default_cache_dir, default_cache_source
    cache = getattr(args, "cache", None)
    if cache is not None:
        if not cache.strip():
            raise ValueError("--cache must name a directory, got an empty string")
        return cache, "--cache"
    return str(default_cache_dir()), default_cache_source()


# --- engine settings files ---
def add_settings_arg(parser: argparse.ArgumentParser) -> None:
    """``--settings FILE``: engine settings as ``trilith calibrate --settings-out``
    writes them; read with :func:`settings_from_args`."""
    parser.add_argument("--settings", metavar="FILE", default=None,
                        help="engine settings file (TOML, one [engine] table per engine, as "
                             "'trilith calibrate --settings-out' writes): every run of those "
                             "engines uses them (docs/calibrate.md)")


def settings_from_args(args: argparse.Namespace, engines: tuple[str, ...]):
    """The ``--settings`` file (a :class:`compare.campaign.settings_file.SettingsFile`)
    or None.  Refused whole before any run: a bad key or value (naming the table,
    the key and its allowed range), an unknown engine table, or a file with no
    table for any of ``engines`` (the engines this command runs), which would
    silently change nothing."""
    path = getattr(args, "settings", None)
    if path is None:
        return None
    from trilith_xval.compare.campaign.settings_file import read_settings_file
    try:
        loaded = read_settings_file(path)
    except ValueError as exc:
        raise ValueError(f"--settings: {exc}") from None
    if not any(name in loaded.tables for name in engines):
        raise ValueError(f"--settings: {path!r} has no table for "
                         f"{', '.join(engines) or 'an engine (this run is analytic)'}; "
                         f"its tables: {', '.join(loaded.tables) or 'none'}")
    return loaded


def file_options(loaded, engine: str) -> dict:
    """The options ``--settings`` sets for ``engine`` (empty without a file)."""
    return {} if loaded is None else loaded.options(engine)


def run_spec(engine: str, scene, excitation, loaded=None, *, calibrated: bool = False,
             overrides: dict | None = None):
    """``engine``'s run, resolved once (:class:`compare.run.spec.RunSpec`): its
    defaults, its calibration where ``calibrated`` (threshold searches), the
    ``--settings`` table (``loaded``; refused when the file's ``[domain]`` is of
    another kind than ``scene``), then ``overrides`` (the command line)."""
    from trilith_xval.compare.run.spec import RunSpec
    if loaded is not None and loaded.options(engine):
        loaded.check_scene(scene)
    return RunSpec.resolve(engine, scene, excitation, calibrated=calibrated,
                           file_options=file_options(loaded, engine),
                           file_name="" if loaded is None else repr(str(loaded.path)),
                           overrides=overrides)


def settings_line(loaded, engine: str) -> str:
    """One line saying which ``--settings`` values ``engine`` ran with."""
    shown = ", ".join(f"{k} = {v}" for k, v in loaded.options(engine).items())
    return f"{engine} settings from {loaded.path} (sha256 {loaded.sha256[:12]}): {shown or 'none'}"
