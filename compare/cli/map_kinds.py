"""``trilith map`` on a scene the model does not cover (:mod:`analytic.kinds`: drums,
unequal columns, a block on a block).

There is no analytic map of these kinds, so the map is the engines' own: each
engine's verdict at every ``(Omega, A)`` cell of the engine grid (the failure rule
of :mod:`engines.structure_monitor`: overturned, collapsed, survived, or the
engine's other statuses unstable / undecided), each engine's first failure on the
grid (the lowest amplitude of each frequency column that overturns or collapses),
and per cell whether every engine gives the same status.  ``--consensus`` adds, per
frequency, each engine's own first-failure amplitude converged in the step and
their consensus, as ``trilith spectrum --consensus`` gives it
(:func:`compare.measure.kind_scan.kind_point`).  Every output says it: engine
against engine, never agreement with the model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from trilith_xval.compare.cli.options import print_json
from trilith_xval.compare.report.kind_map_plot import BASIS, FAILURES, STATUSES

__all__ = ["kind_map", "kind_record_map", "report", "MapAxes", "KindMap", "STATUSES", "FAILURES", "BASIS"]



class KindMap:
    """The engines' maps on one grid.

    ``status[engine]``: (amplitude, omega) array of indices into :data:`STATUSES`;
    ``first[engine]``: per frequency the lowest grid amplitude [m/s^2] that fails
    (NaN: none on the grid); ``agree``: (amplitude, omega) bool, every engine the
    same status; ``cpu_s[engine]``: CPU seconds of its cells.
    """

    def __init__(self, omega, amplitude, status: dict, cpu_s: dict) -> None:
        self.omega, self.amplitude = np.asarray(omega, float), np.asarray(amplitude, float)
        self.status, self.cpu_s = status, cpu_s
        fails = [STATUSES.index(s) for s in FAILURES]
        self.first = {}
        for e, grid in status.items():
            col = np.isin(grid, fails)
            self.first[e] = np.array([self.amplitude[np.argmax(col[:, j])] if col[:, j].any()
                                      else math.nan for j in range(self.omega.size)])
        grids = list(status.values())
        self.agree = np.all([g == grids[0] for g in grids], axis=0)

    @property
    def disagreements(self) -> int:
        """Cells where the engines' statuses differ."""
        return int(np.sum(~self.agree))

    def counts(self, engine: str) -> dict:
        return {s: int(np.sum(self.status[engine] == i)) for i, s in enumerate(STATUSES)}

    def to_dict(self) -> dict:
        def curve(a):
            return [float(x) if math.isfinite(x) else None for x in a]
        return {"omega": self.omega.tolist(), "amplitude": self.amplitude.tolist(),
                "statuses": list(STATUSES),
                "engines": {e: {"cells": [[STATUSES[k] for k in row] for row in g.tolist()],
                                "counts": self.counts(e), "first_failure": curve(self.first[e]),
                                "cpu_s": self.cpu_s[e]}
                            for e, g in self.status.items()},
                "agree": self.agree.tolist(), "disagreements": self.disagreements}

    def csv_rows(self):
        """``engine,omega,amplitude,verdict,engines_agree`` per engine and cell,
        omega-major."""
        for e, g in self.status.items():
            for j, w in enumerate(self.omega):
                for i, a in enumerate(self.amplitude):
                    yield (f"{e},{w:.12g},{a:.12g},{STATUSES[g[i, j]]},"
                           f"{bool(self.agree[i, j])}")


def _statuses(m) -> np.ndarray:
    """The cells of ``m`` (:class:`analytic.overturn_map.OverturnMap`) as indices into
    :data:`STATUSES`: the status alone, since a kind's mode counts sign changes of
    the mean rotation of the bodies on the ground, not the model's impacts."""
    index = np.array([STATUSES.index(lab.split(" (")[0]) for lab in m.labels])
    return index[m.cells]


def _structure_engines() -> tuple[str, ...]:
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    return STRUCTURE_ENGINES


def _check(args, scene, names) -> None:
    """Refuse, before any work, what the engines' map of a kind cannot give."""
    from trilith_xval.compare.cli.options import check_structure_engines
    from trilith_xval.engines.geometry import STRUCTURE_ENGINES
    kind = scene.kind
    if not names:
        raise ValueError(f"trilith map: there is no analytic map of the {kind} kind (scene "
                         f"{scene.name!r}: the model does not cover it); give --engine E1,E2 "
                         f"(the engines against each other: {', '.join(STRUCTURE_ENGINES)})")
    check_structure_engines(names, kind, "map")
    if len(names) < 2:
        raise ValueError(f"--engine: the map of the {kind} kind compares engines with each "
                         f"other: give two or more, got {', '.join(names)}")
    if args.record is not None and args.consensus:
        raise ValueError(f"--consensus with --record does not apply to the {kind} kind: the "
                         "consensus searches a pulse's amplitude")
    if args.convergence:
        raise ValueError(f"--convergence does not apply to the {kind} kind: --consensus "
                         "converges each engine's own threshold in the step")


