"""The one engine threshold search: a robust first-overturning bracket.

An engine run costs ~0.05-1 CPU s, so an engine spectrum is not scanned: at each
frequency the engine's first overturning amplitude is bisected inside a bracket
around the analytic threshold ``A_ref``, widened (doubling) only where the engine
disagrees.  Every caller (``trilith report``, ``spectrum --engine``, ``campaign``,
``map --engine``) uses :func:`engine_threshold` with :data:`SEARCH`.

Robustness.  An engine's verdict near its threshold can hang on a knife-edge:
Pymunk at Omega 12 (Fig. 5, no pendulum) overturns at exactly 0.97 A_ref and
survives at 0.9699 and 0.9701 A_ref.  So the bracket's ends are checked against
a stated perturbation set, :data:`PERTURBATIONS`, that a real test would not
control:

* the overturning end ``a_engine`` must also overturn at ``a_engine (1 + 1e-4)``,
  and with an initial tilt of 1e-6 rad at ``a_engine (1 + 2e-4)``;
* the surviving end ``a_survives`` must also survive at ``a_survives (1 - 1e-4)``,
  and with the tilt at ``a_survives (1 - 2e-4)``.

The tilted twin is one step further out because a tilt shifts a true threshold a
little (PyBullet, Fig. 5 at Omega 14 without the pendulum: the nominal run
overturns at 1.00239 A_ref, the tilted one survives there), while a knife-edge
overturn survives on both sides within 1e-5 (Pymunk at 0.97 A_ref).

An overturn that its perturbed neighbours do not reproduce is *isolated*: kept in
``isolated`` (amplitude, neighbours' verdicts), never taken as the threshold; the
search goes on above it.  A perturbed run that overturns where the nominal one
survives is isolated as well (a perturbation flipped the verdict).  Cost: 4 runs
more per point than a plain bisection (2 per end), plus 2 per isolated overturn.
A shift of the pulse's start by a fraction of a step is not in the set: a pulse
has no start time to shift (:class:`analytic.excitation.Pulse`).

Near a mode jump (the threshold curve is discontinuous in Omega) a small
frequency shift moves the threshold a lot, so jumps are measured separately, as a
frequency (:func:`compare.measure.jump_shift.engine_jump_frequency`).
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

from trilith_xval.analytic.pulses import pulse_of

from trilith_xval.compare.measure.threshold_point import Probe, ThresholdPoint
from trilith_xval.compare.measure.trajectories import settings_provenance

__all__ = ["Probe", "ThresholdPoint", "Search", "SEARCH", "PERTURBATIONS", "engine_threshold",
           "overturns", "overturns_under"]

# Relative amplitude step of the neighbours and the initial tilt [rad] of the
# robustness check.  1e-4 is 1/50 of the 0.5 % bracket and 1/200 of the 2 %
# tolerance: a neighbour that flips the verdict is a knife-edge, not a threshold.
# 1e-6 rad is 5e-6 of Fig. 5's alpha (0.197 rad) and 1/100 of the monitor's
# 1e-4 rad uplift angle: no test bench controls a column's plumb that well.
REL_NEIGHBOUR = 1e-4
TILT = 1e-6
PERTURBATIONS = {"above": f"amplitude x (1 + {REL_NEIGHBOUR:g})",
                 "below": f"amplitude x (1 - {REL_NEIGHBOUR:g})",
                 "tilt": f"initial tilt theta0 = {TILT:g} rad, amplitude one step further "
                         f"out (x (1 -/+ {2 * REL_NEIGHBOUR:g}))"}


def _check_positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return value


def overturns(backend: str, scene, omega: float, amplitude: float, settings=None,
              kind="sine") -> Probe:
    """One run of ``backend`` under a pulse (``kind``: a name of
    :data:`analytic.pulses.PULSE_FAMILY` or a :class:`~analytic.pulses.PulseShape`,
    ``amplitude`` its peak acceleration): its :class:`Probe`."""
    return overturns_under(backend, scene, pulse_of(kind, amplitude, omega), settings,
                           amplitude)


def overturns_under(backend: str, scene, motion, settings=None,
                    value: float = math.nan, verdict_only: bool = True) -> Probe:
    """One run of ``backend`` under any ground motion: its :class:`Probe`, whose
    ``amplitude`` is ``value`` (the scale the search moves).

    'collapsed', 'unstable' and 'undecided' runs do not count as overturned.
    With ``verdict_only`` (default) the run stops as soon as the verdict is
    certain; without it an overturn counts only once the columns have fallen.
    """
    from trilith_xval.engines import configure
    from trilith_xval.compare.run import runs
    settings = configure(backend, settings, verdict_only=verdict_only)
    hits = runs.STATS["hits"]
    traj = runs.simulate(backend, scene, motion, settings)
    cpu = traj.diagnostics.get("cpu_time", math.nan)
    return Probe(float(value), traj.verdict.status, traj.verdict.mode, "",
                 float(cpu) if cpu is not None else math.nan, runs.STATS["hits"] > hits,
                 float(traj.t[-1]) if len(traj.t) else 0.0)


@dataclass(frozen=True)
class Search:
    """The parameters of the one threshold search (see :func:`engine_threshold`).

    ``rel_tol`` 0.5 %: a quarter of the 2 % acceptance tolerance.  ``rel_bracket``
    0.45 rel_tol: where the engine agrees, the guard, the first bracket and its
    two robustness checks decide a point.  ``guard`` 3 %: probed first (1.5x
    the tolerance), so a narrow bracket cannot hide an overturn up to 3 % below
    the model.  ``max_expand`` 9: widenings up to 0.45 rel_tol 2^9 (115 % at
    0.5 %).  ``max_isolated`` 6: isolated overturns tolerated before the point
    is given up as not robustly bracketed.  ``failure``: the verdicts that end a
    run as a failure (default an overturn alone; the engines' consensus where
    the model is invalid also counts a collapse, with ``stop_on_collapse``
    False, :mod:`compare.measure.consensus`).
    """

    rel_tol: float = 5e-3
    rel_bracket: float = 0.45 * 5e-3
    guard: float = 0.03
    max_expand: int = 9
    stop_on_collapse: bool = True
    robust: bool = True
    max_isolated: int = 6
    failure: tuple = ("overturned",)

    @property
    def widest(self) -> float:
        """The largest amplitude the search may try, relative to ``A_ref``, rounded
        up to 0.1: the last widening ``1 + rel_bracket 2^max_expand`` with its
        robustness neighbour (``x (1 + 2 REL_NEIGHBOUR)``); 2.2 for :data:`SEARCH`
        (2.15 unrounded).  Every run of a search has the friction this pulse needs
        (:class:`compare.run.spec.RunSpec`), so its verdicts differ by the
        amplitude alone.

        >>> SEARCH.widest
        2.2
        """
        reach = (1.0 + self.rel_bracket * 2 ** self.max_expand) * (1.0 + 2.0 * REL_NEIGHBOUR)
        return math.ceil(10.0 * reach - 1e-9) / 10.0

    def with_rel_tol(self, rel_tol: float) -> "Search":
        return dataclasses.replace(self, rel_tol=rel_tol, rel_bracket=0.45 * rel_tol)


SEARCH = Search()


class _Runs:
    """The probes of one search, in order, with the CPU time they cost here."""

    def __init__(self, backend, probe, settings, failure=("overturned",)):
        self.backend, self.probe = backend, probe  # probe(value, settings) -> Probe
        self.failure = failure
        self.settings, self._tilted = settings, None
        self.probes: list[Probe] = []
        self.nominal: dict[float, Probe] = {}
        self.spent = 0.0

    def run(self, amplitude: float, perturbation: str = "") -> Probe:
        settings = self.settings
        if perturbation == "tilt":
            if self._tilted is None:
                from trilith_xval.engines import configure
                self._tilted = configure(self.backend, self.settings, theta0=TILT)
            settings = self._tilted
        c0 = time.process_time()
        p = self.probe(amplitude, settings)
        self.spent += time.process_time() - c0
        p = dataclasses.replace(p, amplitude=float(amplitude), perturbation=perturbation)
        self.probes.append(p)
        if not perturbation:
            self.nominal[p.amplitude] = p
        return p

    def fails(self, p: Probe) -> bool:
        """The run ended in a failure of the search (an overturn, by default)."""
        return p.status in self.failure

    def over(self, amplitude: float) -> bool:
        return self.fails(self.run(amplitude))

    def survived(self, amplitude: float) -> bool:
        p = self.nominal.get(amplitude)
        return p is not None and not self.fails(p)


def _isolated(p: Probe, neighbours) -> dict:
    return {"amplitude": p.amplitude, "mode": p.mode, "perturbation": p.perturbation,
            "neighbours": [n.to_dict() for n in neighbours]}


def engine_threshold(backend: str, scene, omega: float, a_reference: float, settings=None, *,
                     kind="sine", mode_reference: str | None = None,
                     search: Search = SEARCH, motion=None, **changes) -> ThresholdPoint:
    """``backend``'s robust first-overturning bracket at ``omega`` around ``a_reference``.

    Parameters
    ----------
    backend, scene, omega, a_reference, settings, kind
        The engine, scene, pulse frequency [rad/s], the model's threshold
        [m/s^2] (the bracket's centre), the engine's settings, the pulse kind
        (a name of :data:`analytic.pulses.PULSE_FAMILY` or a
        :class:`~analytic.pulses.PulseShape`; its peak acceleration is searched).
    mode_reference : str, optional
        The model's overturning mode, carried into the result.
    search : Search
        The search's parameters (default :data:`SEARCH`, shared by every caller).
    **changes
        Fields of ``search`` to replace (``rel_tol`` alone also sets
        ``rel_bracket = 0.45 rel_tol``).
    motion : callable, optional
        ``motion(value) -> excitation``: search the scale ``value`` of any ground
        motion instead of the pulse's amplitude (e.g. a record scaled to a PGA,
        :func:`analytic.ida.scale_to`); ``a_reference`` is then the model's
        value, ``omega`` only a label (NaN allowed) and ``kind`` ignored.  With a
        fixed window (``settings.t_max``) an overturn counts only when the
        columns fall inside it, as in the model's IDA
        (:func:`analytic.ida.model_verdict`): the engines' monitor calls an
        overturn certain before the fall, which may end after the window.

    Returns
    -------
    ThresholdPoint
        NaN ends when no robust bracket was found: no overturn within
        ``max_expand`` widenings, a collapse above the model with
        ``stop_on_collapse``, or more than ``max_isolated`` isolated overturns.

    Notes
    -----
    First the guard ``A_ref (1 - guard)``: an overturn there makes the search go
    downwards from it, a survival bounds it.  Then the bracket
    ``A_ref (1 -/+ rel_bracket)``, doubled outwards until it holds the first
    overturn, bisected to ``rel_tol``.  Then both ends are checked against
    :data:`PERTURBATIONS` (module docstring); an overturning end that is not
    reproduced is isolated and the search continues above it.
    """
    if motion is None:
        omega = _check_positive("omega", omega)

        def probe(a, run):
            return overturns(backend, scene, omega, a, run, kind)
    else:
        def probe(a, run):
            return overturns_under(backend, scene, motion(a), run, a,
                                   verdict_only=run is None or run.t_max is None)
    a_ref = _check_positive("a_reference", a_reference)
    if "rel_tol" in changes and "rel_bracket" not in changes:
        changes["rel_bracket"] = 0.45 * changes["rel_tol"]
    s = dataclasses.replace(search, **changes)
    if not 0.0 < s.rel_bracket < 0.5:
        raise ValueError(f"rel_bracket must be in (0, 0.5), got {s.rel_bracket!r}")
    if not 0.0 < s.rel_tol < 0.5:
        raise ValueError(f"rel_tol must be in (0, 0.5), got {s.rel_tol!r}")
    t0 = time.perf_counter()
    r = _Runs(backend, probe, settings, s.failure)
    ok, lo, hi = _first_bracket(r, a_ref, s)
    isolated: list[dict] = []
    while ok:
        while (hi - lo) > s.rel_tol * a_ref or not r.survived(lo):
            if not r.survived(lo) and hi - lo <= REL_NEIGHBOUR * a_ref:
                # Every run between the last isolated overturn and hi overturned: that
                # overturn was the threshold after all, its perturbed twin flipped (kept
                # in ``isolated``, the point is sensitive); back to the last survivor.
                lo = max(a for a, p in r.nominal.items() if not r.fails(p) and a < hi)
                hi = min(a for a, p in r.nominal.items() if r.fails(p) and a > lo)
                break
            mid = 0.5 * (lo + hi)
            if r.over(mid):
                hi = mid
            else:
                lo = mid
        else:
            if s.robust:
                checks = [r.run(hi * (1.0 + REL_NEIGHBOUR), "above"),
                          r.run(hi * (1.0 + 2.0 * REL_NEIGHBOUR), "tilt")]
                if not all(r.fails(c) for c in checks):
                    isolated.append(_isolated(r.nominal[hi], checks))
                    ok, lo, hi = _past_isolated(r, hi, a_ref, s,
                                                [i["amplitude"] for i in isolated])
                    ok = ok and len(isolated) <= s.max_isolated
                    continue
        break
    if ok and s.robust:
        nominal = r.nominal[lo]
        for c in (r.run(lo * (1.0 - REL_NEIGHBOUR), "below"),
                  r.run(lo * (1.0 - 2.0 * REL_NEIGHBOUR), "tilt")):
            if r.fails(c):  # a perturbation flipped a survivor: isolated, not the threshold
                isolated.append(_isolated(c, [nominal]))
    a_eng, a_surv = (hi, lo) if ok else (math.nan, math.nan)
    mode = r.nominal[hi].mode if ok else None
    cpu = [p.cpu_s for p in r.probes]
    return ThresholdPoint(omega, kind, a_ref, a_eng, a_surv, mode_reference, mode,
                          len(r.probes),
                          sum(p.status not in ("overturned", "survived") for p in r.probes),
                          s.rel_tol, settings_provenance(backend, settings,
                                                         time.perf_counter() - t0),
                          tuple(r.probes), tuple(isolated),
                          math.fsum(cpu) if all(math.isfinite(c) for c in cpu) else math.nan,
                          r.spent)


def _first_bracket(r: _Runs, a_ref: float, s: Search) -> tuple[bool, float, float]:
    """``(found, lo, hi)``: a nominal survivor ``lo`` below a nominal overturn ``hi``."""
    lo, hi = a_ref * (1.0 - s.rel_bracket), a_ref * (1.0 + s.rel_bracket)
    ok, moved_down, survivor = True, False, None
    step = s.rel_bracket
    if s.guard > s.rel_bracket:
        g = a_ref * (1.0 - s.guard)
        if r.over(g):  # overturns well below the model: search downwards from there
            hi, step, moved_down = g, 2.0 * s.guard, True
            ok, lo = step < 0.95, a_ref * (1.0 - 2.0 * s.guard)
        else:
            survivor = g
    while ok and r.over(lo):  # lo overturns: the engine's threshold is lower
        hi, step, moved_down = lo, 2.0 * step, True
        if survivor is not None and step >= s.guard:
            lo = survivor  # known to survive: bisect between it and hi
            break
        ok = step <= max(s.rel_bracket * 2 ** s.max_expand, 2.0 * s.guard) and step < 0.95
        lo = a_ref * (1.0 - step)
    step = s.rel_bracket
    while ok and not moved_down and not r.over(hi):  # hi survives: threshold is higher
        if s.stop_on_collapse and r.probes[-1].status == "collapsed":
            return False, math.nan, math.nan  # the frame broke above the model: no threshold
        lo, step = hi, 2.0 * step
        ok = step <= s.rel_bracket * 2 ** s.max_expand
        hi = a_ref * (1.0 + step)
    return ok, lo, hi


def _past_isolated(r: _Runs, a_iso: float, a_ref: float, s: Search,
                   isolated: list) -> tuple[bool, float, float]:
    """A new bracket above the isolated overturn ``a_iso``: up to the lowest nominal
    overturn above it not yet isolated, else widening upwards (doubling)."""
    above = sorted(a for a, p in r.nominal.items()
                   if r.fails(p) and a > a_iso and a not in isolated)
    lo = a_iso
    if above:
        return True, lo, above[0]
    step = s.rel_bracket
    for _ in range(s.max_expand + 1):
        hi = lo + step * a_ref
        if r.over(hi):
            return True, lo, hi
        if s.stop_on_collapse and r.probes[-1].status == "collapsed":
            break
        lo, step = hi, 2.0 * step
    return False, math.nan, math.nan
