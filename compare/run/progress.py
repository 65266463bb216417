"""Progress of long work, for a person at a terminal and for one reading a pipe or a log.

:func:`bar` is tqdm's bar when stderr is a terminal.  When it is not (piped, logged,
under CI) and :data:`PIPED_LINES` is on, it is :class:`Lines`: one stderr line at
each tenth of the work, ``desc: done/total unit, elapsed s``, so a run of minutes is
never silent.  The ``trilith`` command turns :data:`PIPED_LINES` on unless ``-q``;
from Python it is off (a library prints nothing unasked).

>>> import io, contextlib
>>> err = io.StringIO()
>>> with contextlib.redirect_stderr(err):
...     b = Lines(4, "spectrum", "points")
...     for _ in range(4):
...         b.update()
>>> [line.split(",")[0] for line in err.getvalue().splitlines()]
['spectrum: 1/4 points', 'spectrum: 2/4 points', 'spectrum: 3/4 points', 'spectrum: 4/4 points']
"""
from __future__ import annotations

import sys
import time

__all__ = ["bar", "Lines", "PIPED_LINES"]

PIPED_LINES = False


class Lines:
    """A stderr line at each tenth of ``total`` (and at the end): the count done,
    the unit and the elapsed wall time; the same ``update``/``close`` as tqdm."""

    def __init__(self, total: float, desc: str, unit: str = ""):
        self.total, self.desc, self.unit = total, desc, unit
        self.done, self.t0, self.next = 0, time.perf_counter(), 1

    def update(self, n: float = 1) -> None:
        self.done += n
        if self.total and self.done * 10 >= self.next * self.total:
            self.next = int(self.done * 10 // self.total) + 1
            unit = f" {self.unit}" if self.unit else ""
            print(f"{self.desc}: {self.done:g}/{self.total:g}{unit}, "
                  f"{time.perf_counter() - self.t0:.0f} s", file=sys.stderr, flush=True)

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class _Silent(Lines):
    def update(self, n: float = 1) -> None:
        self.done += n


def bar(total: float, desc: str, unit: str = "", **tqdm_options):
    """A progress bar over ``total`` items of ``unit`` named ``desc`` (module
    docstring): tqdm at a terminal (``tqdm_options`` passed on, ``leave=False``
    by default), :class:`Lines` on a pipe when :data:`PIPED_LINES`, else silent."""
    if sys.stderr.isatty():
        from tqdm import tqdm
        tqdm_options.setdefault("leave", False)
        return tqdm(total=total, desc=desc, unit=unit or "it", file=sys.stderr, **tqdm_options)
    return Lines(total, desc, unit) if PIPED_LINES else _Silent(total, desc, unit)