def kind_map(args, scene, omegas, amps, workers: int, shape) -> int:
    """The command for a scene of another kind (module docstring).  ``omegas``,
    ``amps``: the checked ``--omega``/``--amplitude`` grids the engine grid is
    taken from when ``--engine-omega``/``--engine-amplitude`` are not given;
    ``shape``: the pulse (:func:`compare.cli.pulse_shape.shape_from_args`)."""
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.analytic.overturn_map import verdict_map
    from trilith_xval.analytic.pulses import pulse_of
    from trilith_xval.compare.cli import options as _options
    from trilith_xval.compare.cli.map_cells import ENGINE_POINTS, EngineRun
    from trilith_xval.compare.cli.map_text import subsample

    model = [n.strip() for n in (args.engine or "").split(",") if n.strip().startswith("analytic")]
    if model:  # before the list's own check, which knows engines only
        raise ValueError(f"--engine {model[0]}: the model does not cover the {scene.kind} kind; "
                         f"give engines from {', '.join(_structure_engines())}")
    names = _options.parse_engine_list(args.engine) if args.engine is not None else ()
    _check(args, scene, names)
    if args.record is not None:  # the record's intensity x time scale, engines alone
        from trilith_xval.compare.cli.record_map import record_inputs
        record, _, _, values, scales = record_inputs(args, names)
        return kind_record_map(args, scene, record, values, scales, workers, names)
    w = (_options.parse_omega_range(args.engine_omega, "--engine-omega") if args.engine_omega
         else subsample(omegas, ENGINE_POINTS))
    a = (_options.parse_range(args.engine_amplitude, "--engine-amplitude", "m/s^2")
         if args.engine_amplitude else subsample(amps, ENGINE_POINTS))
    # A consensus point costs at least the scan's first probe and each engine's
    # bracket (two runs); counted so, the budget is a lower bound.
    need = len(names) * w.size * a.size + (w.size * (1 + 2 * len(names)) if args.consensus
                                           else 0)
    if need > args.max_engine_runs:
        raise ValueError(f"the engine grids need at least {need} runs ({w.size * a.size} cells "
                         f"per engine{', and the consensus' if args.consensus else ''}), more "
                         f"than --max-engine-runs {args.max_engine_runs}: coarsen "
                         f"--engine-omega/--engine-amplitude or raise --max-engine-runs")
    loaded = _options.settings_from_args(args, names)
    window = None if args.t_max is None else {"t_max": args.t_max, "early_stop": False}
    cells = {n: _options.run_spec(n, scene, Still(), loaded, overrides=window) for n in names}
    for n in names:  # a friction given below the top cell's bound: refused here
        for omega in w:
            cells[n].at(excitation=pulse_of(shape, float(max(a)), float(omega)))
    _options.step_notes(names, [scene])
    _options.use_store(args)  # every run stored: a killed map resumes
    status, cpu = {}, {}
    for n in names:
        m = verdict_map(EngineRun(cells[n], shape), scene, w, a, backend=n, pulse=shape,
                        workers=workers)
        status[n], cpu[n] = _statuses(m), m.cpu_s
    kmap = KindMap(w, a, status, cpu)
    points = None
    if args.consensus:
        from trilith_xval.compare.measure.kind_scan import kind_point
        searches = {n: _options.run_spec(n, scene, Still(), loaded, calibrated=True,
                                         overrides=window) for n in names}
        points = [kind_point(searches, scene, float(omega), shape)[0] for omega in w]
    axes = MapAxes("omega", "amplitude", "Omega [rad/s]", r"$\Omega$ [rad/s]", "m/s^2",
                   r"$A_s$ [m/s$^2$]", f"{w.size} frequencies x {a.size} amplitudes, {shape} pulse",
                   f"{shape} pulse")
    extra = {"pulse": shape, "t_max": args.t_max}
    return report(args, scene, kmap, axes, extra, points)


