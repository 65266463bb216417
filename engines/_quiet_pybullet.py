"""pybullet, imported without its banner: its C library prints "pybullet build
time: ..." on stderr at import, which would clutter every run and break the CLI's
one-line errors.  fd 2 goes to /dev/null for the import only.  Import ``pybullet``
from here (``from trilith_xval.engines._quiet_pybullet import pybullet as pb``)."""
from __future__ import annotations

import os
import sys


def _import_quietly():
    if "pybullet" in sys.modules:
        return sys.modules["pybullet"]
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        import pybullet
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


pybullet = _import_quietly()
