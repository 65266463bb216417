"""Reference (analytic) spectra for the campaign and the choice of test frequencies.

The reference is the paper's "first overturning amplitude" per Omega from the
compiled analytic path (:func:`analytic.spectrum.first_overturn_amplitude`).  Engines are then
tested at a few grid frequencies kept ``jump_margin`` away from every mode jump
(where a tiny frequency shift moves the threshold a lot), and at the largest jump
the frequency shift is measured separately.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["reference_spectrum", "choose_frequencies", "find_jumps",
           "first_overturning_amplitude", "monotone_above", "locate_tongue_tip",
           "model_valid_at"]


def _grid(config) -> np.ndarray:
    lo, hi = config.omega_range
    step = config.spectrum_step
    # One grid step beyond each end so a jump right at the range end is still seen.
    return np.round(np.arange(lo - step, hi + 1.5 * step, step), 10)


def first_overturning_amplitude(scene, omega: float) -> tuple[float, str | None]:
    """The analytic first overturning amplitude [m/s^2] at one frequency, and its mode."""
    if not (math.isfinite(omega) and omega > 0.0):
        raise ValueError(f"omega must be finite and > 0 rad/s, got {omega!r}")
    amps, modes = _amplitudes(scene, np.array([float(omega)]))
    return float(amps[0]), modes[0]


def _amplitudes(scene, omegas: np.ndarray) -> tuple[list, list]:
    """:func:`analytic.spectrum.first_overturn_amplitude` (scan + bisection with
    the compiled path, default :class:`~analytic.spectrum.SpectrumSettings`)."""
    from trilith_xval.analytic.spectrum import SpectrumSettings, first_overturn_amplitude

    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.keys import scene_dict

    ss = SpectrumSettings()
    # One stored threshold point per frequency (the run store).
    res = [runs.memo("point", {"scene": scene_dict(scene), "omega": float(w),
                               "settings": ss.describe()},
                     lambda w=w: first_overturn_amplitude(scene, float(w), ss)) for w in omegas]
    return [r[0] for r in res], [r[2] for r in res]


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
                      "rel_step": abs(a1 - a0) / min(a0, a1)})
    return jumps


def reference_spectrum(scene, config) -> dict:
    """The reference spectrum of ``scene`` on the config's grid, with its jumps.

    Keys: ``omega``, ``a``, ``mode`` (lists), ``jumps`` (all), ``jump`` (the one
    with the largest threshold step, measured in engines), ``backend``, ``tol``.
    """
    omegas = _grid(config)
    from trilith_xval.analytic.spectrum import SpectrumSettings

    tol = SpectrumSettings().tol
    amps, modes = _amplitudes(scene, omegas)
    amps = [float(a) for a in amps]
    jumps = find_jumps(omegas, amps, modes)
    lo, hi = config.omega_range
    inside = [jp for jp in jumps if lo <= jp["omega"] <= hi and jp["rel_step"] > 0.05]
    jump = max(inside, key=lambda jp: jp["rel_step"]) if inside else None
    if jump is not None:
        jump = {**jump, **locate_tongue_tip(scene, jump)}
    return {"omega": omegas.tolist(), "a": amps, "mode": list(modes), "jumps": jumps,
            "jump": jump, "backend": config.spectrum_backend, "tol": tol}


def monotone_above(scene, omega: float, a_ref: float, span: float, n: int = 12) -> bool:
    """True when the model overturns at every one of ``n`` amplitudes in
    ``(a_ref, a_ref (1 + span)]``: no safe island just above the threshold.

    Where the model has narrow overturning windows (the spectrum's low-amplitude
    region) a bisection in an engine would find *a* transition, not the first
    one, and the comparison would mean nothing.
    """
    from trilith_xval.analytic import fast
    from trilith_xval.analytic.excitation import Pulse

    return all(fast.verdict_for(scene, Pulse(a_ref * (1.0 + r), omega)).overturned
               for r in np.linspace(span / n, span, n))


def model_valid_at(scene, omega: float, amplitude: float) -> bool:
    """True when the analytic model's own assumptions hold for the pulse
    ``(amplitude, omega)``: the vertical forces of the ground on the columns and
    of the column tops on the lintel stay positive up to the verdict (or to
    ``|theta| = alpha`` for an overturning run), see :mod:`analytic.reactions`.
    Where one turns negative the real columns hop or the lintel is thrown off,
    the engines (which let them) are no longer comparable to the model, and an
    engine-vs-model threshold error would blame the engine for the model."""
    from trilith_xval.analytic.excitation import Pulse
    from trilith_xval.compare.run.runs import simulate

    return bool(simulate("analytic", scene, Pulse(amplitude, omega)).diagnostics.get(
        "model_valid", True))


def locate_tongue_tip(scene, jump: dict, d_omega: float = 0.02, rel_da: float = 0.01) -> dict:
    """Refine a mode jump on the model: where the lower branch's overturning
    "tongue" closes.

    Near a jump the lower threshold branch is a tongue in the (Omega, A) plane
    that narrows and closes at the jump frequency (above it the first
    overturning is on the other branch).  Bisecting Omega (to ``d_omega``) on
    "some A between the lower level and the middle of the two levels, in
    ``rel_da`` relative steps, overturns on the lower branch" finds the tip; the
    tongue's middle amplitude there is the probe at which the verdict flips
    *at the jump* (a probe elsewhere would flip where it crosses the tongue's
    edge).  Returns ``omega_tip``, ``probe_amplitude`` and a bracket
    ``omega_lo``/``omega_hi`` of +-0.25 rad/s around the tip.
    """
    from trilith_xval.analytic import fast
    from trilith_xval.analytic.excitation import Pulse

    a0, a1 = jump["a_lo"], jump["a_hi"]
    left = a0 < a1  # the tongue (lower branch) lies below the jump frequency
    branch = jump["mode_lo"] if left else jump["mode_hi"]
    # The tongue lies between the lower level and the middle of the two levels.
    lo_level = min(a0, a1)
    amps = lo_level * (1.0 + rel_da) ** np.arange(
        -5, int(math.log(0.5 * (a0 + a1) / lo_level) / math.log1p(rel_da)) + 1)

    def tongue(w: float) -> list[float]:
        return [float(a) for a in amps
                if (lambda v: v.overturned and v.mode == branch)(
                    fast.verdict_for(scene, Pulse(float(a), w)))]

    inside, outside = (jump["omega_lo"], jump["omega_hi"]) if left else (
        jump["omega_hi"], jump["omega_lo"])
    hits = tongue(inside)
    if not hits or tongue(outside):
        return {}
    # Bisect the frequency where the tongue closes.
    while abs(outside - inside) > d_omega:
        mid = 0.5 * (inside + outside)
        found = tongue(mid)
        if found:
            inside, hits = mid, found
        else:
            outside = mid
    probe = float(np.median(hits))
    return {"omega_tip": inside, "probe_amplitude": probe, "omega_lo": inside - 0.25,
            "omega_hi": inside + 0.25, "branch": branch, "d_omega": d_omega}


def choose_frequencies(spec: dict, config, scene=None) -> list[tuple[float, float, str | None]]:
    """``n_frequencies`` grid points ``(omega, a_ref, mode)`` spread over the
    range, each at least ``jump_margin`` from every mode jump and, when ``scene``
    is given, with a monotone model verdict over twice the bisection bracket
    above the threshold (:func:`monotone_above`) and a valid model there (no
    pull at the ground or at the lintel, :func:`model_valid_at`)."""
    n = config.n_frequencies
    if n <= 0:
        return []
    lo, hi = config.omega_range
    jump_ws = [jp["omega"] for jp in spec["jumps"]]
    cand = [(w, a, m) for w, a, m in zip(spec["omega"], spec["a"], spec["mode"])
            if lo <= w <= hi and math.isfinite(a)
            and all(abs(w - wj) >= config.jump_margin for wj in jump_ws)]
    if scene is not None:
        cand = [c for c in cand if monotone_above(scene, c[0], c[1], 2.0 * config.rel_bracket)]
        # The engines are judged only where the model itself is valid (no hop, no lintel lift).
        cand = [c for c in cand
                if model_valid_at(scene, c[0], c[1] * (1.0 + 2.0 * config.rel_bracket))]
    if len(cand) <= n:
        return cand
    # Evenly spread over the candidates (deterministic), ends included.
    if n == 1:
        return [cand[len(cand) // 2]]
    idx = np.unique(np.round(np.linspace(0, len(cand) - 1, n)).astype(int))
    return [cand[i] for i in idx]