def kind_record_map(args, scene, record, values, scales, workers: int, names) -> int:
    """``map --record`` on a kind: each engine's verdict at every (time scale k,
    intensity) cell (:class:`compare.cli.map_cells.RecordRun`: the record scaled
    and played ``k`` times slower, in the fixed window), as :func:`kind_map` for
    pulses; ``values``, ``scales``: the engine grid, checked."""
    from trilith_xval.analytic.overturn_map import verdict_map
    from trilith_xval.compare.cli.options import use_store
    from trilith_xval.compare.cli.map_cells import RecordRun
    use_store(args)
    status, cpu = {}, {}
    for n in names:
        m = verdict_map(RecordRun(n, scene, record, args.im, args.tail), scene, scales, values,
                        backend=n, pulse=record.label, workers=workers)
        status[n], cpu[n] = _statuses(m), m.cpu_s
    unit = {"pga": "m/s^2", "pgv": "m/s", "scale": ""}[args.im]
    name = args.im.upper() if args.im != "scale" else "scale factor"
    tex = {"pga": " [m/s$^2$]", "pgv": " [m/s]", "scale": ""}[args.im]
    axes = MapAxes("time_scale", args.im, "time scale k", "time scale k (every period x k)",
                   unit, name + tex, f"{scales.size} time scales x {values.size} {args.im} "
                   f"values of record {record.label}, window end + {args.tail:g} s",
                   f"record {record.label}")
    extra = {"record": record.describe(), "im": args.im, "tail": args.tail}
    return report(args, scene, KindMap(scales, values, status, cpu), axes, extra)


@dataclass(frozen=True)
class MapAxes:
    """How a kind's map names its axes: ``x``, ``y`` the JSON/CSV names of the
    columns' and rows' values (``omega``, ``amplitude``; a record's ``time_scale``,
    ``intensity``), ``x_text`` the text table's heading, ``x_label`` and ``y_label``
    the PNG's, ``y_unit`` the rows' unit, ``what`` the grid in words, ``subject``
    the excitation in the PNG's titles."""

    x: str
    y: str
    x_text: str
    x_label: str
    y_unit: str
    y_label: str
    what: str
    subject: str


def report(args, scene, kmap: KindMap, axes: MapAxes, extra: dict, points=None) -> int:
    """Write ``--csv``/``--plot`` whole and print the JSON (``extra``: the inputs
    beside the scene) or the text of the engines' map ``kmap``."""
    names = list(kmap.status)
    _write(args, scene, kmap, points, axes)
    if args.json:
        doc = {"kind": scene.kind, "model": None, "basis": BASIS, "scene": scene.to_dict(),
               **extra, "axes": {"omega": axes.x, "amplitude": axes.y}, **kmap.to_dict()}
        if points is not None:
            doc["consensus"] = points
        from trilith_xval.compare.run.jsonable import plain
        print_json(plain(doc))
        return 0
    print(f"scene {scene.name} ({scene.kind}): no analytic map; the engines' verdicts on "
          f"{axes.what}; {BASIS}")
    for n in names:
        counts = ", ".join(f"{s} {k}" for s, k in kmap.counts(n).items() if k)
        print(f"{n}: {counts} ({kmap.cpu_s[n]:.1f} CPU s)")
    print(f"engines disagree on {kmap.disagreements} of {kmap.agree.size} cells")
    unit = f" [{axes.y_unit}]" if axes.y_unit else ""
    head = "".join(f" {n + unit:>18}" for n in names)
    print(f"first failure on the grid\n{axes.x_text:>13}{head}")
    for j, x in enumerate(kmap.omega):
        row = "".join(f" {kmap.first[n][j]:18.4g}" if math.isfinite(kmap.first[n][j])
                      else f" {'none':>18}" for n in names)
        print(f"{x:13.4g}{row}")
    if points is not None:
        from trilith_xval.compare.measure.kind_scan import SCAN_STEPS
        print("each engine's own first failure, converged in the step, and their consensus:")
        for p in points:
            own = ", ".join(f"{e} {r['a_fails']:.4g}" for e, r in p["engines"].items())
            median = "-" if p["median"] is None else f"{p['median']:.4g}"
            print(f"  Omega {p['omega']:g}: {own or f'no failure in {SCAN_STEPS} scan probes'}"
                  f"; median {median} m/s^2, {p['status']}")
    return 0


def _write(args, scene, kmap: KindMap, points, axes: MapAxes) -> None:
    """The CSV (one row per engine and cell, then each engine's converged first
    failure with ``--consensus``) and the PNG, each written whole."""
    if args.csv:
        from trilith_xval.compare.run.atomic import write_text
        rows = [f"engine,{axes.x},{axes.y},verdict,engines_agree,basis"]
        rows += [f"{r},\"{BASIS}\"" for r in kmap.csv_rows()]
        for p in points or ():
            rows += [f"{e},{p['omega']:.12g},{r['a_fails']:.12g},first failure (converged "
                     f"in the step; engines: {p['status']}),,\"{BASIS}\""
                     for e, r in p["engines"].items()]
        write_text(args.csv, "\n".join(rows) + "\n")
    if args.plot:
        from trilith_xval.compare.report.kind_map_plot import plot_kind_map
        plot_kind_map(kmap, args.plot, scene, axes, points)
