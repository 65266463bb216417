"""The cells of an overturn map: one engine's verdict per grid point, through the
run store (``trilith map``, ``map --record``, and their versions for the other
kinds, :mod:`compare.cli.map_kinds`)."""
from __future__ import annotations

__all__ = ["ENGINE_POINTS", "EngineRun", "RecordRun"]

ENGINE_POINTS = 8  # default engine grid: at most 8 x 8 of the analytic grid's values


class EngineRun:
    """``(A, Omega) -> Verdict`` of one engine: its run ``spec`` (a
    :class:`compare.run.spec.RunSpec`) at each cell's pulse, verdict only, the
    friction rule evaluated for that pulse, through the run store."""

    def __init__(self, spec, pulse):
        self.spec = spec.with_options("the map's cells", verdict_only=True)
        self.pulse = pulse

    def __call__(self, amplitude: float, omega: float):
        from trilith_xval.analytic.pulses import pulse_of
        from trilith_xval.compare.run import runs
        spec = self.spec.at(excitation=pulse_of(self.pulse, amplitude, omega))
        return runs.simulate(spec.backend, spec.scene, spec.excitation, spec.settings).verdict


class RecordRun:
    """``(value, k) -> Verdict`` of one backend under the record scaled to the
    intensity ``value`` and played ``k`` times slower, in the fixed window."""

    def __init__(self, backend: str, scene, record, im: str, tail: float):
        self.backend, self.scene, self.record, self.im, self.tail = (backend, scene, record,
                                                                     im, tail)

    def __call__(self, value: float, k: float):
        from trilith_xval import engines

        from trilith_xval.analytic.ida import scale_to
        from trilith_xval.compare.run import runs
        from trilith_xval.scenes.ground_motion import time_scaled
        motion = scale_to(time_scaled(self.record, k), self.im, value)
        extra = {"sample_dt": 0.01} if self.backend == "analytic" else {"verdict_only": False}
        settings = engines.configure(self.backend, t_max=motion.end_time + self.tail, **extra)
        return runs.simulate(self.backend, self.scene, motion, settings).verdict
