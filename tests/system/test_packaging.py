"""One import name: the installed distribution adds only ``trilith_xval``.

The repository keeps the folders the design card names (analytic/, engines/,
compare/, scenes/); pyproject.toml maps them under ``trilith_xval``.  These tests
check that mapping against the folders, then build the wheel, install it into a
fresh environment outside the checkout and run a command there: an installed copy
must give the numbers and the calibrated step of the checkout (its settings are
package data, never read from docs/).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import venv
import zipfile
from pathlib import Path

import pytest

from tests.support.paths import ROOT

NAME = "trilith_xval"
FOLDERS = ("analytic", "compare", "engines", "scenes")


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def _package_folders() -> set[str]:
    """Every folder under the installed top-level folders that holds Python code
    or package data (scenes/data, scenes/records), as a dotted name."""
    found = set()
    for top in FOLDERS:
        for path in [ROOT / top, *(ROOT / top).rglob("*")]:
            if path.is_dir() and path.name != "__pycache__" and (
                    (path / "__init__.py").exists() or any(path.glob("*.toml"))
                    or any(path.glob("*.csv"))):
                found.add(".".join(path.relative_to(ROOT).parts))
    return found


def test_every_package_folder_is_listed_under_the_one_name():
    tool = _pyproject()["tool"]["setuptools"]
    listed = set(tool["packages"])
    expected = {f"{NAME}.{folder}" for folder in _package_folders()}
    missing, extra = expected - listed, listed - expected
    assert not missing, f"pyproject.toml [tool.setuptools] packages lacks {sorted(missing)}"
    assert not extra, f"pyproject.toml lists packages with no folder: {sorted(extra)}"
    assert tool["package-dir"] == {f"{NAME}.{f}": f for f in FOLDERS}
    assert _pyproject()["project"]["scripts"]["trilith"].startswith(f"{NAME}.")


def test_no_module_imports_a_bare_top_level_name():
    """A bare ``import engines`` works in the checkout (its root is on the path)
    but not once installed: every project import goes through the one name."""
    import re
    bare = re.compile(r"^\s*(?:>>> )?(?:from|import) (?:analytic|engines|compare|scenes)\b", re.M)
    offenders = [str(p.relative_to(ROOT)) for top in (*FOLDERS, "benchmarks", "tests")
                 for p in (ROOT / top).rglob("*.py") if bare.search(p.read_text())]
    assert not offenders, f"bare project imports in {offenders}"


def _build_wheel(tmp: Path) -> Path:
    """The wheel, built from a copy of the checkout (a build writes build/ and
    *.egg-info next to the sources: not into the user's checkout)."""
    src = tmp / "src"
    everywhere = shutil.ignore_patterns("__pycache__", "*.egg-info")
    at_root = {".git", ".venv", "build", "report", "figures", ".pytest_cache"}

    def ignore(folder, names):
        skip = set(everywhere(folder, names))
        return skip | (at_root & set(names)) if Path(folder) == ROOT else skip
    shutil.copytree(ROOT, src, ignore=ignore)
    out = tmp / "dist"
    # No build isolation: the build backend (setuptools>=77) is in the test extras,
    # so the test needs no network.
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                           "-q", "-w", str(out), str(src)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    (wheel,) = out.glob("*.whl")
    return wheel


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    return _build_wheel(tmp_path_factory.mktemp("wheel"))


def test_the_wheel_holds_one_import_name_and_the_calibrations(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {NAME}, f"the wheel installs {sorted(tops)}"
    assert not any("benchmarks" in n or n.startswith(f"{NAME}/tests") for n in names)
    for engine in ("pymunk_", "mujoco_", "dart_", "pybullet_", "drake_"):
        assert f"{NAME}/engines/{engine}/thresholds.toml" in names
    assert f"{NAME}/scenes/data/fig5.toml" in names
    # The synthetic suite (fragility --records synthetic), all twelve motions.
    assert sum(n.startswith(f"{NAME}/scenes/records/synthetic/cp-") for n in names) == 12
    assert not any(n.startswith(f"{NAME}/docs") for n in names)


def _fresh_env(tmp: Path, wheel: Path) -> Path:
    """A new virtual environment with the wheel installed and nothing of the
    checkout: the dependencies (numpy, pymunk, ...) are borrowed from the running
    environment's site-packages as a plain path, whose .pth files (the editable
    install's finder among them) are not run."""
    env = tmp / "env"
    venv.EnvBuilder(with_pip=False).create(env)
    py = env / "bin" / "python"
    site = Path(subprocess.run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    # The dependencies only: every entry of the running site-packages but the
    # checkout's own (editable) install, whose metadata would make pip take the
    # wheel as installed already and whose finder maps the checkout's folders.
    borrowed = tmp / "borrowed"
    borrowed.mkdir()
    for entry in Path(sysconfig.get_paths()["purelib"]).iterdir():
        if not entry.name.lower().startswith(("trilith", "__editable__")):
            (borrowed / entry.name).symlink_to(entry)
    (site / "borrowed_dependencies.pth").write_text(str(borrowed) + "\n")
    # pip's own settings from the environment (a PIP_*/PYTHON* variable another test
    # or the CI set) must not send the install elsewhere.
    clean = {k: v for k, v in os.environ.items()
             if not k.startswith(("PIP_", "PYTHON")) and k != "VIRTUAL_ENV"}
    proc = subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps",
                           "--no-index", "-q", str(wheel)], capture_output=True, text=True,
                          env=clean)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return env


def _spectrum(python_or_exe: list[str], cwd: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([*python_or_exe, "spectrum", "--engine", "pymunk", "--omega", "10",
                           "--json", "--no-cache", "-q"], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout)


def _physics(doc):
    """``doc`` without what the machine measured while computing it (CPU and wall
    seconds, load average): those differ between any two runs."""
    if isinstance(doc, dict):
        return {k: _physics(v) for k, v in doc.items()
                if k != "timings" and "cpu" not in k and k not in ("wall_time", "load_average")}
    if isinstance(doc, list):
        return [_physics(v) for v in doc]
    return doc


@pytest.mark.slow
def test_an_installed_wheel_answers_like_the_checkout(wheel, tmp_path):
    env = _fresh_env(tmp_path, wheel)
    work = tmp_path / "elsewhere"
    work.mkdir()
    where = subprocess.run([env / "bin" / "python", "-c",
                            f"import {NAME}.engines as e, importlib.util as u; print(e.__file__); "
                            "print([m for m in ('analytic', 'engines', 'compare', 'scenes', "
                            "'benchmarks') if u.find_spec(m)])"],
                           cwd=work, capture_output=True, text=True, check=True,
                           env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
                           ).stdout.split("\n")
    assert where[0].startswith(str(env)), f"imported from {where[0]}, not the installed wheel"
    assert where[1] == "[]", f"the install adds top-level names {where[1]}"

    installed = _spectrum([str(env / "bin" / "trilith")], work)
    checkout = _spectrum([sys.executable, "-m", f"{NAME}.compare.cli.main"], work)
    installed, checkout = _physics(installed), _physics(checkout)
    # Same step (the calibrated one, read from package data in both) and the same
    # numbers bit for bit: same code, same inputs, one process each.
    assert installed["engines"]["pymunk"]["settings"]["dt"] == \
        checkout["engines"]["pymunk"]["settings"]["dt"] == 2e-4
    assert installed["analytic"] == checkout["analytic"]
    assert installed["engines"] == checkout["engines"]
