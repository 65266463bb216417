"""DART (dartpy): the trilith as planar 3D boxes with rigid (LCP) contact.

The world is built from the scene's body list (:class:`~engines.geometry.Structure`,
in :mod:`engines.dart_.world`; the trilith's is the world built before the body
list, bit for bit): two ``b x h``
columns and the lintel on planar joints in the vertical x-z plane, box-on-box
contact with DART's collision detector and the boxed LCP (Dantzig) of its
constraint solver, and a point-like pendulum bob on a revolute joint at the
lintel's underside that collides with nothing, like the analytic pendulum
(Eq. 1, 8).  ``gamma = 0`` builds no pendulum, ``mu = 0`` no lintel.

Base motion: ``"gravity"`` sets the d'Alembert load as gravity's x component
before each step (the one rule of :meth:`engines.base.Engine.base_load`).  The
coordinates of a planar joint hung from the world origin are the body's centre
and CCW angle in the analytic plane, so :meth:`DartEngine.read` copies them.

Measured at the defaults (``docs/dart.md``): restitution against Eq. 20 (lam
3/5/7 x mu 0.5/1/2) and Eq. 19 (lam 3/5/7, gamma 0.3), four impacts each,
within 0.27 %; about 0.85 CPU s per simulated second on the Fig. 5 frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import dartpy as dart

from trilith_xval.engines import geometry
from trilith_xval.engines.base import Engine, EngineSettings
from trilith_xval.engines.diagnostics import PlaneState, Pose, joint_plane_state

from .world import COLLISION_DETECTORS, DartWorld

__all__ = ["DartEngine", "Settings"]


@dataclass(frozen=True)
class Settings(EngineSettings):
    """Numerical settings of the DART backend; defaults are the calibrated ones.

    The run options and engine fields (``criterion``, ``t_max``, ``theta0``,
    ``psi0``, ``early_stop``, ``dt``, ``base_motion``, ``sample_every``,
    ``monitor``, ``friction``) are :class:`engines.base.EngineSettings`; their
    defaults hold.  ``dt`` 1e-4 s: at 1e-3 s a single block's restitution was
    0.93 % low (``/work/shared/notes/dart-drake.md``); DART's rigid LCP makes
    the impact plastic in one step, so the error is the step's share of the
    free motion.  ``friction`` None: ``max(10, 1.2 required_friction)``; DART
    takes the smaller of two shapes' coefficients and every shape gets this one.
    Restitution coefficients are 0 on every shape (DART's coefficient had no
    effect at rocking impact speeds of ~0.1 m/s anyway).

    Parameters
    ----------
    detector : {'dart', 'fcl', 'bullet', 'ode'}
        Collision detector.  ``'dart'`` (DART's own box-box routine): single
        block restitution +0.04 %; FCL, Bullet and ODE gave +0.03 % and ran
        ~20 % faster, so the choice is free; DART's own needs no extra library.
    deactivation : bool
        dartpy's body deactivation (default True, dartpy's own default): a body
        slower than 0.01 m/s and 0.05 rad/s for 0.5 s has every velocity set to 0.
        It freezes slow swings and moves a threshold near a slow rocking (Notes);
        False switches it off.  The default stays True while DART's stored
        calibration, atlas part and spectra are those measured with it.

    Notes
    -----
    At fig9_lam7_b0.8 with the pendulum, Omega 6 rad/s, 2e-4 s, the atlas's search
    finds a window +2.62 % above the model with deactivation on and agrees
    (+0.38 %) with it off; at Omega 5.8 and 6.2 rad/s both agree
    (``python -m benchmarks.dart_deactivation``, ``docs/dart.md``).
    """

    detector: str = "dart"
    deactivation: bool = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.base_motion != "gravity":
            raise ValueError(f"dart Settings: base_motion must be 'gravity' (DART has no moving "
                             f"ground here), got {self.base_motion!r}")
        if not isinstance(self.deactivation, bool):
            raise TypeError(f"dart Settings: deactivation must be true or false, got "
                            f"{self.deactivation!r}")
        if self.detector not in COLLISION_DETECTORS:
            raise ValueError(f"dart Settings: detector must be one of {COLLISION_DETECTORS}, "
                             f"got {self.detector!r}")


class DartEngine(Engine):
    """DART (rigid multibody, LCP contact); the hooks of :class:`engines.base.Engine`."""

    name = "dart"
    label = "DART"
    color = "tab:cyan"
    regression_point = ("no_pendulum", 12.5)
    impact_variants = (
        ("detector=fcl", "FCL collision detector", {"detector": "fcl"}),
        ("detector=bullet", "Bullet collision detector", {"detector": "bullet"}),
    )
    impact_fixed = ("the constraint solver (DART's boxed LCP, Dantzig) is fixed; the "
                    "collision detector is the setting")
    marker = "v"
    affordable = False  # 10-55 CPU s per threshold point (docs/atlas.md)
    capabilities = frozenset({"time_step", "initial_tilt", "trajectory"})
    default_friction = 10.0
    structures = True  # builds any body list (engines.geometry.Structure)
    Settings = Settings

    @classmethod
    def version(cls) -> str:
        """dartpy's version, e.g. ``'dartpy 6.20.0'``."""
        return f"dartpy {dart.__version__}"

    def build(self) -> None:
        s = self.settings
        self.structure = geometry.structure_of(self.scene, s.theta0, s.psi0)
        self.world = DartWorld(self.structure, s.dt, self.friction, s.detector, s.deactivation)

    def advance(self, steps: int) -> None:
        n = self.step_index
        load = self.base_load
        self.world.steps([load(k) for k in range(n, n + steps)])
        self.step_index = n + steps

    def read(self) -> PlaneState:
        world = self.world
        states = world.planar_states()
        pendulum = world.pendulum_state() if world.pendulum is not None else None
        if self.structure.is_trilith:
            return joint_plane_state(states, pendulum)
        poses = tuple(Pose(*map(float, state)) for state in states)
        psi = psi_dot = 0.0
        if pendulum is not None:
            parent = poses[world.parent_index]
            psi, psi_dot = pendulum[0] + parent.angle, pendulum[1] + parent.omega
        return PlaneState((), None, psi, psi_dot, bodies=poses)

    def close(self) -> None:
        world, self.world = getattr(self, "world", None), None
        if world is not None:
            world.close()
