"""``trilith view`` on a real (virtual) display: Xvfb is started, the command opens
its matplotlib window (TkAgg), and screenshots of the X screen show a drawn
scene that moves.

Skipped, with the reason, when Xvfb or Tk is missing (``.ci/run`` installs
``xvfb``; Tk comes with the Python build).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.support.paths import ROOT
XVFB = shutil.which("Xvfb")


def _has_tk() -> bool:
    try:
        import tkinter  # noqa: F401
    except ImportError:
        return False
    return True


pytestmark = [
    pytest.mark.skipif(XVFB is None, reason="no Xvfb on PATH (Debian: apt-get install xvfb; "
                                            ".ci/run installs it when apt is available)"),
    pytest.mark.skipif(not _has_tk(), reason="this Python has no tkinter: matplotlib cannot "
                                             "open a TkAgg window"),
]


def grab(display: str) -> np.ndarray | None:
    """The whole X screen as an RGB array (Pillow's XCB grab, else ImageMagick's
    ``import``); None when neither can read the display."""
    from PIL import Image, ImageGrab, features

    if features.check("xcb"):
        try:
            return np.asarray(ImageGrab.grab(xdisplay=display).convert("RGB"), dtype=float)
        except OSError:
            return None
    if shutil.which("import"):
        out = subprocess.run(["import", "-display", display, "-window", "root", "png:-"],
                             capture_output=True, timeout=30, check=False)
        if out.returncode == 0:
            import io
            return np.asarray(Image.open(io.BytesIO(out.stdout)).convert("RGB"), dtype=float)
        return None
    pytest.skip("no way to take an X screenshot (Pillow without XCB and no ImageMagick)")


@pytest.fixture
def xvfb():
    """A fresh Xvfb server; its display name (``:N``, chosen by Xvfb itself)."""
    read, write = os.pipe()
    proc = subprocess.Popen([XVFB, "-displayfd", str(write), "-screen", "0", "1280x720x24",
                             "-nolisten", "tcp"], pass_fds=(write,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    try:
        with os.fdopen(read) as fh:
            number = fh.readline().strip()
        if not number:
            pytest.skip("Xvfb did not start")
        yield f":{number}"
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def is_blank(shot: np.ndarray | None) -> bool:
    return shot is None or shot.std() < 10.0


def test_view_opens_a_window_that_moves(xvfb, tmp_path):
    env = {**os.environ, "DISPLAY": xvfb, "MPLBACKEND": "TkAgg",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    env.pop("WAYLAND_DISPLAY", None)
    cmd = [sys.executable, "-m", "trilith_xval.compare.cli.main", "view", "--scene", "fig5", "--engine", "all",
           "--amplitude", "25", "--omega", "11", "--duration", "3", "--fps", "20"]
    proc = subprocess.Popen(cmd, env=env, cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    try:
        # Three backends simulate first (a few seconds), then the window appears.
        deadline = time.monotonic() + 90.0
        first = None
        while time.monotonic() < deadline and proc.poll() is None:
            shot = grab(xvfb)
            if not is_blank(shot):
                first = shot
                break
            time.sleep(0.5)
        assert proc.poll() is None, proc.communicate(timeout=10)[1].decode()[-2000:]
        assert first is not None, "no window was drawn within 90 s"
        time.sleep(1.0)  # 20 frames later at 20 fps
        second = grab(xvfb)
        from PIL import Image
        Image.fromarray(first.astype(np.uint8)).save(tmp_path / "view_1.png")
        Image.fromarray(second.astype(np.uint8)).save(tmp_path / "view_2.png")
        # Not blank: a drawn trilith (dark outlines, light background) on the screen.
        assert (first.mean(axis=2) < 80).mean() > 1e-3
        # The scene moves: the window's pixels change between the two screenshots.
        changed = (np.abs(second - first).max(axis=2) > 30).mean()
        assert changed > 1e-3, f"only {changed:.2e} of the screen changed"
    finally:
        proc.kill()
        proc.wait(timeout=10)
