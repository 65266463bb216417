"""The compiled fast path of the analytic model (backend ``"analytic-fast"``).

Same model and same phase semantics as the accurate path (``analytic.simulate``,
scipy DOP853 with events), integrated by a numba-compiled Dormand-Prince 5(4)
with its 4th-order dense output and event location on the interpolant
(:mod:`analytic._fast_kernels`).  The equations themselves are the functions of
:mod:`analytic.equations` compiled as they are.

Phase semantics
---------------
* REST (``theta = theta_dot = 0``; the pendulum obeys Eq. 1).  Uplift about side
  ``s`` when ``uplift_margin`` (Eq. 9 as a moment) reaches 0 from above; at once
  if it is already ``<= 0`` when a REST segment starts.
* ROCK ``s`` (Eq. 8 for ``s=+1``, A.1 for ``s=-1``).  Impact when ``s*theta``
  falls through 0 (never at the start of the phase): Eq. 19/21 give the new
  velocities; ``|theta_dot+| < rest_velocity`` ends in REST (event 'rest'),
  otherwise rocking continues about ``-s``.  Overturned when ``|theta|`` reaches
  ``criterion.threshold(alpha)``; mode 'no-impact' or 'after-impact'.
* The pulse end, and its quarter periods (the extrema of a sine's uplift margin,
  so a short uplift window is not stepped over), are breakpoints.  Under a
  sampled record every sample is one: each step integrates one straight line
  of the record's linear interpolation (the function the accurate path
  integrates, ``SampledRecord.acceleration``), and the uplift margin, whose
  minima lie at the samples, is checked at every sample, as the accurate path
  checks it.  "The pulse" below is then the record: its end is the last sample.
* Exact survival (``t_max=None``), after the pulse: energy below
  ``overturn_energy_barrier`` at the pulse end or after any later impact/rest;
  REST without pendulum; REST with pendulum and no uplift within one free
  pendulum period (``4 sqrt(l/g) K(k^2)``).  Otherwise the run is 'undecided' at
  pulse end + ``t_cap``.  With ``t_max`` given the run stops there and a run
  that has not overturned is 'survived'.
* Certain overturn (verdict-only entry points, ``t_max=None``): after the pulse,
  past ``alpha`` with the energy below the barrier (and ``M R >= 2 gamma l``),
  or without pendulum past ``alpha`` moving outward, the fall to the threshold
  is certain (``_fast_steps.overturn_certain``, proof in
  ``docs/overturn-maps.md``).  The run ends there: the verdict's ``time`` is then
  the instant the overturn became certain, not the instant ``|theta|`` reaches
  the threshold, and its ``reason`` says so.  :func:`simulate` never exits
  early: a trajectory always shows the whole fall.

Only what an excitation's ``compiled_form()`` describes (the one-sine and
one-cosine pulses, a sampled record) is compiled: :func:`simulate` hands any
other excitation (the pulses of :mod:`analytic.pulses`, a user's own) to the
accurate path (``analytic.simulate``) and says so in the trajectory's
diagnostics.

Notes
-----
A record costs at least one step per sample, and the steps of its rocking:
linear in its length.  Measured by ``python -m benchmarks.run
bench_record_paths`` (CPU seconds, compiled against accurate, in one run;
``docs/earthquakes.md``): a 16,000-sample record (80 s, rocking to the end)
0.042 against 17.4 CPU s (ratio 0.0024), the model's IDA of the 12 shipped
synthetic motions (372 runs) 0.17 against 291 CPU s (ratio 0.0006), with the
same verdicts at every run.
"""
from __future__ import annotations

import math
import time

import numpy as np

from . import _fast_kernels as _k
from .excitation import CompiledForm, Excitation, check_excitation
from .fast_settings import Settings, version
from .parameters import Scene
from .trajectory import Event, Trajectory, Verdict

__all__ = ["NAME", "version", "Settings", "simulate", "overturn_verdict", "verdict_for",
           "kernel_args", "warm_up", "STATUS_NAMES", "PULSE_CODES"]

NAME = "analytic-fast"
CAPABILITIES = frozenset({"trajectory"})
STATUS_NAMES = ("overturned", "survived", "unstable", "undecided")
EVENT_NAMES = ("uplift", "impact", "rest", "overturn", "unstable")
REASONS = ("overturned", "energy below the overturning barrier after the pulse",
           "at rest after the pulse, no pendulum",
           "no uplift within one free-pendulum period after the pulse",
           "t_max reached", "t_cap after the pulse reached", "non-finite state",
           "step size underflow", "step budget exhausted",
           "overturn certain after the pulse (past alpha, cannot come back); "
           "time = when it became certain")
# The one map from pulse names to the kernels' codes.
PULSE_CODES = {"sine": _k.KIND_SINE, "cosine": _k.KIND_COSINE}
# Every compiled form's kind: the pulses and a sampled record.
KIND_CODES = {**PULSE_CODES, "samples": _k.KIND_SAMPLES}


