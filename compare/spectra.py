"""Reference (analytic) spectra for the campaign and the choice of test frequencies.

The reference is the paper's "first overturning amplitude" per Omega from the
compiled analytic path (:mod:`analytic.spectrum` when present).  Engines are then
tested at a few grid frequencies kept ``jump_margin`` away from every mode jump
(where a tiny frequency shift moves the threshold a lot), and at the largest jump
the frequency shift is measured separately.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["reference_spectrum", "choose_frequencies", "find_jumps",
           "first_overturning_amplitude"]


def _spectrum_module():
    try:
        from analytic import spectrum
    except ImportError:
        return None
    return spectrum


def _grid(config) -> np.ndarray:
    lo, hi = config.omega_range
    step = config.spectrum_step
    # One grid step beyond each end so a jump right at the range end is still seen.
    return np.round(np.arange(lo - step, hi + 1.5 * step, step), 10)


def _scan_fallback(scene, omegas: np.ndarray, tol: float = 0.01,
                   step: float = 0.25) -> tuple[list, list]:
    """First overturning amplitude per Omega by an upward scan (``step`` m/s^2) from
    the uplift acceleration and a bisection to ``tol``; used only when
    :mod:`analytic.spectrum` is unavailable."""
    from analytic import fast
    from analytic.excitation import Pulse

    b, h, mu, gamma, j, l, g = scene.model_args()
    a_up = g / scene.lam  # Eq. 11: nothing moves below it (pendulum hanging still)
    amps, modes = [], []
    for w in omegas:
        lo, a = a_up, a_up
        v = None
        while a < 200.0:
            v = fast.verdict_for(scene, Pulse(a, float(w)))
            if v.overturned:
                break
            lo, a = a, a + step
        if v is None or not v.overturned:
            amps.append(math.nan)
            modes.append(None)
            continue
        hi = a
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            vm = fast.verdict_for(scene, Pulse(mid, float(w)))
            if vm.overturned:
                hi, v = mid, vm
            else:
                lo = mid
        amps.append(hi)
        modes.append(v.mode)
    return amps, modes


def first_overturning_amplitude(scene, omega: float) -> tuple[float, str | None]:
    """The analytic first overturning amplitude [m/s^2] at one frequency, and its mode."""
    if not (math.isfinite(omega) and omega > 0.0):
        raise ValueError(f"omega must be finite and > 0 rad/s, got {omega!r}")
    amps, modes = _amplitudes(scene, np.array([float(omega)]))
    return float(amps[0]), modes[0]


def _amplitudes(scene, omegas: np.ndarray) -> tuple[list, list]:
    module = _spectrum_module()
    if module is not None and hasattr(module, "first_overturning_amplitudes"):
        return module.first_overturning_amplitudes(scene, omegas)
    return _scan_fallback(scene, omegas)


def find_jumps(omega, amp, mode) -> list[dict]:
    """Consecutive grid points whose overturning mode differs: one jump each."""
    jumps = []
    for i in range(len(omega) - 1):
        if mode[i] is None or mode[i + 1] is None or mode[i] == mode[i + 1]:
            continue
        a0, a1 = amp[i], amp[i + 1]
        jumps.append({"omega_lo": float(omega[i]), "omega_hi": float(omega[i + 1]),
                      "omega": 0.5 * float(omega[i] + omega[i + 1]),
                      "a_lo": float(a0), "a_hi": float(a1),
                      "mode_lo": mode[i], "mode_hi": mode[i + 1],
                      "rel_step": abs(a1 - a0) / min(a0, a1),
                      # Between the two levels the verdict flips across the jump.
                      "probe_amplitude": 0.5 * float(a0 + a1)})
    return jumps


def reference_spectrum(scene, config) -> dict:
    """The reference spectrum of ``scene`` on the config's grid, with its jumps.

    Keys: ``omega``, ``a``, ``mode`` (lists), ``jumps`` (all), ``jump`` (the one
    with the largest threshold step, measured in engines), ``backend``, ``tol``.
    """
    omegas = _grid(config)
    tol = 0.01
    amps, modes = _amplitudes(scene, omegas)
    amps = [float(a) for a in amps]
    jumps = find_jumps(omegas, amps, modes)
    lo, hi = config.omega_range
    inside = [jp for jp in jumps if lo <= jp["omega"] <= hi and jp["rel_step"] > 0.05]
    jump = max(inside, key=lambda jp: jp["rel_step"]) if inside else None
    return {"omega": omegas.tolist(), "a": amps, "mode": list(modes), "jumps": jumps,
            "jump": jump, "backend": config.spectrum_backend, "tol": tol}


def choose_frequencies(spec: dict, config) -> list[tuple[float, float, str | None]]:
    """``n_frequencies`` grid points ``(omega, a_ref, mode)`` spread over the
    range, each at least ``jump_margin`` from every mode jump."""
    n = config.n_frequencies
    if n <= 0:
        return []
    lo, hi = config.omega_range
    jump_ws = [jp["omega"] for jp in spec["jumps"]]
    cand = [(w, a, m) for w, a, m in zip(spec["omega"], spec["a"], spec["mode"])
            if lo <= w <= hi and math.isfinite(a)
            and all(abs(w - wj) >= config.jump_margin for wj in jump_ws)]
    if len(cand) <= n:
        return cand
    # Evenly spread over the candidates (deterministic), ends included.
    if n == 1:
        return [cand[len(cand) // 2]]
    idx = np.unique(np.round(np.linspace(0, len(cand) - 1, n)).astype(int))
    return [cand[i] for i in idx]
