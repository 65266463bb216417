"""The excitation contract: what every ground motion of the project provides.

:class:`Excitation` is the one base class of the ground motions (the one-sine
and one-cosine :class:`~analytic.excitation.Pulse`, the Ricker and
Mavroeidis-Papageorgiou pulses of :mod:`analytic.pulses`, the
:class:`~analytic.excitation.SampledRecord` of a recorded motion, and
:class:`~analytic.excitation.Still`).  The model, the compiled kernels, the
engines and the run store ask only for its members, never for a concrete
class, so a user's own subclass runs everywhere a shipped one does.

:func:`check_excitation` is the one type check of an ``excitation`` argument
(``TypeError``); bad values inside an excitation are refused by its own
constructor (``ValueError`` naming the field and its range).
:func:`check_excitation_contract` checks that a subclass keeps the contract
(as scikit-learn's ``check_estimator`` does for estimators).
"""
from __future__ import annotations

import abc
import dataclasses
import inspect
import json
import math
from typing import Callable, ClassVar, NamedTuple

import numpy as np

# The pulse shapes the compiled kernels integrate (a CompiledForm's kind).
PULSE_KINDS = ("sine", "cosine")
# Every kind a CompiledForm may name: the pulses and a sampled record.
COMPILED_KINDS = PULSE_KINDS + ("samples",)

__all__ = ["Excitation", "CompiledForm", "check_excitation", "check_excitation_contract",
           "EXCITATION_TYPES", "COMPILED_KINDS"]


class CompiledForm(NamedTuple):
    """What the compiled kernels of :mod:`analytic.fast` integrate.

    * ``kind`` ``'sine'`` / ``'cosine'``: the one-sine or one-cosine pulse
      (Eq. 22/23) of ``amplitude`` [m/s^2] and circular frequency ``omega``
      [rad/s] (``times``, ``accelerations`` None);
    * ``kind`` ``'samples'``: ``amplitude`` (a factor, 1 for the record as
      given) times the linear interpolation of ``accelerations`` [m/s^2] at
      ``times`` [s] (1-D float arrays, strictly increasing times), zero before
      the first and after the last sample; ``omega`` unused (0).  The kernels
      read the arrays and never write them.
    """

    kind: str
    amplitude: float
    omega: float
    times: np.ndarray | None = None
    accelerations: np.ndarray | None = None