def _pack(model_args: tuple, omega: float, kind_code: int, threshold: float, rtol: float,
          atol: float, rest_velocity: float, t_max: float | None, t_cap: float,
          max_steps: int, rest_step_fraction: float, certain_exit: bool,
          restitution_factor: float = 1.0, t_end: float | None = None) -> tuple:
    """The kernels' arguments after the amplitude, in their order (the one place
    that knows it); ``t_max`` None or <= 0 = exact survival; ``t_end`` the end
    of the excitation [s] (default a pulse's ``2 pi / omega``).  The restitution
    factor comes last: :func:`warm_up` and :func:`simulate` append ``record,
    sample_dt, rec_t, rec_a`` after it."""
    t_max = -1.0 if t_max is None else float(t_max)
    t_end = 2.0 * math.pi / omega if t_end is None else float(t_end)
    return (*model_args, float(omega), int(kind_code), t_end,
            float(threshold), rtol, atol, rest_velocity, t_max, t_cap, int(max_steps),
            rest_step_fraction, bool(certain_exit), float(restitution_factor))


def kernel_args(scene: Scene, omega: float, kind: str, settings: Settings,
                certain_exit: bool = True) -> tuple:
    """Arguments of the compiled kernels after the amplitude, for ``scene`` under a
    ``kind`` pulse of frequency ``omega`` [rad/s]: call
    ``_fast_kernels.verdict(amplitude, *args)`` or ``verdicts(amplitudes, *args)``.
    No validation (callers validate once)."""
    return _pack(scene.model_args(), omega, PULSE_CODES[kind],
                 settings.criterion.threshold(scene.alpha), settings.rtol, settings.atol,
                 settings.rest_velocity, settings.t_max, settings.t_cap, settings.max_steps,
                 settings.rest_step_fraction, certain_exit, settings.restitution_factor)


def overturn_verdict(b: float, h: float, mu: float, gamma: float, j: float, l: float,
                     g: float, amplitude: float, omega: float, kind: int, threshold: float,
                     rtol: float = 1e-8, atol: float = 1e-10, rest_velocity: float = 1e-6,
                     t_max: float = -1.0, t_cap: float = 120.0,
                     max_steps: int = 2_000_000, rest_step_fraction: float = 0.01,
                     restitution_factor: float = 1.0) -> tuple[int, int, float, int]:
    """Verdict of one pulse, compiled and allocation-free per step (for spectra).

    No validation (callers validate once); ``kind`` 0 = sine (Eq. 22), 1 = cosine
    (Eq. 23); ``t_max <= 0`` = exact survival; ``restitution_factor`` in (0, 1]
    scales every impact's rocking ratio (Eq. 19/20).  Returns ``(status_code,
    reason_code, time, n_impacts)``; ``STATUS_NAMES[status_code]``, ``REASONS``.
    With a fixed ``t_max`` the exact survival rules still stop the run early (the
    verdict at ``t_max`` follows from them), so ``n_impacts`` then counts the
    impacts up to that decision only.  With exact survival a certain overturn
    ends the run early (module docstring): ``time`` is then when it became certain.
    """
    return _k.verdict(amplitude, *_pack((b, h, mu, gamma, j, l, g), omega, kind, threshold,
                                        rtol, atol, rest_velocity, t_max, t_cap, max_steps,
                                        rest_step_fraction, True, restitution_factor))


def verdict_for(scene: Scene, pulse: Excitation, settings: Settings | None = None) -> Verdict:
    """The :class:`Verdict` of ``scene`` under ``pulse`` without sampling the
    trajectory (see :func:`overturn_verdict` for fixed-window runs).  A certain
    overturn ends the run early: ``Verdict.time`` is then the instant it became
    certain (``Verdict.reason`` says so); :func:`simulate` gives the fall itself.

    ``pulse`` must be an excitation the kernels integrate (its
    ``compiled_form()`` is not None: a one-sine or one-cosine pulse, a sampled
    record), ``TypeError`` otherwise."""
    settings = _check(scene, pulse, settings)
    form = _compiled(pulse)
    if form is None:
        raise TypeError(f"verdict_for: pulse must be an excitation the compiled kernels "
                        f"integrate (compiled_form() of kind {tuple(KIND_CODES)}: a sine or "
                        f"cosine Pulse, a SampledRecord), got {type(pulse).__name__}")
    args = _form_args(scene, form, settings)
    if form.kind == "samples":
        st, rs, tv, ni, _e, _n = _k.record_verdicts(np.array([form.amplitude]), *args,
                                                    form.times, form.accelerations)
        return _make_verdict(st[0], rs[0], tv[0], ni[0])
    return _make_verdict(*_k.verdict(form.amplitude, *args))


def _compiled(excitation: Excitation) -> CompiledForm | None:
    """The excitation's compiled form if the kernels know its kind, else None."""
    form = excitation.compiled_form()
    return form if form is not None and form.kind in KIND_CODES else None


