"""MuJoCo backend: the trilith as planar bodies with 3D box contacts, the
pendulum as a hinged child body of the lintel (model built from the Scene in
:mod:`engines.mujoco_.world`).

The hooks of :class:`engines.base.Engine`.  There is no ``render_frames``:
MuJoCo's renderer needs an OpenGL context (EGL/OSMesa/GLFW),
which a headless machine lacks; recordings draw MuJoCo runs in 2D from the
Trajectory (``trilith record``), as for Pymunk.

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

import dataclasses
from dataclasses import dataclass, field

import mujoco

from trilith_xval.analytic.options import check_real
from trilith_xval.engines import geometry
from trilith_xval.engines.base import Engine, EngineSettings
from trilith_xval.engines.diagnostics import PlaneState, Pose
from trilith_xval.engines.monitor import MonitorSettings

from .world import BAD_WARNINGS, mjcf

__all__ = ["MujocoEngine", "Settings", "INTEGRATORS", "CONES", "SOLVERS"]

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
    friction : float or None
        Coulomb coefficient of every contact (MuJoCo takes the larger of the
        two geoms' values; all geoms get this one).  None: ``max(10, 1.2
        required_friction)`` (:class:`engines.base.EngineSettings`); 10, as
        Pymunk; pivot sliding at point D (2.5 g) 7e-5 m.
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

    def with_solver_iterations(self, n: int) -> Settings:
        return dataclasses.replace(self, iterations=n)

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


class MujocoEngine(Engine):
    """MuJoCo (planar joints, 3D box contacts); the hooks of :class:`engines.base.Engine`.

    Examples
    --------
    >>> from trilith_xval.analytic.excitation import Pulse
    >>> from trilith_xval.scenes import load_scene
    >>> tr = MujocoEngine.simulate(load_scene("fig5"), Pulse(4.0, 9.0), Settings(t_max=0.1))
    >>> tr.backend, tr.verdict.status, tr.settings["friction_used"]
    ('mujoco', 'survived', 10.0)
    """

    name = "mujoco"
    label = "MuJoCo"
    color = "tab:purple"
    regression_point = ("fig5", 12.5)
    impact_variants = (
        ("solref timeconst=2dt", "solref: MuJoCo's smallest stable time constant",
         {"timeconst_steps": 2.0}),
        ("solref dampratio=1", "solref: MuJoCo's default damping ratio", {"dampratio": 1.0}),
        ("solimp MuJoCo default", "solimp (0.9, 0.95, 0.001, 0.5, 2)",
         {"solimp": (0.9, 0.95, 0.001, 0.5, 2.0)}),
        ("cone=pyramidal", "MuJoCo's default friction cone", {"cone": "pyramidal"}),
        ("impratio=1", "MuJoCo's default impratio", {"impratio": 1.0}),
    )
    marker = "^"
    capabilities = frozenset({"time_step", "solver_iterations", "moving_ground",
                              "initial_tilt", "trajectory", "free_block"})
    default_friction = 10.0
    structures = True  # builds any body list (engines.geometry.Structure)
    # `trilith calibrate`'s search beside the step: the contact time constant (solref),
    # in steps; MuJoCo requires at least 2 for stability (default 3).
    calibration_space = {"timeconst_steps": (2.0, 3.0, 5.0)}
    Settings = Settings

    @classmethod
    def free_block(cls, *args, settings=None):
        """A free planar block started in flight (:mod:`.free_block`), at
        ``settings`` (default: the calibrated defaults)."""
        from .free_block import free_block
        return free_block(*args, cls.Settings() if settings is None else settings)

    @classmethod
    def version(cls) -> str:
        """MuJoCo's version string, e.g. ``'mujoco 4.0.0'``."""
        return f"mujoco {mujoco.__version__}"

    def build(self) -> None:
        scene, s = self.scene, self.settings
        self.structure = geometry.structure_of(scene, s.theta0, s.psi0)
        self.xml = mjcf(self.structure, s, self.friction)
        try:
            self.model = m = mujoco.MjModel.from_xml_string(self.xml)
        except ValueError as exc:  # e.g. a body below MuJoCo's mass/inertia floor (1e-15)
            raise ValueError(f"mujoco cannot model this scene: {str(exc).splitlines()[0]} "
                             f"(scene {scene.name!r}: column_mass, gamma and l set the "
                             f"smallest body)") from None
        self.data = d = mujoco.MjData(m)
        self.moving = s.base_motion == "ground"

        def adr(joint: str) -> int:
            return int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)])

        # Slide/hinge joints only: qpos and qvel share their addresses.
        structure = self.structure
        self.boxes = [adr(f"{box.name}_x") for box in structure.bodies]
        self.pendulum = adr("pendulum_psi") if structure.bob is not None else None
        self.parent = (self.boxes[structure.index(structure.bob.parent)]
                       if structure.bob is not None else None)
        # The trilith's bodies by role (columns first, then the lintel if mu > 0).
        trilith = structure.is_trilith
        self.columns = tuple(self.boxes[:2]) if trilith else ()
        self.lintel = self.boxes[2] if trilith and len(self.boxes) > 2 else None
        self.ground = adr("ground_x") if self.moving else None
        # Joint coordinates are offsets from the upright MJCF pose.
        self.centres0 = [box.upright for box in structure.bodies]
        for a, box, (x0, y0) in zip(self.boxes, structure.bodies, self.centres0):
            x, y, angle = box.start
            d.qpos[a:a + 3] = (x - x0, y - y0, angle)
        if self.pendulum is not None:
            # Relative to its parent (the trilith's lintel starts unrotated, a turned
            # structure's parent by its tilt): the bob starts at psi0 from the vertical.
            d.qpos[self.pendulum] = s.psi0 - structure.body(structure.bob.parent).start[2]
        if self.moving:
            self._set_ground(0)
        mujoco.mj_forward(m, d)
        self._warnings = [int(getattr(mujoco.mjtWarning, w)) for w in BAD_WARNINGS]

    def close(self) -> None:
        """Nothing to release (MuJoCo frees the model with its Python objects)."""
        self.model = self.data = None

    def _set_ground(self, step: int) -> None:
        self.data.qpos[self.ground], self.data.qvel[self.ground] = self.ground_motion(step)

    def advance(self, steps: int) -> None:
        """One loop with local names: stepping is the hot path."""
        n, m, d = self.step_index, self.model, self.data
        step = mujoco.mj_step
        if self.moving:
            for k in range(n, n + steps):
                self._set_ground(k)
                step(m, d)
        else:
            gravity, load = m.opt.gravity, self.base_load
            # After the pulse the load stays 0: stop setting it.
            k_end = min(n + steps, max(n, self._load_end))
            for k in range(n, k_end):
                gravity[0] = load(k)
                step(m, d)
            if k_end < n + steps:
                gravity[0] = 0.0
                for _ in range(n + steps - k_end):
                    step(m, d)
        self.step_index = n + steps

    def read(self) -> PlaneState:
        d = self.data
        qpos, qvel = d.qpos.tolist(), d.qvel.tolist()
        problem = None
        for w in self._warnings:
            if d.warning[w].number:
                problem = f"MuJoCo warning {mujoco.mjtWarning(w).name} (state reset or invalid)"
                break

        def pose(a: int, k: int) -> Pose:
            return Pose(self.centres0[k][0] + qpos[a], self.centres0[k][1] + qpos[a + 1],
                        qpos[a + 2], qvel[a], qvel[a + 1], qvel[a + 2])

        poses = tuple(pose(a, k) for k, a in enumerate(self.boxes))
        pe, pa = self.pendulum, self.parent
        psi = psi_dot = 0.0
        if pe is not None:  # absolute angle: relative hinge angle plus the parent's rotation
            psi, psi_dot = qpos[pe] + qpos[pa + 2], qvel[pe] + qvel[pa + 2]
        gx = float(qpos[self.ground]) if self.moving else 0.0
        if not self.structure.is_trilith:
            return PlaneState((), None, psi, psi_dot, gx, problem=problem, bodies=poses)
        lintel = poses[2] if len(poses) > 2 else None
        return PlaneState(poses[:2], lintel, psi, psi_dot, gx, problem=problem)
