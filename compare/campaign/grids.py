"""Grids given as text: ``'START:STOP:STEP'`` or ``'V1,V2,...'`` (the CLI's ``--omega``
and ``--amplitude``, and a study file's ``omega``)."""
from __future__ import annotations

import math

__all__ = ["parse_range", "parse_omega_range"]


def parse_range(spec: str, option: str, unit: str = "rad/s", lo: float = 0.0,
                hi: float = 1e4, max_count: int = 100_000):
    """``'START:STOP:STEP'`` (STOP included) or ``'V1,V2,...'`` -> a sorted-as-given
    float array, every value in ``(lo, hi]``; ValueError naming ``option`` otherwise.
    Used for ``--omega`` (frequencies) and ``--amplitude`` (``trilith map``)."""
    import numpy as np
    text = str(spec).strip()
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) != 3:
                raise ValueError
            start, stop, step = parts
            if not all(math.isfinite(p) for p in parts) or step <= 0 or stop < start:
                raise ValueError
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            if n > max_count:
                raise ValueError(f"{option} must give 1 to {max_count} values, got {n}")
            values = np.round(start + step * np.arange(n), 12)
        else:
            values = np.array([float(p) for p in text.split(",")])
    except ValueError as exc:
        if str(exc).startswith(option):
            raise
        raise ValueError(f"{option} expects START:STOP:STEP with {lo:g} < START <= STOP, "
                         f"STEP > 0 (or a comma list), got {spec!r}") from None
    if values.size == 0 or values.size > max_count:
        raise ValueError(f"{option} must give 1 to {max_count} values, got {values.size}")
    if not np.all(np.isfinite(values)) or np.any(values <= lo) or np.any(values > hi):
        raise ValueError(f"{option}: every value must be in ({lo:g}, {hi:g}] {unit}, "
                         f"got {spec!r}")
    return values


def parse_omega_range(spec: str, option: str = "--omega"):
    """``'START:STOP:STEP'`` (STOP included) or ``'W1,W2,...'`` -> frequencies in
    ``analytic.excitation.OMEGA_RANGE`` [rad/s] (a pulse lasts at most 2 pi / 0.1 s)."""
    from trilith_xval.analytic.excitation import OMEGA_RANGE
    lo, hi = OMEGA_RANGE
    values = parse_range(spec, option, "rad/s", 0.0, hi)
    if values.min() < lo:
        raise ValueError(f"{option}: every frequency must be in [{lo:g}, {hi:g}] rad/s, "
                         f"got {spec!r}")
    return values