class Excitation(abc.ABC):
    """The contract every ground motion meets: what the model, the compiled
    kernels, the engines and the run store ask of an excitation.

    A subclass is a frozen dataclass (its fields are what the run key hashes)
    that checks its values in ``__post_init__`` (``ValueError`` naming the field
    and its range).  It must provide:

    * ``end_time`` [s]: the ground is still (``xg_ddot = 0``) outside
      ``[start_time, end_time]``; ``end_time <= start_time`` means no motion;
    * ``acceleration_array(t)``: the ground acceleration ``xg_ddot`` [m/s^2] at
      the times of an array (vectorised; 0 outside the window);
    * ``velocity(t)`` [m/s] and ``displacement(t)`` [m], both 0 at ``t = 0``
      (for engines that move a ground body);
    * ``scaled(factor)``: the same motion with its accelerations times
      ``factor > 0`` (the amplitude search of :mod:`analytic.ida` scales by it).

    Everything else has a default that a subclass may refine: ``acceleration(t)``
    (scalar), ``start_time``, ``peak_times`` and ``kink_times`` (breakpoints the
    accurate integrator stops at), ``interpolant`` (its right-hand side),
    ``acceleration_bound`` / ``velocity_bound`` (for the friction and blow-up
    bounds of the engines), ``pga`` / ``pgv``, ``label``, ``describe()``,
    ``key_fields()`` (what the run key hashes) and ``compiled_form()`` (``None``:
    the compiled kernels do not integrate it, :mod:`analytic.fast` hands it to
    the accurate path).  :func:`check_excitation_contract` checks a subclass.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> import numpy as np
    >>> @dataclass(frozen=True)
    ... class Step(Excitation):
    ...     amplitude: float
    ...     duration: float
    ...     @property
    ...     def end_time(self): return self.duration
    ...     def acceleration_array(self, t):
    ...         t = np.asarray(t, dtype=float)
    ...         return np.where((t >= 0) & (t <= self.duration), self.amplitude, 0.0)
    ...     def velocity(self, t):
    ...         return self.amplitude * min(max(t, 0.0), self.duration)
    ...     def displacement(self, t):
    ...         tc = min(max(t, 0.0), self.duration)
    ...         return 0.5 * self.amplitude * tc ** 2 + self.velocity(t) * max(t - tc, 0.0)
    ...     def scaled(self, factor): return Step(factor * self.amplitude, self.duration)
    >>> Step(2.0, 0.5).acceleration(0.25), Step(2.0, 0.5).describe()["type"]
    (2.0, 'step')
    """

    #: The kind name ``describe()`` reports (``'pulse'``, ``'record'``, ...);
    #: a subclass that sets none gets its class name in lower case.
    type_name: ClassVar[str] = ""

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        if not cls.__dict__.get("type_name"):
            cls.type_name = cls.__name__.lower()

    # ----------------------------------------------------------- required
    @property
    @abc.abstractmethod
    def end_time(self) -> float:
        """After this instant [s] the ground is still."""

    @abc.abstractmethod
    def acceleration_array(self, t) -> np.ndarray:
        """``xg_ddot`` [m/s^2] at every time of ``t`` (0 outside the window)."""

    @abc.abstractmethod
    def velocity(self, t: float) -> float:
        """Ground velocity [m/s], 0 at ``t = 0``."""

    @abc.abstractmethod
    def displacement(self, t: float) -> float:
        """Ground displacement [m], 0 at ``t = 0``."""

    @abc.abstractmethod
    def scaled(self, factor: float) -> "Excitation":
        """The motion with its accelerations times ``factor`` (> 0)."""

    # ----------------------------------------------------------- defaults
    def acceleration(self, t: float) -> float:
        """``xg_ddot(t)`` [m/s^2] at one instant."""
        return float(self.acceleration_array(t))

    @property
    def start_time(self) -> float:
        """Before this instant [s] the ground is still (a breakpoint: the motion
        may start with a jump)."""
        return 0.0

    @property
    def peak_times(self) -> tuple[float, ...]:
        """Instants of the extrema of ``|xg_ddot|`` [s], where the uplift margin
        is smallest: the accurate path ends its rest segments there."""
        return ()

    @property
    def kink_times(self) -> np.ndarray | None:
        """Instants [s] where ``xg_ddot`` is only piecewise smooth (a record's
        samples), at which the accurate path checks the uplift margin; None
        for a smooth motion."""
        return None

    def interpolant(self, lo: float, hi: float) -> Callable[[float], float]:
        """``xg_ddot(t)`` with ``t`` clamped to ``[lo, hi]``, for an integrator's
        right-hand side inside one smooth piece of the motion."""
        acc = self.acceleration
        return lambda t: acc(min(max(t, lo), hi))

    def acceleration_bound(self) -> float:
        """An estimate of ``max |xg_ddot|`` [m/s^2] for the engines' friction
        bound: the largest of 20001 samples over ``[0, end_time]``."""
        if self.end_time > 0.0:
            t = np.linspace(0.0, self.end_time, 20001)
            return float(np.max(np.abs(self.acceleration_array(t))))
        return 0.0

    def velocity_bound(self) -> float:
        """An estimate of ``max |xg_dot|`` [m/s] (it only scales the engines'
        blow-up speed limit): the largest of 401 samples over ``[0, end_time]``."""
        if self.end_time <= 0.0:
            return 0.0
        ts = [self.end_time * k / 400.0 for k in range(401)]
        return max(abs(self.velocity(t)) for t in ts)

    @property
    def pga(self) -> float:
        """Peak ground acceleration [m/s^2] (an intensity of :mod:`analytic.ida`)."""
        return self.acceleration_bound()

    @property
    def pgv(self) -> float:
        """Peak ground velocity [m/s] (an intensity of :mod:`analytic.ida`)."""
        return self.velocity_bound()

    @property
    def label(self) -> str:
        """A name for reports (a record's file name); the class name by default."""
        return type(self).__name__

    def describe(self) -> dict:
        """``{'type': type_name, <fields>}``: what a result reports."""
        return {"type": self.type_name, **self._fields()}

    def key_fields(self) -> dict:
        """What a run key hashes (``compare.run.keys``): the class name and every
        field, so two different motions never share a key."""
        return {"type": type(self).__name__, **self._fields()}

    def compiled_form(self) -> CompiledForm | None:
        """The compiled kernels' form of this motion, None when they do not
        integrate it (then :mod:`analytic.fast` runs the accurate path)."""
        return None

    def _fields(self) -> dict:
        if not dataclasses.is_dataclass(self):
            raise TypeError(f"{type(self).__name__} is no dataclass: it must define "
                            "describe() and key_fields() itself")
        return dataclasses.asdict(self)


# What the one type check names as allowed.
EXCITATION_TYPES = "Pulse, Ricker, MavroeidisPapageorgiou, SampledRecord, Still"


