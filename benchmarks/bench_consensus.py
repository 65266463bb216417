"""What a consensus point costs against a model-bracketed point, per engine, at the
same step: ``python -m benchmarks.run bench_consensus``.

For each cheap engine (``BENCH_CONSENSUS_ENGINES``, default Pymunk and MuJoCo) at
its threshold step (its calibrated step inside the calibration's domain, else its
reference step), in one run, from an empty run store:

* the model-bracketed point (:func:`compare.measure.engine_spectrum.measure_point`,
  the atlas's bracket, no cause reruns) at valid atlas points of Fig. 8 and 9;
* the engine's own threshold converged in the step
  (:func:`compare.measure.consensus.own_threshold`) at invalid ones of the same scenes.

CPU seconds (``time.process_time``: one process, no workers) per point and their
ratio; the issue's bound is 2x.  The points are fixed below (a sample, not the
atlas): the ratio holds on this sample, which is stated with it.
"""
from __future__ import annotations

import os
import statistics
import tempfile
import time

from . import machine, write

ENGINES = tuple(os.environ.get("BENCH_CONSENSUS_ENGINES", "pymunk,mujoco").split(","))
# (scene, case, Omega [rad/s]) from docs/validation/atlas.json: valid, then invalid points.
VALID = (("fig8_lam5_gamma0.1", "pendulum", 12.0), ("fig8_lam3_gamma0.2", "no_pendulum", 10.0),
         ("fig9_lam5_b0.4", "pendulum", 16.0), ("fig9_lam7_b0.2", "no_pendulum", 20.0))
INVALID = (("fig8_lam3_gamma0.1", "pendulum", 20.0), ("fig8_lam3_gamma0.3", "no_pendulum", 26.0),
           ("fig9_lam3_b0.6", "pendulum", 22.0), ("fig9_lam5_b0.6", "no_pendulum", 24.0))
REL_TOL, REL_BRACKET = 4e-3, 0.03  # the atlas's (compare.campaign.atlas.AtlasConfig)


def _reference(name: str, case: str, omega: float) -> float:
    from trilith_xval.analytic.first_overturn import SpectrumSettings, first_overturn_amplitude
    from trilith_xval.compare.campaign.study import _scene
    return first_overturn_amplitude(_scene(name, case), omega, SpectrumSettings())


def main(argv: list[str] | None = None) -> int:
    from trilith_xval.compare.campaign.study import _scene
    from trilith_xval.compare.measure.consensus import FAILURE_SEARCH, own_threshold
    from trilith_xval.compare.measure.engine_spectrum import (measure_point, point_search,
                                                              point_spec)
    from trilith_xval.compare.run import runs
    from trilith_xval.compare.run.spec import RunSpec
    from trilith_xval.compare.run.store import RunStore

    load0, t0 = os.getloadavg()[0], time.perf_counter()
    refs = {p: _reference(*p) for p in VALID + INVALID}
    rows = {}
    with tempfile.TemporaryDirectory(prefix="bench-consensus-") as tmp:
        previous = runs.activate(RunStore(tmp))
        try:
            for e in ENGINES:
                bracketed, consensus = [], []
                for p in VALID:
                    sc, (a, _, mode, *_) = _scene(p[0], p[1]), refs[p]
                    spec = point_spec(RunSpec.resolve(e, sc, calibrated=True), sc, p[2], a,
                                      search=point_search(REL_TOL, REL_BRACKET))
                    c0 = time.process_time()
                    measure_point(spec, p[2], a, mode, rel_tol=REL_TOL, rel_bracket=REL_BRACKET,
                                  convergence=False)
                    bracketed.append(time.process_time() - c0)
                for p in INVALID:
                    sc, a = _scene(p[0], p[1]), refs[p][0]
                    spec = point_spec(RunSpec.resolve(e, sc, calibrated=True), sc, p[2], a,
                                      search=FAILURE_SEARCH.with_rel_tol(REL_TOL))
                    c0 = time.process_time()
                    own_threshold(spec, p[2], a, rel_tol=REL_TOL)
                    consensus.append(time.process_time() - c0)
                mb, mc = statistics.mean(bracketed), statistics.mean(consensus)
                rows[e] = {"dt": RunSpec.resolve(e, _scene(*VALID[0][:2]),
                                                 calibrated=True).settings.dt,
                           "model_bracketed_cpu_s": bracketed, "consensus_cpu_s": consensus,
                           "mean_model_bracketed": mb, "mean_consensus": mc, "ratio": mc / mb}
                print(f"{e}: consensus {mc:.2f} CPU s per point, model-bracketed {mb:.2f} "
                      f"(ratio {mc / mb:.2f}, bound 2)")
        finally:
            runs.activate(previous)
    payload = {"engines": rows, "valid_points": VALID, "invalid_points": INVALID,
               "wall_s": time.perf_counter() - t0,
               "load_average": [load0, os.getloadavg()[0]], "machine": machine()}
    print(f"written {write('consensus', payload)}; load {load0:.2f} -> "
          f"{os.getloadavg()[0]:.2f}")
    return 0
