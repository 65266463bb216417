"""`trilith --version`: the version, and the commit when run from a git checkout;
never a failure without git."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from trilith_xval.compare.cli.main import main

ROOT = Path(__file__).resolve().parents[3]


def _version(capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    out, err = capsys.readouterr()
    assert err == ""
    return out


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                    reason="needs git and a checkout")
def test_version_names_the_commit_of_the_checkout(capsys):
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                          text=True, check=True).stdout.strip()
    out = _version(capsys)
    assert out.startswith("trilith ") and f"(commit {head[:12]}" in out
    assert len(out.splitlines()) == 1


def test_version_without_git_is_the_version_alone(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))  # no git program to be found
    out = _version(capsys)
    assert out.startswith("trilith ") and "commit" not in out
