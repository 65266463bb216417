"""What ``trilith map`` and ``trilith map --record`` print, and the engine grid they
share."""
from __future__ import annotations

__all__ = ["print_map_summary", "subsample"]


def print_map_summary(m, what: str) -> None:
    """One map's headline (``what``: its grid), its cost in CPU seconds (wall beside)
    and the number of cells per verdict."""
    print(f"{m.backend}: {what} in {m.cpu_s:.2f} CPU s ({m.wall_time:.2f} s wall)")
    for lab, n in m.counts().items():
        if n:
            print(f"  {lab:>26}: {n}")


def subsample(values, n: int):
    """At most ``n`` of ``values``, evenly spread, the ends kept (an engine grid on the
    model's)."""
    import numpy as np
    if values.size <= n:
        return values
    return values[np.unique(np.round(np.linspace(0, values.size - 1, n)).astype(int))]
