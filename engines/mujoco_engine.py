"""MuJoCo backend: the trilith as planar bodies with 3D box contacts, the
pendulum as a hinged child body of the lintel (model built from the Scene in
:mod:`engines.mujoco_scene`).

Contract (``engines/__init__.py``): ``NAME``, ``version()``, ``Settings``,
``simulate(scene, excitation, settings) -> Trajectory``.  There is no
``render_frames``: MuJoCo's renderer needs an OpenGL context (EGL/OSMesa/GLFW),
which a headless machine lacks; recordings draw MuJoCo runs in 2D from the
Trajectory (``compare/show/record.py``), as for Pymunk.

Base motion: ``"gravity"`` adds the d'Alembert load ``-xg_ddot(t + dt/2)`` to
gravity in the base frame each step (exact for a rigid translating base);
``"ground"`` puts a heavy box on a slide joint whose position and velocity are
set to the ground's motion before every step.  (A mocap ground moved through
``mocap_pos`` does not work: the contact sees no ground velocity and the trilith
never rocks, ``/work/shared/notes/mujoco.md``.)

Every run builds a fresh ``MjModel``/``MjData`` from the generated MJCF, so runs
are independent and bit-identical.  ``mu = 0``: no lintel body, the columns rock
independently (the ``mu = 0`` frame of Eq. 8); with a pendulum this is refused
(the hinge needs a lintel).

Measured accuracy at the defaults (docs/mujoco.md): restitution vs Eq. 20
(lam 3/5/7 x mu 0.5/1/2) within 0.051 %, vs Eq. 19 within 0.053 %, 0.13 % over
216 impacts from three release angles; A-D verdicts and modes as the analytic
model with and without the pendulum, overturning times within 0.9 %, theta RMS
before the first impact <= 2.1e-4 alpha; the overturning amplitude at 12.5 rad/s
(pendulum) equal to the analytic within the 0.4 % bisection step.

Sleeping stays off (MuJoCo's default; ``<flag sleep="enable"/>`` freezes a
rocking block released at rest) and so does any contact margin (a margin
without gap makes contacts act at a distance).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mujoco

from analytic.options import check_real
from analytic.trajectory import Trajectory
from engines import mujoco_scene as ms
from engines._common import MonitorSettings, required_friction
from engines.base import BASE_MOTIONS, EngineSettings, check_run, simulate_world

__all__ = ["NAME", "Settings", "simulate", "version", "BASE_MOTIONS", "INTEGRATORS", "CONES",
           "SOLVERS"]

NAME = "mujoco"
CAPABILITIES = frozenset({"time_step", "solver_iterations", "moving_ground", "initial_tilt",
                          "trajectory"})
INTEGRATORS = ("Euler", "implicitfast", "implicit", "RK4")
CONES = ("elliptic", "pyramidal")
SOLVERS = ("Newton", "CG", "PGS")


def version() -> str:
    """MuJoCo's version string, e.g. ``'mujoco 4.0.0'``."""
    return f"mujoco {mujoco.__version__}"


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Numerical settings of a MuJoCo run; defaults are the calibrated ones.

    Parameters
    ----------
    criterion : OverturnCriterion
        Shared overturning criterion (same as the analytic model).
    t_max : float or None
        Run length cap [s]; None: decided by the monitor (rest / energy rules).
    dt : float
        Time step [s] (``<option timestep>``).  1e-4 s as the other engines;
        5e-5 s was no better with the earlier 10-step contact (outliers to 1.1 %).
    theta0, psi0 : float
        Initial tilt and pendulum angle [rad], released at rest (``theta0 > 0``
        leans left, on the left corners).
    base_motion : {'gravity', 'ground'}
        How the base excitation is imposed (see the module docstring).  They
        agree within 0.07 % of the peak angle (point B, pendulum, 1.5 s).
    sample_every : int
        Steps between state reads: the shared default (4 ms, see
        :class:`engines.base.EngineSettings`).
    monitor : MonitorSettings
        Shared stop rules, with ``impact_window`` 5e-3 rad: a soft contact is
        still relaxing its impact penetration ~1 ms after the impact, so the
        velocities are read from samples farther away.  At the shared 1e-3 rad
        the restitution errors were up to 0.33 % (Eq. 20 grid), at 5e-3 rad
        0.05 %.
    friction : float
        Coulomb coefficient of every contact (MuJoCo takes the larger of the
        two geoms' values; all geoms get this one).  Must be >=
        :func:`engines._common.required_friction`.  10, as Pymunk: above the
        bound for pulses up to 10 g; pivot sliding at point D (2.5 g) 7e-5 m.
    timeconst_steps : float
        Contact ``solref`` time constant in time steps (used when ``timeconst``
        is None).  3 (3e-4 s): with ``dampratio = 3`` this is about the
        stiffness of the critically damped 10-step contact of the MuJoCo notes.
        The restitution is set by the damping ratio, not the stiffness: at
        ``dampratio = 1`` the corner rebounds and the column hops after each
        impact, -2.6 % at lam = 3 for 10, 20 steps and for dt down to 2e-5 s.
    timeconst : float or None
        Contact ``solref`` time constant [s]; None: ``timeconst_steps * dt``.
        MuJoCo silently raises it to at least ``2 dt``.
    dampratio : float
        Contact ``solref`` damping ratio.  3 (overdamped: the impact is plastic,
        no rebound).  Max restitution error over lam 3/5/7 x mu 0/0.5/1/2 at 10
        steps: 2.6 % at 1, 0.37 % at 3, 0.52 % at 4, 1.2 % at 6.
    solimp : tuple of 5 floats
        Contact impedance ``(dmin, dmax, width, midpoint, power)``.  dmin = dmax
        = 0.99: the contact's static compliance ``(1 - d)/d g / k`` is 11 times
        smaller than with MuJoCo's default (0.9, 0.95): theta RMS before the
        first impact at A/C 0.9e-4 alpha instead of 1.2-1.4e-3, uplift within
        0.1 ms of Eq. 9 instead of 0.6-1.1 ms early.
    cone : {'elliptic', 'pyramidal'}
        Friction cone.  Elliptic: pyramidal gave +15 % restitution at lam = 3
        (the frame creeps).
    impratio : float
        Ratio of frictional to normal constraint impedance (elliptic cone).
        10, per the MuJoCo notes; 100 was no better (0.85 % outliers, 10-step contact).
    iterations : int
        Constraint solver iterations per step.  MuJoCo's default 100 (Newton
        converges in a few; 1 iteration gave -14 % in the MuJoCo notes).
    solver : {'Newton', 'CG', 'PGS'}
        Constraint solver; MuJoCo's default.
    integrator : {'Euler', 'implicitfast', 'implicit', 'RK4'}
        Time integrator.  Euler (MuJoCo's default): implicitfast gave the same
        ratios to 0.02 % (no joint damping to treat implicitly; 10-step contact).

    Calibration (free rocking at fig. 5 scale, b = 0.6 m, released at rest from
    0.3, 0.5 and 0.8 alpha, 4 impacts each; lam 3/5/7 x mu 0.5/1/2 against Eq.
    20 and lam 3/5/7 with the pendulum against Eq. 19; 216 impacts): every
    error within 0.13 %, median 0.02 %.  Details in docs/mujoco.md.
    """

    monitor: MonitorSettings = field(default_factory=lambda: MonitorSettings(impact_window=5e-3))
    friction: float = 10.0
    timeconst_steps: float = 3.0
    timeconst: float | None = None
    dampratio: float = 3.0
    solimp: tuple[float, float, float, float, float] = (0.99, 0.99, 0.001, 0.5, 2.0)
    cone: str = "elliptic"
    impratio: float = 10.0
    iterations: int = 100
    solver: str = "Newton"
    integrator: str = "Euler"

    @property
    def solver_iterations(self) -> int:
        """The contract's name for ``iterations`` (convergence studies double it)."""
        return self.iterations

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_own(self)

    def describe(self) -> dict:
        out = super().describe()
        out["timeconst_effective"] = max(self.effective_timeconst(), 2.0 * self.dt)
        return out

    def effective_timeconst(self) -> float:
        """The contact time constant [s] asked for (MuJoCo applies at least 2 dt)."""
        return self.timeconst if self.timeconst is not None else self.timeconst_steps * self.dt


def _check_own(s: Settings) -> None:
    """MuJoCo's own fields, at construction; ValueError naming the field."""
    def real(name, value, lo, hi, lo_open=True):
        check_real("mujoco Settings", name, value, lo, hi, lo_open=lo_open)

    def integer(name, value, lo, hi):
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ValueError(f"mujoco Settings: {name} must be an integer in [{lo}, {hi}], "
                             f"got {value!r}")

    def choice(name, value, allowed):
        if value not in allowed:
            raise ValueError(f"mujoco Settings: {name} must be one of {allowed}, got {value!r}")

    real("timeconst_steps", s.timeconst_steps, 0.0, 1e6)
    if s.timeconst is not None:
        real("timeconst", s.timeconst, 0.0, 10.0)
    real("dampratio", s.dampratio, 0.0, 100.0)
    if not (isinstance(s.solimp, tuple) and len(s.solimp) == 5):
        raise ValueError(f"mujoco Settings: solimp must be a tuple (dmin, dmax, width, midpoint, "
                         f"power), got {s.solimp!r}")
    for label, value, lo, hi in zip(("dmin", "dmax", "width", "midpoint", "power"), s.solimp,
                                    (0.0, 0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0, 1.0, 100.0)):
        real(f"solimp {label}", value, lo, hi, lo_open=label != "power")
    choice("cone", s.cone, CONES)
    real("impratio", s.impratio, 0.0, 1e6)
    integer("iterations", s.iterations, 1, 100_000)
    choice("solver", s.solver, SOLVERS)
    choice("integrator", s.integrator, INTEGRATORS)


def _validate(scene, excitation, s: Settings) -> None:
    """Checks that need the scene, before anything is built."""
    check_run(NAME, Settings, s, scene, excitation)


def simulate(scene, excitation, settings: Settings | None = None) -> Trajectory:
    """Run ``scene`` under ``excitation`` in MuJoCo; returns a :class:`Trajectory`.

    Parameters
    ----------
    scene : analytic.parameters.Scene
    excitation : Pulse, SampledRecord or Still
    settings : Settings or None
        None: the calibrated defaults.

    Returns
    -------
    Trajectory
        Sampled every ``sample_every`` steps; diagnostics ``lintel_rotation_max``
        [rad], ``pivot_sliding_max`` [m], ``penetration_max`` [m] (over the rocking
        regime), ``steps``, ``wall_time`` [s], ``required_friction``.

    Raises ``ValueError`` for bad settings before any model is built.  A blow-up
    (non-finite state, a MuJoCo reset warning, a body flown away or too fast)
    gives the verdict ``'unstable'``.

    Examples
    --------
    >>> from analytic.excitation import Pulse
    >>> from scenes import load_scene
    >>> tr = simulate(load_scene("fig5"), Pulse(4.0, 9.0), Settings(t_max=0.1))
    >>> tr.backend, tr.verdict.status
    ('mujoco', 'survived')
    """
    s = settings if settings is not None else Settings()
    _validate(scene, excitation, s)
    info = s.describe()
    info["engine_version"] = version()

    def make_world():
        world = ms.World(scene, excitation, s, s.friction)
        world.diag["required_friction"] = required_friction(scene, excitation)
        return world

    return simulate_world(NAME, make_world, scene, excitation, s, info)