def _form_args(scene: Scene, form: CompiledForm, settings: Settings,
               certain_exit: bool = True) -> tuple:
    """:func:`kernel_args` of a compiled form (a pulse or a record)."""
    if form.kind != "samples":
        return kernel_args(scene, form.omega, form.kind, settings, certain_exit)
    return _pack(scene.model_args(), 0.0, _k.KIND_SAMPLES,
                 settings.criterion.threshold(scene.alpha), settings.rtol, settings.atol,
                 settings.rest_velocity, settings.t_max, settings.t_cap, settings.max_steps,
                 settings.rest_step_fraction, certain_exit, settings.restitution_factor,
                 t_end=float(form.times[-1]))


def _make_verdict(st: int, rs: int, tv: float, ni: int) -> Verdict:
    status = STATUS_NAMES[st]
    mode = None
    if status == "overturned":
        mode = "after-impact" if ni > 0 else "no-impact"
    # Like the accurate path: a time only for an overturn (when it happened).
    t_v = float(tv) if status == "overturned" else None
    return Verdict(status, t_v, mode, int(ni), REASONS[rs])


def _check(scene, excitation, settings) -> Settings:
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be an analytic.Scene, got {type(scene).__name__}")
    check_excitation(excitation)
    settings = Settings() if settings is None else settings
    if not isinstance(settings, Settings):
        raise ValueError(f"settings must be analytic.fast.Settings, got {type(settings).__name__}")
    return settings


def warm_up(record: bool = True) -> float:
    """Compile (or load from the on-disk cache) the kernels once per process;
    ``record=False`` only the verdict kernel (what spectra use).  Returns seconds."""
    t0 = time.perf_counter()
    args = kernel_args(Scene(), 10.0, "sine", Settings())
    _k.verdicts(np.array([10.0]), *args)
    if record:
        none = np.zeros(1)
        _k.run(10.0, *args[:-2], False, args[-1], True, 1e-2, none, none)
        rec = np.array([0.0, 0.1])
        _k.record_verdicts(np.array([1.0]), *_pack(Scene().model_args(), 0.0, _k.KIND_SAMPLES,
                                                   1.5, 1e-8, 1e-10, 1e-6, None, 1.0, 1000,
                                                   0.01, True, t_end=0.1), rec, rec)
    return time.perf_counter() - t0


def simulate(scene: Scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Run ``scene`` under ``excitation``; returns a :class:`Trajectory`.

    Samples on the ``sample_dt`` grid plus one row at every event (the state
    after it).  An excitation without a compiled form (a Ricker wavelet, a
    user's own, ...: ``compiled_form()`` is None) is handed to the accurate path.
    ``diagnostics['steps']`` counts the kernel's accepted and rejected steps.
    """
    settings = _check(scene, excitation, settings)
    form = _compiled(excitation)
    if form is None:
        from . import simulate as accurate  # the fallback the docstring promises
        acc_settings = accurate.Settings(criterion=settings.criterion, t_max=settings.t_max,
                                         rest_velocity=settings.rest_velocity,
                                         restitution_factor=settings.restitution_factor)
        traj = accurate.simulate(scene, excitation, acc_settings)
        traj.diagnostics["fast_path_fallback"] = (f"{type(excitation).__name__}: accurate "
                                                  "path used")
        return traj
    t0 = time.perf_counter()
    # No early exit here: a trajectory shows the fall up to the threshold.
    args = _form_args(scene, form, settings, certain_exit=False)
    none = np.zeros(1)  # a pulse's record arrays (never read)
    rec_t = none if form.times is None else form.times
    rec_a = none if form.accelerations is None else form.accelerations
    (st, rs, tv, ni, samples, ns, events, ne, n_steps, _e_out) = _k.run(
        form.amplitude, *args, True, settings.sample_dt, rec_t, rec_a)
    wall = time.perf_counter() - t0
    data = samples[:ns]
    evs = []
    for row in events[:ne]:
        kind = EVENT_NAMES[int(row[0])]
        if kind in ("impact",):
            evs.append(Event(kind, float(row[1]), int(row[2]), float(row[3]), float(row[4]),
                             float(row[5]), float(row[6]), float(row[7])))
        else:
            evs.append(Event(kind, float(row[1]), int(row[2]), psi=float(row[5])))
    settings_dict = settings.describe()
    verdict = _make_verdict(st, rs, tv, ni)
    diagnostics = {"steps": int(n_steps), "version": version()}
    if form.kind == "samples" and np.all(np.isfinite(data)):
        # A record's run keeps the contact checks the accurate path reports
        # (docs/model.md, "Ground reaction"), which a record's reader relied on.
        from .reactions import validity_diagnostics
        diagnostics.update(validity_diagnostics(data[:, 0], data[:, 1], data[:, 2], data[:, 3],
                                                data[:, 4], excitation, scene.model_args(),
                                                scene.alpha, verdict.overturned))
    return Trajectory(backend=NAME, t=data[:, 0], theta=data[:, 1], theta_dot=data[:, 2],
                      psi=data[:, 3], psi_dot=data[:, 4], events=tuple(evs),
                      verdict=verdict, criterion=settings.criterion,
                      t_max=settings.t_max, settings=settings_dict, diagnostics=diagnostics,
                      wall_time=wall, scene=scene, excitation=excitation)
