"""Free rocking of a scene the model does not cover (:data:`engines.geometry.RELEASE_KINDS`:
a column of drums, a block on a block): each engine's measured velocity ratio per
impact, the engines against each other; there is no Eq. 19/20 to compare with.

The structure is released at rest from a tilt (:func:`engines.geometry.structure_of`:
a block on a block turned as one rigid body about its footprint's corner, each
column of drums as one rigid stack about its base corner), with no base motion, for
a fixed window, every step sampled.  The rocking angle is the structure monitor's
``theta`` (:mod:`engines.structure_monitor`): the mean rotation of the bodies on the
ground (the lower block; the two bottom drums), so the ratio is of those bodies; the
bodies above rock with them or on them, which the largest rotation of each body
tells (``as_one``).

At each impact (a sign change of ``theta`` beyond the monitor's uplift angle) the
ratio is ``theta_dot+ / theta_dot-`` at the zero crossing of ``theta`` (interpolated
between samples), each velocity a straight line fitted over the samples with
``window <= |theta| <= 3 window`` on its side (``window``: the monitor's impact
window, 1e-3 rad, outside which engines' impacts have ended) and extrapolated to the
crossing.  Without the extrapolation the gravity acceleration over the ~1e-3 /
theta_dot s between the reading and the impact (~1 rad/s^2 for a 3 m column near
rest) would bias a slow impact (0.1 rad/s) by ~10 %; the straight line leaves the
change of that acceleration, second order.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["impact_ratios", "kind_free_rocking", "AS_ONE_TOL", "DEFAULT_WINDOW_S"]

# A body rocks with the bottom one when its largest rotation is within 5 % of the
# bottom body's: a body rocking on the one below adds its own rotation, of the order
# of the release tilt itself (tens of %), far above 5 %.
AS_ONE_TOL = 0.05
# Length of a release run [s]: a 3 m column of drums released at half its limit shows
# four impacts in 3.8 s (Pymunk, MuJoCo, 2026-11-28); 6 s leaves room for more.
DEFAULT_WINDOW_S = 6.0


def impact_ratios(t, theta, theta_dot, times, window: float) -> list[dict]:
    """Per impact time of ``times`` [s] (the monitor's: the first sample beyond the
    uplift angle on the new side): ``t`` (the zero crossing), ``before``, ``after``
    [rad/s] and ``ratio`` (module docstring); NaN where a side has fewer than two
    samples in its band (an impact too fast or too slow for the sampling)."""
    t, theta, theta_dot = (np.asarray(a, dtype=float) for a in (t, theta, theta_dot))
    rows = []
    for ti in times:
        i = min(int(np.searchsorted(t, ti)), t.size - 1)
        new = np.sign(theta[i])
        old = np.flatnonzero((np.sign(theta[:i]) == -new))
        if old.size == 0:
            continue
        c = int(old[-1])  # the last sample on the old side
        t0 = t[c] + (t[c + 1] - t[c]) * theta[c] / (theta[c] - theta[c + 1])
        before = _band(t, theta, theta_dot, range(c, -1, -1), -new, window, t0)
        after = _band(t, theta, theta_dot, range(c + 1, t.size), new, window, t0)
        ratio = after / before if math.isfinite(before) and before != 0.0 else math.nan
        rows.append({"t": float(t0), "before": before, "after": after, "ratio": ratio})
    return rows


def _band(t, theta, theta_dot, indices, sign, window: float, t0: float) -> float:
    """theta_dot at ``t0`` from the straight line through the samples of one side
    (``indices`` walking away from the crossing) with ``window <= |theta| <= 3 window``."""
    picked = []
    for k in indices:
        a = abs(theta[k])
        if np.sign(theta[k]) != sign and a >= window:
            break
        if a > 3.0 * window:
            break
        if a >= window:
            picked.append(k)
    if len(picked) < 2:
        return math.nan
    slope, cut = np.polyfit(t[picked], theta_dot[picked], 1)
    return float(slope * t0 + cut)


def kind_free_rocking(run, theta0: float, n_impacts: int, window_s: float = DEFAULT_WINDOW_S
                      ) -> dict:
    """``run``'s engine releasing its scene from ``theta0`` [rad] (module docstring):
    ``impacts`` (the first ``n_impacts`` rows of :func:`impact_ratios`), ``status``,
    ``body`` (whose rotation the ratio is of), ``as_one`` and ``max_rotation`` (each
    body's largest ``|angle|`` [rad]), ``dt``, ``cpu_s``."""
    from trilith_xval.analytic.excitation import Still
    from trilith_xval.compare.run.runs import simulate
    from trilith_xval.engines.monitor import MonitorSettings
    scene = run.scene
    settings = run.with_options("the free-rocking release", theta0=theta0, psi0=0.0,
                                t_max=window_s, early_stop=False, sample_every=1).settings
    tr = simulate(run.backend, scene, Still(), settings)
    rects = {r.name: r for r in scene.layout()}
    rotation = {name: tr.diagnostics[f"max_angle_over_alpha.{name}"]
                * math.atan2(r.b, r.h) for name, r in rects.items()
                if f"max_angle_over_alpha.{name}" in tr.diagnostics}
    ground = [n for n, lower in scene.supports() if lower == "ground"]
    bottom = max(rotation[n] for n in ground)
    as_one = all(abs(v - bottom) <= AS_ONE_TOL * bottom for n, v in rotation.items()
                 if n != "lintel")
    rows = impact_ratios(tr.t, tr.theta, tr.theta_dot, [e.t for e in tr.impacts],
                         MonitorSettings().impact_window)[:n_impacts]
    return {"engine": run.backend, "impacts": rows, "status": tr.verdict.status,
            "reason": tr.verdict.reason, "body": " and ".join(ground), "as_one": as_one,
            "max_rotation": rotation, "dt": settings.dt, "cpu_s": tr.diagnostics.get("cpu_time")}
