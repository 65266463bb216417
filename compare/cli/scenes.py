"""``trilith scenes``: the shipped scenes with their key values and source."""
from __future__ import annotations

import argparse

from scenes import SCENE_DIR, load_scene, scene_names

from compare.cli.options import envelope, print_json


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "scenes", help="list the shipped scenes (scenes/data/*.toml) with their key values",
        description="Each shipped scene with lam, b, mu, gamma, l, alpha and where its "
                    "numbers come from (the file's first comment line). Any of the names "
                    "works as --scene NAME; a path to your own TOML file works too.")
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    return parser


def source(path) -> str:
    """The file's first comment line, up to its first colon: where the numbers come from."""
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            return line.lstrip("#").strip().split(":")[0].rstrip(".")
    return ""


def rows() -> list[dict]:
    out = []
    for name in scene_names():
        scene = load_scene(name)
        out.append({"name": name, "lam": scene.lam, "b": scene.b, "mu": scene.mu,
                    "gamma": scene.gamma, "l": scene.pendulum_length, "alpha": scene.alpha,
                    "source": source(SCENE_DIR / f"{name}.toml")})
    return out


def run(args: argparse.Namespace) -> int:
    table = rows()
    if args.json:
        print_json(envelope("scenes", {"directory": "scenes/data"}, {"scenes": table}, {}))
        return 0
    print(f"{'name':<20} {'lam':>5} {'b [m]':>6} {'mu':>5} {'gamma':>5} {'l [m]':>6} "
          f"{'alpha [rad]':>11}  source")
    for r in table:
        print(f"{r['name']:<20} {r['lam']:5.3g} {r['b']:6.3g} {r['mu']:5.3g} {r['gamma']:5.3g} "
              f"{r['l']:6.3g} {r['alpha']:11.4g}  {r['source']}")
    return 0