def check_excitation(excitation, where: str = "") -> Excitation:
    """``excitation`` itself if it is an :class:`Excitation`: the one check of an
    ``excitation`` argument, made by every entry point (the accurate and the
    compiled model, the engines, the run keys).

    Parameters
    ----------
    excitation : object
    where : str, optional
        What refuses it (an engine's name), put before the message.

    Raises
    ------
    TypeError
        ``excitation`` is not an :class:`Excitation`, naming the parameter and
        what it may be.
    """
    if not isinstance(excitation, Excitation):
        prefix = f"{where}: " if where else ""
        raise TypeError(f"{prefix}excitation must be an analytic.excitation.Excitation "
                        f"({EXCITATION_TYPES} or a subclass of Excitation), "
                        f"got {type(excitation).__name__}")
    return excitation


def _fail(cls, what: str) -> None:
    raise AssertionError(f"{cls.__name__} breaks the excitation contract: {what}")


def _close(a, b, scale: float) -> bool:
    # Scalar and vectorised forms may round differently (math.sin vs np.sin).
    return bool(np.all(np.abs(np.asarray(a, float) - np.asarray(b, float))
                       <= 1e-12 * scale + 1e-300))


def check_excitation_contract(cls_or_obj) -> None:
    """Check that an excitation class (or instance) keeps the :class:`Excitation`
    contract; raises ``AssertionError`` naming the broken rule.

    A class is checked for what a class can show (a concrete frozen-dataclass
    subclass of :class:`Excitation` with a kind name); an instance also for
    its behaviour: a finite window, a vectorised acceleration that is zero
    outside it and agrees with the scalar one and the interpolant, a velocity
    and displacement zero at ``t = 0`` and a velocity that integrates the
    acceleration, a ``scaled`` copy of the same class (``ValueError`` for a
    factor <= 0), JSON-able ``describe()`` and ``key_fields()``, breakpoints
    inside the window, bounds covering the samples, and a ``compiled_form()``
    (if any) that is the motion the compiled kernels integrate.
    """
    obj = None if isinstance(cls_or_obj, type) else cls_or_obj
    cls = cls_or_obj if obj is None else type(obj)
    if not issubclass(cls, Excitation):
        _fail(cls, "not a subclass of analytic.excitation.Excitation")
    if inspect.isabstract(cls):
        _fail(cls, f"abstract members left: {sorted(cls.__abstractmethods__)}")
    if not (dataclasses.is_dataclass(cls) and cls.__dataclass_params__.frozen):
        _fail(cls, "not a frozen dataclass (its fields are what a run key hashes)")
    if not (isinstance(cls.type_name, str) and cls.type_name):
        _fail(cls, "type_name must be a non-empty str")
    if obj is not None:
        _check_instance(cls, obj)


