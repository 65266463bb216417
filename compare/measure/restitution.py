"""Free-rocking restitution: one measurement, one result type, for any backend.

The trilith is released at rest from a tilt ``theta0`` with no base motion
(:class:`~analytic.excitation.Still`) and rocks freely; at every impact the
backend's measured velocity ratio ``theta_dot+ / theta_dot-`` (read away from the
impact: :mod:`engines.monitor`) is compared with the model: Eq. 20 without the
pendulum, Eq. 19 at the impact's measured ``psi`` with it (both as corrected in
:func:`analytic.equations.restitution_ratio`, ``docs/paper-errata.md``), times the
restitution factor ``r`` when one is given: the target a measured restitution
sets (``docs/model.md``).

The run length comes from the analytic model itself (:mod:`analytic.simulate`
released from the same tilt): a backend runs to halfway between impacts ``n`` and
``n + 1``, just long enough to show ``n`` impacts.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from trilith_xval.analytic import equations as eq
from trilith_xval.analytic.excitation import Still
from trilith_xval.analytic.trajectory import Trajectory

__all__ = ["ImpactRestitution", "RestitutionResult", "measure_restitution", "free_rocking",
           "restitution_from_trajectory", "analytic_impact_times", "DEFAULT_N_IMPACTS", "DEFAULT_THETA0_FRACTION",
           "MAX_N_IMPACTS"]

# Four impacts: two of each side, while the amplitude is still large enough that
# every engine resolves the impact cleanly (the amplitude drops ~e^2 per impact).
DEFAULT_N_IMPACTS = 4
# The release tilt, as a fraction of the static overturning angle: large, clean
# impacts far from toppling.
DEFAULT_THETA0_FRACTION = 0.5
MAX_N_IMPACTS = 50


@dataclass(frozen=True)
class ImpactRestitution:
    """One impact: measured ``theta_dot+/theta_dot-`` against Eq. 19/20.

    ``side`` is the side entered (+1 left corners); ``psi`` [rad] the pendulum
    angle at the impact (0 without a pendulum).
    """

    t: float
    side: int
    psi: float
    theta_dot_before: float
    measured: float
    predicted: float

    @property
    def rel_error(self) -> float:
        """``measured / predicted - 1`` (NaN if the prediction is 0)."""
        return self.measured / self.predicted - 1.0 if self.predicted != 0.0 else math.nan

    def to_dict(self) -> dict:
        return {"t": self.t, "side": self.side, "psi": self.psi,
                "theta_dot_before": self.theta_dot_before, "measured": self.measured,
                "predicted": self.predicted, "rel_error": self.rel_error}


@dataclass(frozen=True)
class RestitutionResult:
    """Per-impact measured and predicted velocity ratios of one free-rocking run."""

    engine: str
    version: str
    lam: float
    mu: float
    gamma: float
    theta0: float
    psi0: float
    n_requested: int
    impacts: tuple[ImpactRestitution, ...]
    status: str
    settings: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    wall_time: float = math.nan
    restitution_factor: float = 1.0

    @property
    def equation(self) -> str:
        """``'Eq. 19'`` with a pendulum (at the measured psi), else ``'Eq. 20'``;
        prefixed by ``'r x '`` when the target is scaled by a restitution factor."""
        name = "Eq. 19" if self.gamma > 0.0 else "Eq. 20"
        return name if self.restitution_factor == 1.0 else f"{self.restitution_factor:g} x {name}"

    @property
    def n_impacts(self) -> int:
        return len(self.impacts)

    @property
    def complete(self) -> bool:
        """True when the run showed all ``n_requested`` impacts."""
        return self.n_impacts >= self.n_requested

    @property
    def max_rel_error(self) -> float:
        """Largest ``|measured/predicted - 1|`` (NaN without impacts)."""
        return max((abs(i.rel_error) for i in self.impacts), default=math.nan)

    def to_dict(self) -> dict:
        """Every field; ``restitution_factor`` only when it is not 1 (the exact
        impact), so that documents of exact-impact runs stay as they were."""
        extra = {} if self.restitution_factor == 1.0 else {
            "restitution_factor": self.restitution_factor}
        return {"engine": self.engine, "version": self.version, "lam": self.lam,
                "mu": self.mu, "gamma": self.gamma, "equation": self.equation,
                "theta0": self.theta0, "psi0": self.psi0, "n_requested": self.n_requested,
                "n_impacts": self.n_impacts, "complete": self.complete,
                "impacts": [i.to_dict() for i in self.impacts],
                "max_rel_error": self.max_rel_error, "status": self.status,
                "settings": self.settings, "diagnostics": self.diagnostics,
                **extra, "wall_time": self.wall_time}


def analytic_impact_times(scene, theta0: float, psi0: float, n: int) -> list[float]:
    """Times [s] of the first ``n`` impacts of free rocking released at rest from
    ``(theta0, psi0)``, by the analytic backend itself (fewer if it comes to rest).

    Examples
    --------
    >>> from trilith_xval.scenes import load_scene
    >>> scene = load_scene("fig5", gamma=0.0)
    >>> [round(t, 4) for t in analytic_impact_times(scene, 0.5 * scene.alpha, 0.0, 2)]
    [0.6721, 1.8117]
    """
    from trilith_xval.analytic.simulate import Settings, simulate
    # early_stop off: released inside the well, the energy is below the barrier at
    # t = 0 and the exact rules would stop at once; 60 s is far past the impacts
    # of interest (fig5: the fourth impact comes at ~3.7 s) and costs ~0.2 s.
    traj = simulate(scene, Still(), Settings(theta0=theta0, psi0=psi0, early_stop=False,
                                             sample_dt=None, t_cap=60.0))
    return [e.t for e in traj.impacts[:n]]


def restitution_from_trajectory(traj: Trajectory, scene=None, n_impacts: int | None = None,
                                restitution_factor: float = 1.0
                                ) -> tuple[ImpactRestitution, ...]:
    """Each impact event of ``traj`` against the model (Eq. 20, or Eq. 19 at the
    impact's measured ``psi`` with a pendulum, times ``restitution_factor``); the
    event ``side`` is the side entered."""
    scene = scene if scene is not None else traj.scene
    if scene is None:
        raise ValueError("scene must be given when the trajectory carries none")
    if n_impacts is not None and (isinstance(n_impacts, bool) or not isinstance(n_impacts, int)
                                  or n_impacts < 1):
        raise ValueError(f"n_impacts must be None or an integer >= 1, got {n_impacts!r}")
    b, h, mu, gamma, j, _l, _g = scene.model_args()
    rows = []
    for ev in traj.impacts[:n_impacts]:
        psi = ev.psi if (gamma > 0.0 and math.isfinite(ev.psi)) else 0.0
        side = ev.side if ev.side in (-1, 1) else (1 if ev.theta_dot_after > 0 else -1)
        rows.append(ImpactRestitution(float(ev.t), int(side), float(psi),
                                      float(ev.theta_dot_before), float(ev.velocity_ratio),
                                      restitution_factor
                                      * eq.restitution_ratio(psi, side, b, h, mu, gamma, j)))
    return tuple(rows)


def measure_restitution(backend: str, scene, theta0: float | None = None, settings=None,
                        n_impacts: int = DEFAULT_N_IMPACTS, psi0: float = 0.0,
                        restitution_factor: float = 1.0, **options) -> RestitutionResult:
    """Release ``scene`` from tilt ``theta0`` in ``backend`` and compare each
    impact's velocity ratio with Eq. 19/20: :func:`free_rocking` of the run these
    arguments make (:class:`compare.run.spec.RunSpec`, built once here).

    Parameters
    ----------
    backend : str
        A registered backend declaring the ``'initial_tilt'`` capability.
    scene : Scene
    theta0 : float, optional
        Initial tilt [rad], ``0 < |theta0| < alpha`` (released at rest; sign =
        side).  Default ``alpha / 2``: well inside the well, fast impacts.
    settings : the backend's Settings, optional
        Base settings (every field a layer of the run, "the settings given");
        ``options`` go over them, as :func:`engines.configure` would apply them.
    n_impacts, psi0, restitution_factor
        As :func:`free_rocking`.

    Returns
    -------
    RestitutionResult

    Raises
    ------
    ValueError
        Unknown backend or one without free-rocking releases, ``theta0`` outside
        ``(-alpha, alpha)`` or zero, ``n_impacts`` out of range, a setting the
        backend refuses (naming it); before any run.

    Examples
    --------
    >>> from trilith_xval.scenes import load_scene
    >>> r = measure_restitution("pymunk", load_scene("fig5", gamma=0.0), n_impacts=2)
    >>> r.equation, r.n_impacts, r.max_rel_error < 0.005
    ('Eq. 20', 2, True)
    """
    from trilith_xval.compare.run.spec import RunSpec
    _check_tilt_backend(backend)
    given = {} if settings is None else {f.name: getattr(settings, f.name)
                                         for f in dataclasses.fields(settings)}
    run = RunSpec.resolve(backend, scene, Still(), overrides={**given, **options},
                          overrides_from="the options given")
    return free_rocking(run, theta0, n_impacts=n_impacts, psi0=psi0,
                        restitution_factor=restitution_factor)


def _check_tilt_backend(backend: str) -> None:
    """ValueError unless ``backend`` is registered and can release from a tilt."""
    from trilith_xval.engines import get_backend, supports
    get_backend(backend)
    if not supports(backend, "initial_tilt"):
        raise ValueError(f"engine {backend!r} cannot release the trilith from a tilt "
                         f"(no 'initial_tilt' capability)")


def free_rocking(run, theta0: float | None = None, n_impacts: int = DEFAULT_N_IMPACTS,
                 psi0: float = 0.0, restitution_factor: float = 1.0) -> RestitutionResult:
    """Release ``run``'s scene from tilt ``theta0`` in its backend and compare each
    impact's velocity ratio with Eq. 19/20.

    Parameters
    ----------
    run : compare.run.spec.RunSpec
        The backend, the scene and the settings, under no base motion
        (:class:`~analytic.excitation.Still`); ``theta0``, ``psi0``, ``t_max`` and
        ``early_stop=False`` are set here, one more layer over its own.
    theta0 : float, optional
        Initial tilt [rad], ``0 < |theta0| < alpha`` (released at rest; sign =
        side).  Default ``alpha / 2``: well inside the well, fast impacts.
    n_impacts : int
        Impacts to measure, in [1, 50].
    psi0 : float
        Initial pendulum angle [rad], in [-pi, pi].
    restitution_factor : float
        In (0, 1]: the target is Eq. 19/20 times it (a measured restitution);
        the analytic backends also run with it.  The run's length still comes
        from the exact model, whose impacts are the latest (a lossier rocking
        swings lower, hence faster), so the run shows at least ``n_impacts``.

    Returns
    -------
    RestitutionResult

    Raises
    ------
    ValueError
        A backend without free-rocking releases, a run under a base motion,
        ``theta0`` outside ``(-alpha, alpha)`` or zero, ``n_impacts`` out of
        range; before any run.
    """
    from trilith_xval.engines import get_backend
    backend, scene = run.backend, run.scene
    _check_tilt_backend(backend)
    if not isinstance(run.excitation, Still):
        raise ValueError(f"free rocking has no base motion: the run's excitation must be "
                         f"Still, got {type(run.excitation).__name__}")
    alpha = scene.alpha
    theta0 = 0.5 * alpha if theta0 is None else theta0
    for name, value in (("theta0", theta0), ("psi0", psi0)):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise TypeError(f"{name} must be a real number, got {value!r}")
    theta0, psi0 = float(theta0), float(psi0)
    if not (math.isfinite(theta0) and 0.0 < abs(theta0) < alpha):
        raise ValueError(f"theta0 must satisfy 0 < |theta0| < alpha = {alpha:.4g} rad, "
                         f"got {theta0!r}")
    if not (math.isfinite(psi0) and abs(psi0) <= math.pi):
        raise ValueError(f"psi0 must be in [-pi, pi] rad, got {psi0!r}")
    from trilith_xval.analytic.options import check_restitution_factor
    restitution_factor = check_restitution_factor("measure_restitution", restitution_factor)
    if isinstance(n_impacts, bool) or not isinstance(n_impacts, int) or not (
            1 <= n_impacts <= MAX_N_IMPACTS):
        raise ValueError(f"n_impacts must be an integer in [1, {MAX_N_IMPACTS}], got {n_impacts!r}")
    times = analytic_impact_times(scene, theta0, psi0, n_impacts + 1)
    if len(times) < n_impacts:
        raise ValueError(f"the analytic model comes to rest after {len(times)} impacts from "
                         f"theta0 = {theta0:g} rad; ask for n_impacts <= {len(times)}")
    t_max = (0.5 * (times[n_impacts - 1] + times[n_impacts]) if len(times) > n_impacts
             else times[-1] + 0.5)
    release = {"theta0": theta0, "psi0": psi0, "t_max": t_max, "early_stop": False}
    if restitution_factor != 1.0 and backend.startswith("analytic"):
        release["restitution_factor"] = restitution_factor  # the model runs it too
    settings = run.with_options("the free-rocking release", **release).settings
    from trilith_xval.compare.run.runs import simulate  # through the run store
    traj = simulate(backend, scene, Still(), settings)
    return RestitutionResult(
        engine=backend, version=get_backend(backend).version(), lam=scene.lam, mu=scene.mu,
        gamma=scene.gamma, theta0=theta0, psi0=psi0, n_requested=n_impacts,
        impacts=restitution_from_trajectory(traj, scene, n_impacts, restitution_factor),
        status=traj.verdict.status, settings=dict(traj.settings),
        diagnostics=dict(traj.diagnostics), wall_time=traj.wall_time,
        restitution_factor=restitution_factor)
