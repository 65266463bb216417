"""Overturning thresholds of a backend, measured cheaply around the analytic ones.

An engine run costs ~0.1-1 s, so an engine spectrum is not scanned: at each
frequency the engine's first overturning amplitude is bisected inside a bracket
centred on the analytic threshold ``A_ref (1 -/+ rel_bracket)``, widened
(doubling) only when the engine disagrees by more than the bracket.  With the
defaults a point costs 2 bracket runs plus ~5 bisection runs.

Near a mode jump (the threshold curve is discontinuous in Omega) a small
frequency shift moves the threshold a lot, so jumps are measured separately, as a
frequency: at an amplitude between the two threshold levels of the jump the
verdict flips across the jump frequency; that flip is bisected in Omega.
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

from analytic.excitation import Pulse

from compare.measure.trajectories import Provenance, settings_provenance

__all__ = ["ThresholdPoint", "JumpShift", "engine_threshold", "engine_jump_frequency",
           "overturns"]


def _check_positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return value


def overturns(backend: str, scene, omega: float, amplitude: float, settings=None,
              kind: str = "sine") -> tuple[bool, str, str | None]:
    """One run: ``(overturned, status, mode)`` of ``backend`` under a pulse.

    'collapsed', 'unstable' and 'undecided' runs count as not overturned; their
    status is returned so callers can flag them.  The run stops as soon as the
    verdict is certain (``verdict_only``).
    """
    from engines import configure
    from compare.run.runs import simulate
    # Only the verdict is needed: stop as soon as it is certain, overturning included.
    settings = configure(backend, settings, verdict_only=True)
    traj = simulate(backend, scene, Pulse(amplitude, omega, kind), settings)
    return traj.overturned, traj.verdict.status, traj.verdict.mode


@dataclass(frozen=True)
class ThresholdPoint:
    """A backend's first overturning amplitude at one frequency.

    ``a_engine`` is the lowest amplitude found to overturn (upper end of the final
    bracket ``[a_low, a_engine]``, whose width is ``<= rel_tol * a_reference``);
    NaN when no bracket was found within ``max_expand`` widenings.
    """

    omega: float
    kind: str
    a_reference: float
    a_engine: float
    a_low: float
    mode_reference: str | None
    mode_engine: str | None
    n_runs: int
    irregular_runs: int
    rel_tol: float
    provenance: Provenance
    probes: tuple = ()  # (amplitude, status, mode) of every run, in order

    @property
    def a_survives(self) -> float:
        """Highest amplitude below ``a_engine`` seen to *survive* (NaN if none:
        e.g. only collapsed runs below it)."""
        below = [a for a, st, _ in self.probes if st == "survived" and a < self.a_engine]
        return max(below) if below else math.nan

    @property
    def collapsed_below(self) -> bool:
        """True when a run below ``a_engine`` ended 'collapsed': the engine's frame
        broke before it overturned (the threshold is then that of a broken frame)."""
        return any(st == "collapsed" and a < self.a_engine for a, st, _ in self.probes)

    @property
    def bracketed(self) -> bool:
        return math.isfinite(self.a_engine)

    @property
    def rel_error(self) -> float:
        """``(A_engine - A_analytic)/A_analytic``."""
        return (self.a_engine - self.a_reference) / self.a_reference

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out.update(provenance=self.provenance.to_dict(), rel_error=self.rel_error,
                   bracketed=self.bracketed, a_survives=self.a_survives,
                   collapsed_below=self.collapsed_below,
                   probes=[list(p) for p in self.probes])
        return out


def engine_threshold(backend: str, scene, omega: float, a_reference: float, settings=None, *,
                     kind: str = "sine", mode_reference: str | None = None,
                     rel_bracket: float = 0.03, rel_tol: float = 2e-3,
                     max_expand: int = 5, guard: float = 0.0,
                     stop_on_collapse: bool = False) -> ThresholdPoint:
    """Bisect ``backend``'s overturning threshold at ``omega`` around ``a_reference``.

    Parameters
    ----------
    rel_bracket : float
        Initial half-width of the bracket relative to ``a_reference``, in (0, 0.5).
        3 %: engines agree with the model within ~1-2 % away from jumps.
    rel_tol : float
        Final bracket width relative to ``a_reference``, in (0, 0.5).  With
        ``2 rel_bracket <= rel_tol`` the first two runs already decide a point where
        the engine agrees (the engine spectrum does this).
        0.2 %: a tenth of the 2 % acceptance tolerance.
    max_expand : int
        Widenings (doubling the step) allowed on each side before giving up.
    guard : float
        If larger than ``rel_bracket``: first probe ``a_reference (1 - guard)``; if
        the engine overturns there already, search downwards from it, else it is a
        known survivor that bounds the downward search (one run, so that a narrow
        bracket cannot hide an overturn up to ``guard`` below the model).
    stop_on_collapse : bool
        Stop widening upwards at the first 'collapsed' run: above it the engine's
        bodies are no longer the model's mechanism, so there is no threshold of
        the model's to find (the point is reported unbracketed, with the collapse).
    """
    omega = _check_positive("omega", omega)
    a_ref = _check_positive("a_reference", a_reference)
    if not 0.0 < rel_bracket < 0.5:
        raise ValueError(f"rel_bracket must be in (0, 0.5), got {rel_bracket!r}")
    if not 0.0 < rel_tol < 0.5:
        raise ValueError(f"rel_tol must be in (0, 0.5), got {rel_tol!r}")
    t0 = time.perf_counter()
    runs = irregular = 0
    modes: dict[float, str | None] = {}
    probes: list[tuple[float, str, str | None]] = []

    def probe(a: float) -> bool:
        nonlocal runs, irregular
        runs += 1
        over, status, mode = overturns(backend, scene, omega, a, settings, kind)
        irregular += status not in ("overturned", "survived")
        modes[a] = mode
        probes.append((a, status, mode))
        return over

    lo, hi = a_ref * (1.0 - rel_bracket), a_ref * (1.0 + rel_bracket)
    ok, moved_down, survivor = True, False, None
    step = rel_bracket
    if guard > rel_bracket:
        g = a_ref * (1.0 - guard)
        if probe(g):  # overturns well below the model: search downwards from there
            hi, step, moved_down = g, 2.0 * guard, True
            ok, lo = step < 0.95, a_ref * (1.0 - 2.0 * guard)
        else:
            survivor = g
    while ok and probe(lo):  # lo overturns: the engine's threshold is lower
        hi, step, moved_down = lo, 2.0 * step, True
        if survivor is not None and step >= guard:
            lo = survivor  # known to survive: bisect between it and hi
            break
        ok = step <= max(rel_bracket * 2 ** max_expand, 2.0 * guard) and step < 0.95
        lo = a_ref * (1.0 - step)
    step = rel_bracket
    while ok and not moved_down and not probe(hi):  # hi survives: threshold is higher
        if stop_on_collapse and probes[-1][1] == "collapsed":
            ok = False  # the frame broke above the model's threshold: nothing to bracket
            break
        lo, step = hi, 2.0 * step
        ok = step <= rel_bracket * 2 ** max_expand
        hi = a_ref * (1.0 + step)
    if not ok:
        a_eng, lo = math.nan, math.nan
    else:
        while (hi - lo) > rel_tol * a_ref:
            mid = 0.5 * (lo + hi)
            if probe(mid):
                hi = mid
            else:
                lo = mid
        a_eng = hi
    return ThresholdPoint(omega, kind, a_ref, a_eng, lo, mode_reference,
                          modes.get(a_eng) if math.isfinite(a_eng) else None, runs, irregular,
                          rel_tol, settings_provenance(backend, settings,
                                                       time.perf_counter() - t0),
                          tuple(probes))


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
        return overturns(backend, scene, w, amplitude, settings, kind)[0]

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
