"""Free-rocking restitution experiment, for any registered backend.

The trilith is released at rest from a tilt ``theta0`` with no base motion
(:class:`~analytic.excitation.Still`) and rocks freely; at every impact the
backend's measured velocity ratio ``theta_dot+ / theta_dot-`` (read away from the
impact, see :mod:`engines._common`) is compared with the analytic prediction:
Eq. 20 without the pendulum, Eq. 19 at the impact's measured ``psi`` with it
(both as corrected in :func:`analytic.equations.restitution_ratio`).

The run length comes from the analytic model itself: the time of impact ``n + 1``
under the corrected equations (Eq. 8 between impacts, Eq. 19/21 at them), so a
backend runs just long enough to show ``n`` impacts.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from analytic import equations as eq
from analytic.excitation import Still
from engines import get_backend

__all__ = ["RestitutionResult", "measure_restitution", "analytic_impact_times",
           "DEFAULT_N_IMPACTS", "MAX_N_IMPACTS"]

# Four impacts: two of each side, while the amplitude is still large enough that
# every engine resolves the impact cleanly (the amplitude drops ~e^2 per impact).
DEFAULT_N_IMPACTS = 4
MAX_N_IMPACTS = 50


@dataclass(frozen=True)
class RestitutionResult:
    """Per-impact measured and predicted velocity ratios of one free-rocking run.

    ``predicted[k]`` is Eq. 20 (``gamma = 0``) or Eq. 19 at ``psi[k]``;
    ``rel_errors[k] = measured[k] / predicted[k] - 1``.
    """

    engine: str
    version: str
    theta0: float
    psi0: float
    n_requested: int
    times: tuple[float, ...]
    sides: tuple[int, ...]
    psi: tuple[float, ...]
    theta_dot_before: tuple[float, ...]
    measured: tuple[float, ...]
    predicted: tuple[float, ...]
    rel_errors: tuple[float, ...]
    status: str
    settings: dict = field(default_factory=dict)
    scene: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    wall_time: float = math.nan

    @property
    def n_impacts(self) -> int:
        return len(self.measured)

    @property
    def complete(self) -> bool:
        """True when the run showed all ``n_requested`` impacts."""
        return self.n_impacts >= self.n_requested

    @property
    def max_rel_error(self) -> float:
        """Largest ``|measured/predicted - 1|`` (NaN without impacts)."""
        return max((abs(e) for e in self.rel_errors), default=math.nan)

    def to_dict(self) -> dict:
        out = {name: getattr(self, name) for name in (
            "engine", "version", "theta0", "psi0", "n_requested", "status", "settings",
            "scene", "diagnostics", "wall_time")}
        for name in ("times", "sides", "psi", "theta_dot_before", "measured", "predicted",
                     "rel_errors"):
            out[name] = list(getattr(self, name))
        out["n_impacts"] = self.n_impacts
        out["complete"] = self.complete
        out["max_rel_error"] = self.max_rel_error
        return out


def analytic_impact_times(scene, theta0: float, psi0: float, n: int) -> list[float]:
    """Times [s] of the first ``n`` impacts of free rocking released at rest from
    ``(theta0, psi0)``, by the corrected analytic model (Eq. 8/A.1 between
    impacts, Eq. 19/21 at them).  Fewer if the trilith comes to rest."""
    b, h, mu, gamma, j, l, g = scene.model_args()
    state = np.array([theta0, 0.0, psi0, 0.0])
    side = 1 if theta0 > 0 else -1
    t0 = 0.0
    times: list[float] = []
    # A half cycle never lasts longer than a few free-rocking periods; 20 s per
    # leg is a generous safety net for slender, slow columns.
    for _ in range(n):
        def rhs(t, y, side=side):
            td, pd = eq.rocking_accelerations(y[0], y[1], y[2], y[3], 0.0, side,
                                              b, h, mu, gamma, j, l, g)
            return (y[1], td, y[3], pd)

        def crossing(t, y, side=side):
            return side * y[0]

        crossing.terminal = True
        crossing.direction = -1
        # direction=-1: the leg starts at theta = 0 moving outwards, so only the
        # return to theta = 0 counts.
        sol = solve_ivp(rhs, (t0, t0 + 20.0), state, method="DOP853", rtol=1e-10,
                        atol=1e-12, events=crossing)
        if sol.t_events[0].size == 0:
            break
        t0 = float(sol.t_events[0][0])
        y = sol.y_events[0][0]
        times.append(t0)
        new_side = -side
        td_plus, pd_plus = eq.impact_velocities(y[1], y[2], y[3], new_side, b, h, mu, gamma, j, l)
        if td_plus == 0.0:
            break
        state = np.array([0.0, td_plus, y[2], pd_plus])
        side = new_side
    return times


def _prepare_settings(name: str, backend, settings, theta0: float, psi0: float,
                      t_max: float):
    if settings is None:
        settings = backend.Settings()
    names = {f.name for f in dataclasses.fields(settings)}
    missing = [n for n in ("theta0", "t_max") if n not in names]
    if missing:
        raise ValueError(f"engine {name!r} has no {', '.join(missing)} setting: it cannot run "
                         f"a free-rocking release yet")
    if psi0 != 0.0 and "psi0" not in names:
        raise ValueError(f"engine {name!r} has no psi0 setting; psi0 must be 0 for it")
    changes = {"theta0": theta0, "t_max": t_max}
    if "psi0" in names:
        changes["psi0"] = psi0
    if "monitor" in names:  # the engines' run monitor: keep running through the impacts
        changes["monitor"] = dataclasses.replace(settings.monitor, energy_rule=False)
    return dataclasses.replace(settings, **changes)


def measure_restitution(backend_name: str, scene, theta0: float, settings=None,
                        n_impacts: int = DEFAULT_N_IMPACTS, psi0: float = 0.0
                        ) -> RestitutionResult:
    """Release ``scene`` from tilt ``theta0`` in backend ``backend_name`` and
    compare each impact's velocity ratio with Eq. 19/20.

    Parameters
    ----------
    backend_name : str
        A registered backend (``engines.BACKENDS``) whose ``Settings`` has
        ``theta0`` and ``t_max`` (and optionally ``psi0``, ``monitor``).
    scene : Scene
    theta0 : float
        Initial tilt [rad], ``0 < |theta0| < alpha`` (released at rest; sign = side).
    settings : backend Settings or None
        Base settings; ``theta0``, ``psi0``, ``t_max`` (and the monitor's energy
        rule) are overridden.
    n_impacts : int
        Impacts to measure, in [1, 50].
    psi0 : float
        Initial pendulum angle [rad], in [-pi, pi].

    Raises
    ------
    ValueError
        Unknown backend, ``theta0`` outside ``(-alpha, alpha)`` or zero,
        ``n_impacts`` out of range, or a backend without free-rocking settings;
        all before any simulation.
    """
    backend = get_backend(backend_name)
    try:
        theta0 = float(theta0)
        psi0 = float(psi0)
    except (TypeError, ValueError):
        raise ValueError(f"theta0 and psi0 must be real numbers, got {theta0!r}, {psi0!r}") from None
    alpha = scene.alpha
    if not (math.isfinite(theta0) and 0.0 < abs(theta0) < alpha):
        raise ValueError(f"theta0 must satisfy 0 < |theta0| < alpha = {alpha:.4g} rad, "
                         f"got {theta0!r}")
    if not (math.isfinite(psi0) and abs(psi0) <= math.pi):
        raise ValueError(f"psi0 must be in [-pi, pi] rad, got {psi0!r}")
    if isinstance(n_impacts, bool) or not isinstance(n_impacts, int) or not (
            1 <= n_impacts <= MAX_N_IMPACTS):
        raise ValueError(f"n_impacts must be an integer in [1, {MAX_N_IMPACTS}], got {n_impacts!r}")
    times = analytic_impact_times(scene, theta0, psi0, n_impacts + 1)
    if len(times) < n_impacts:
        raise ValueError(f"the analytic model comes to rest after {len(times)} impacts from "
                         f"theta0 = {theta0:g} rad; ask for n_impacts <= {len(times)}")
    if len(times) > n_impacts:  # stop halfway to the next impact
        t_max = 0.5 * (times[n_impacts - 1] + times[n_impacts])
    else:
        t_max = times[-1] + 0.5
    run_settings = _prepare_settings(backend_name, backend, settings, theta0, psi0, t_max)
    from compare.runs import simulate as run_simulate  # the run store (issue 12)
    traj = run_simulate(backend_name, scene, Still(), run_settings)

    b, h, mu, gamma, j, l, g = scene.model_args()
    impacts = traj.impacts[:n_impacts]
    measured, predicted, errors, psis = [], [], [], []
    for ev in impacts:
        psi = ev.psi if scene.has_pendulum else 0.0
        pred = eq.restitution_ratio(psi, ev.side, b, h, mu, gamma, j)
        ratio = ev.velocity_ratio
        measured.append(ratio)
        predicted.append(pred)
        errors.append(ratio / pred - 1.0 if pred > 0.0 else math.nan)
        psis.append(psi)
    version = backend.version() if hasattr(backend, "version") else "unknown"
    return RestitutionResult(
        engine=backend_name, version=version, theta0=theta0, psi0=psi0,
        n_requested=n_impacts, times=tuple(e.t for e in impacts),
        sides=tuple(e.side for e in impacts), psi=tuple(psis),
        theta_dot_before=tuple(e.theta_dot_before for e in impacts),
        measured=tuple(measured), predicted=tuple(predicted), rel_errors=tuple(errors),
        status=traj.verdict.status, settings=dict(traj.settings),
        scene=scene.to_dict(), diagnostics=dict(traj.diagnostics), wall_time=traj.wall_time)