def _check_instance(cls, obj: Excitation) -> None:
    t0, t1 = float(obj.start_time), float(obj.end_time)
    if not (math.isfinite(t0) and math.isfinite(t1) and t0 >= 0.0):
        _fail(cls, f"start_time {t0!r} and end_time {t1!r} must be finite, start >= 0")
    span = max(t1, 1e-3)
    t = np.linspace(0.0, span, 401)
    a = np.asarray(obj.acceleration_array(t), dtype=float)
    if a.shape != t.shape or not np.all(np.isfinite(a)):
        _fail(cls, "acceleration_array(t) must give finite values of t's shape")
    scale = max(float(np.max(np.abs(a))), 1e-300)
    outside = np.asarray(obj.acceleration_array(np.array([-1.0, t1 + 1.0])), dtype=float)
    if np.any(outside != 0.0):
        _fail(cls, "xg_ddot must be 0 before start_time and after end_time")
    pick = t[::40]
    if not _close([obj.acceleration(float(x)) for x in pick], a[::40], scale):
        _fail(cls, "acceleration(t) must agree with acceleration_array(t)")
    if t1 > t0:
        lo, hi = t0 + 0.25 * (t1 - t0), t0 + 0.5 * (t1 - t0)
        f = obj.interpolant(lo, hi)
        inner = np.linspace(lo, hi, 7)
        if not _close([f(float(x)) for x in inner], obj.acceleration_array(inner), scale):
            _fail(cls, "interpolant(lo, hi) must agree with acceleration inside [lo, hi]")
    for name in ("velocity", "displacement"):
        if abs(getattr(obj, name)(0.0)) > 1e-12 * max(scale, 1.0):
            _fail(cls, f"{name}(0) must be 0")
    fine = np.linspace(0.0, span, 20001)
    v_end = float(np.trapezoid(obj.acceleration_array(fine), fine))
    if abs(obj.velocity(span) - v_end) > 1e-3 * scale * span:
        _fail(cls, f"velocity(end_time) {obj.velocity(span):.6g} must integrate the "
                   f"acceleration ({v_end:.6g})")
    _check_scaled(cls, obj, t, a, scale)
    for name in ("describe", "key_fields"):
        out = getattr(obj, name)()
        if not isinstance(out, dict) or "type" not in out:
            _fail(cls, f"{name}() must give a dict with a 'type'")
        try:
            json.dumps(out, allow_nan=False)
        except (TypeError, ValueError) as exc:
            _fail(cls, f"{name}() must be JSON-able: {exc}")
    if obj.describe()["type"] != cls.type_name or obj.key_fields()["type"] != cls.__name__:
        _fail(cls, "describe()['type'] must be type_name, key_fields()['type'] the class name")
    peaks = tuple(obj.peak_times)
    if any(not (t0 <= p <= t1) for p in peaks):
        _fail(cls, "peak_times must lie in [start_time, end_time]")
    kinks = obj.kink_times
    if kinks is not None:
        k = np.asarray(kinks, dtype=float)
        if k.ndim != 1 or np.any(np.diff(k) <= 0.0) or k[0] < t0 or k[-1] > t1:
            _fail(cls, "kink_times must increase strictly inside [start_time, end_time]")
    bound = obj.acceleration_bound()
    if not (math.isfinite(bound) and bound >= (1.0 - 1e-9) * float(np.max(np.abs(a)))):
        _fail(cls, "acceleration_bound() must cover |xg_ddot| (at least on a grid)")
    for name in ("velocity_bound", "pga", "pgv"):
        value = getattr(obj, name)
        value = value() if callable(value) else value
        if not (math.isfinite(value) and value >= 0.0):
            _fail(cls, f"{name} must be finite and >= 0, got {value!r}")
    if not isinstance(obj.label, str):
        _fail(cls, "label must be a str")
    _check_compiled(cls, obj, t, a, scale)


def _check_scaled(cls, obj, t, a, scale) -> None:
    twice = obj.scaled(2.0)
    if type(twice) is not cls:
        _fail(cls, f"scaled() must give a {cls.__name__}, got {type(twice).__name__}")
    if not _close(twice.acceleration_array(t), 2.0 * a, 2.0 * scale):
        _fail(cls, "scaled(2) must double every acceleration")
    if not _close(obj.acceleration_array(t), a, scale):
        _fail(cls, "scaled() must leave the motion itself unchanged")
    for bad in (0.0, -1.0, math.nan):
        try:
            obj.scaled(bad)
        except ValueError:
            continue
        _fail(cls, f"scaled({bad!r}) must raise ValueError (factor > 0)")


def _check_compiled(cls, obj, t, a, scale) -> None:
    form = obj.compiled_form()
    if form is None:
        return
    if not isinstance(form, CompiledForm) or form.kind not in COMPILED_KINDS:
        _fail(cls, f"compiled_form() must be None or a CompiledForm of kind {COMPILED_KINDS}")
    if form.kind == "samples":
        compiled = _samples_form(cls, obj, form, t)
    else:
        wave = np.cos if form.kind == "cosine" else np.sin
        on = (t >= 0.0) & (t <= 2.0 * math.pi / form.omega)
        compiled = np.where(on, form.amplitude * wave(form.omega * t), 0.0)
    if not _close(compiled, a, scale):
        _fail(cls, "compiled_form() must be the motion acceleration_array gives")


def _samples_form(cls, obj, form: CompiledForm, t: np.ndarray) -> np.ndarray:
    """The acceleration a 'samples' form gives at ``t``, after checking its arrays
    (the kernels stop the excitation at the last sample: it must be the end)."""
    ts, acc = form.times, form.accelerations
    if not (isinstance(ts, np.ndarray) and isinstance(acc, np.ndarray)
            and ts.dtype == np.float64 and acc.dtype == np.float64
            and ts.ndim == 1 and ts.shape == acc.shape and ts.size >= 2):
        _fail(cls, "a 'samples' compiled form needs times and accelerations as 1-D float64 "
                   "arrays of one length >= 2")
    if not (np.all(np.isfinite(ts)) and np.all(np.isfinite(acc)) and np.all(np.diff(ts) > 0.0)
            and math.isfinite(form.amplitude)):
        _fail(cls, "a 'samples' compiled form needs finite values and increasing times")
    if ts[0] != obj.start_time or ts[-1] != obj.end_time:
        _fail(cls, "a 'samples' compiled form must span [start_time, end_time]")
    return np.interp(t, ts, form.amplitude * acc, left=0.0, right=0.0)
