"""``trilith scenes``: the shipped scenes with their key values and source, or
every value of the scenes given with ``--scene`` (names, files, globs), each
beside what it means."""
from __future__ import annotations

import argparse
from pathlib import Path

from trilith_xval.analytic.kinds import KindScene
from trilith_xval.analytic.parameters import GLOSSARY, glossary_text
from trilith_xval.scenes import SCENE_DIR, load_scene, scene_names

from trilith_xval.compare.cli.options import add_scene_args, envelope, print_json, scenes_from_args

# Unit of each value shown, beside the number ('' for ratios).
UNITS = {"lam": "", "b": "m", "h": "m", "mu": "", "gamma": "", "l": "m", "gap": "m",
         "lintel_height": "m", "alpha": "rad", "column_mass": "kg", "J_G": "kg m^2",
         "depth": "m", "hinge_x": "m", "g": "m/s^2"}


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "scenes", help="list the shipped scenes (scenes/data/*.toml) with their key values",
        description="Each shipped scene with lam, b, mu, gamma, l, alpha and where its "
                    "numbers come from (the file's first comment line). Any of the names "
                    "works as --scene NAME; a path to your own TOML file works too. "
                    "With --scene (or --set, --no-pendulum): every value of those scenes, "
                    "each with its meaning.")
    add_scene_args(parser, several=True)
    for action in parser._actions:  # the listing, not fig5, is what no --scene gives
        if action.dest == "scene":
            action.help = ("scene name, path to a TOML file or glob of names such as "
                           "'fig8_*' (repeatable): show every value of these scenes "
                           "(default: list every shipped scene)")
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    return parser


def source(path) -> str:
    """The file's first comment line, up to its first colon: where the numbers come from."""
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            return line.lstrip("#").strip().split(":")[0].rstrip(".")
    return ""


def values(scene) -> dict:
    """Every value of ``scene`` named as in :data:`analytic.parameters.GLOSSARY`, the
    defaults resolved; ``l`` is None without a pendulum (there is none to measure).
    A scene of another kind (:mod:`analytic.kinds`) gives its outline's values
    where it has them (a column of drums: its monolithic trilith's), None
    elsewhere, ``alpha`` its smallest body's, and its ``kind``."""
    if isinstance(scene, KindScene):
        out = dict.fromkeys(UNITS)
        if hasattr(scene, "base"):  # drums: the outline is a parametric trilith
            out.update(values(scene.base))
            out["column_mass"] = out["J_G"] = None  # the drums', not the monolith's
        out.update(depth=scene.depth, g=scene.g, alpha=scene.alpha, kind=scene.kind)
        return out
    return {"lam": scene.lam, "b": scene.b, "h": scene.h, "mu": scene.mu,
            "gamma": scene.gamma, "l": scene.pendulum_length if scene.has_pendulum else None,
            "gap": scene.d, "lintel_height": scene.lintel_thickness, "alpha": scene.alpha,
            "column_mass": scene.m1, "J_G": scene.inertia_J_G, "depth": scene.depth,
            "hinge_x": scene.hinge_x, "g": scene.g}


def rows() -> list[dict]:
    """One row per shipped scene: its name, key values and source."""
    out = []
    for name in scene_names():
        scene = load_scene(name)
        out.append({"name": name, **{k: values(scene)[k] for k in
                                     ("lam", "b", "mu", "gamma", "l", "alpha")},
                    "source": source(SCENE_DIR / f"{name}.toml")})
    return out


def _num(value, width: int, digits: int = 3) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:{width}.{digits}g}"


def _chosen(args: argparse.Namespace) -> bool:
    return bool(args.scene or args.overrides or args.no_pendulum)


def _file(scene, items) -> Path | None:
    """The file ``scene`` was read from: a path given, or the shipped file."""
    for item in items:
        path = Path(item)
        if path.suffix == ".toml" and path.stem == scene.name and path.is_file():
            return path
    shipped = SCENE_DIR / f"{scene.name}.toml"
    return shipped if shipped.is_file() else None


def _shown(path: Path) -> str:
    """A shipped file relative to the checkout (as the README names it), others as given."""
    return (str(path.relative_to(SCENE_DIR.parent.parent))
            if path.is_relative_to(SCENE_DIR) else str(path))


def _detail(args: argparse.Namespace) -> list[dict]:
    out = []
    for scene in scenes_from_args(args):
        path = _file(scene, args.scene or [])
        out.append({"name": scene.name, "file": _shown(path) if path else None,
                    "source": source(path) if path else "", **values(scene)})
        if isinstance(scene, KindScene):
            out[-1]["bodies"] = [r._asdict() for r in scene.layout()]
    return out


def run(args: argparse.Namespace) -> int:
    if _chosen(args):
        chosen = _detail(args)
        if args.json:
            print_json(envelope("scenes", {"scene": args.scene or ["fig5"],
                                           "set": args.overrides,
                                           "no_pendulum": args.no_pendulum},
                                {"scenes": chosen}, {}))
            return 0
        width = max(map(len, UNITS))
        for i, r in enumerate(chosen):
            print(("\n" if i else "") + f"{r['name']}: {r['file']}"
                  + (f" ({r['source']})" if r["source"] else ""))
            if "kind" in r:  # another kind: its bodies, then the outline's values
                print(f"  kind {r['kind']} (docs/geometry.md); bodies, upright at rest:")
                for body in r["bodies"]:
                    print(f"    {body['name']:<16} b {body['b']:.4g} m, h {body['h']:.4g} m, "
                          f"centre ({body['x']:.4g}, {body['y']:.4g}) m, {body['mass']:.4g} kg")
            for key, unit in UNITS.items():
                missing = "-  (see the bodies)" if "kind" in r else "-  (no pendulum)"
                shown = missing if r[key] is None else f"{r[key]:.6g} {unit}".rstrip()
                print(f"  {key:<{width}}  {shown:<18}  {GLOSSARY[key]}")
        return 0
    table = rows()
    if args.json:
        print_json(envelope("scenes", {"directory": "scenes/data"},
                            {"scenes": table, "glossary": GLOSSARY}, {}))
        return 0
    print(f"{'name':<20} {'lam':>5} {'b [m]':>6} {'mu':>5} {'gamma':>5} {'l [m]':>6} "
          f"{'alpha [rad]':>11}  source")
    for r in table:
        print(f"{r['name']:<20} {_num(r['lam'], 5)} {_num(r['b'], 6)} {_num(r['mu'], 5)} "
              f"{_num(r['gamma'], 5)} {_num(r['l'], 6)} {_num(r['alpha'], 11, 4)}  {r['source']}")
    print("\nwhere (trilith scenes --scene NAME|FILE shows every value of a scene):")
    print(glossary_text("  "))
    return 0
