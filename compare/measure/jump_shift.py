"""Where an engine's verdict flips across a mode jump, as a frequency.

Near a mode jump the threshold curve is discontinuous in Omega: a small shift of
the jump moves the threshold a lot, so the jump is measured as a frequency: at an
amplitude between the two threshold levels of the jump the verdict flips across
the jump frequency; that flip is bisected in Omega, in the engine and in the
reference alike.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

from trilith_xval.compare.measure import thresholds
from trilith_xval.compare.measure.thresholds import _check_positive
from trilith_xval.compare.measure.trajectories import Provenance, settings_provenance

__all__ = ["JumpShift", "engine_jump_frequency"]


@dataclass(frozen=True)
class JumpShift:
    """Where a backend's verdict flips across a mode jump at a fixed amplitude.

    ``omega_reference`` comes from the same bisection on the reference backend,
    so the shift compares like with like; NaN when the flip was not bracketed.
    """

    amplitude: float
    kind: str
    omega_reference: float
    omega_engine: float
    omega_tol: float
    n_runs: int
    provenance: Provenance

    @property
    def shift(self) -> float:
        return self.omega_engine - self.omega_reference

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out.update(provenance=self.provenance.to_dict(), shift=self.shift)
        return out


def _flip_frequency(backend: str, scene, amplitude: float, w_lo: float, w_hi: float,
                    settings, kind: str, omega_tol: float, max_expand: int) -> tuple[float, int]:
    """Bisect the frequency in ``[w_lo, w_hi]`` where the verdict at ``amplitude``
    flips; widens by the bracket width (up to ``max_expand`` times) if both ends agree."""
    runs = 0

    def probe(w: float) -> bool:
        nonlocal runs
        runs += 1
        return thresholds.overturns(backend, scene, w, amplitude, settings, kind).overturned

    width = w_hi - w_lo
    v_lo, v_hi = probe(w_lo), probe(w_hi)
    for i in range(max_expand):
        if v_lo != v_hi:
            break
        # Widen on both sides: the engine's jump may sit on either side of the model's.
        w_lo, w_hi = max(w_lo - width, 0.5 * w_lo), w_hi + width
        v_lo, v_hi = probe(w_lo), probe(w_hi)
    if v_lo == v_hi:
        return math.nan, runs
    while w_hi - w_lo > omega_tol:
        mid = 0.5 * (w_lo + w_hi)
        if probe(mid) == v_lo:
            w_lo = mid
        else:
            w_hi = mid
    return 0.5 * (w_lo + w_hi), runs


def engine_jump_frequency(backend: str, scene, amplitude: float, omega_lo: float,
                          omega_hi: float, settings=None, *, kind: str = "sine",
                          reference_backend: str = "analytic-fast", reference_settings=None,
                          omega_tol: float = 0.02, max_expand: int = 2) -> JumpShift:
    """Frequency of a mode jump in ``backend`` and in the reference, at ``amplitude``.

    ``[omega_lo, omega_hi]`` should bracket the model's jump (e.g. the two
    spectrum frequencies where the overturning mode changes) and ``amplitude``
    lie between the threshold levels on either side.  ``omega_tol`` [rad/s]: final
    bracket width (0.02 rad/s, far below the spectra's 0.1-1 rad/s steps).
    """
    amplitude = _check_positive("amplitude", amplitude)
    omega_lo = _check_positive("omega_lo", omega_lo)
    omega_hi = _check_positive("omega_hi", omega_hi)
    if not omega_hi > omega_lo:
        raise ValueError(f"omega_hi must be > omega_lo={omega_lo:g}, got {omega_hi!r}")
    omega_tol = _check_positive("omega_tol", omega_tol)
    t0 = time.perf_counter()
    w_ref, _ = _flip_frequency(reference_backend, scene, amplitude, omega_lo, omega_hi,
                               reference_settings, kind, omega_tol, max_expand)
    t1 = time.perf_counter()
    w_eng, runs = _flip_frequency(backend, scene, amplitude, omega_lo, omega_hi, settings,
                                  kind, omega_tol, max_expand)
    del t0
    return JumpShift(amplitude, kind, w_ref, w_eng, omega_tol, runs,
                     settings_provenance(backend, settings, time.perf_counter() - t1))
