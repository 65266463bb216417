"""A rigid rocking block in OpenSees (openseespy): a peer code beside the model.

What is modelled (SI units throughout: m, kg, s, N, rad)
-----------------------------------------------------------
A 2-D rectangular block of half-width ``b`` and half-height ``h`` (slenderness
``alpha = atan(b/h)``, uniform mass ``m``, polar inertia about its centre
``m (b^2 + h^2)/3``) standing on a rigid, horizontal base:

* **The body** is a braced rectangle of corotational trusses (``corotTruss``:
  exact under large rotations): the four corners and the centre, every corner
  joined to its neighbours and to the centre (8 bars on 5 nodes, rigid in the
  plane).  Mass ``m/12`` sits on each corner and ``2m/3`` on the centre, which
  gives the block's mass, centre and polar inertia exactly (planar rigid-body
  dynamics needs nothing else).  The bars are :attr:`ContactSettings.body_ratio`
  times stiffer than the contact, so the body's own modes sit far above it.
* **The contact**, under each bottom corner, is a ``flatSliderBearing`` (a
  compression-only ``ENT`` axial spring and Coulomb friction on its axial force,
  ``mu_f = 10``, so that the block rocks without sliding: Housner's assumption)
  beside a vertical ``zeroLength`` with a second ``ENT`` spring that carries the
  damper (below); each spring is ``k_n / 2``.  The normal stiffness ``k_n`` is
  set from a static penetration: ``k_n = m g / (2 delta)`` with
  ``delta = penetration x b`` (default ``1e-5 b``: 3 micrometres on the 0.3 m
  half-width of ``single_block``).  The vertical contact mode then has
  ``omega_c = sqrt(g / delta)`` (1.8e3 rad/s, a 3.5 ms period), three orders
  above the rocking frequency ``p = sqrt(3 g / (4 R))`` (2.2 rad/s), so an
  impact is short against a half-cycle (0.2 s to 1 s).
* **The impact loss.**  Housner's restitution ``r = 1 - 1.5 sin^2(alpha)`` follows
  from an instantaneous impact of the new corner with angular momentum about it
  conserved.  A purely elastic penalty contact bounces (and, measured, throws
  the block off its corners), so the contact carries a viscous damper acting
  only while its corner is pressed (stiffness-proportional Rayleigh damping of
  the two ``zeroLength`` elements alone, on the current tangent of their ``ENT``
  spring, zero when the corner is lifted), of damping ratio ``zeta`` of the
  vertical contact mode.  That damper is the assumption that brings in the
  energy loss and ``zeta`` is its one free parameter: the default 0.5 is the
  value at which the measured restitution of ``single_block`` meets Housner's
  (``docs/peers.md`` measures how it moves with ``zeta``, the stiffness and the
  step, and checks the same ``zeta`` on two other slenderness values); the
  restitution coefficient itself is never imposed, it comes out of each impact.
* **Integration**: HHT (``alpha = 0.9`` in OpenSees' convention: a little
  numerical damping of the body's unresolved bar modes; 1 would be Newmark's
  average acceleration), Newton iterations, step ``dt = T_c / steps_per_contact``
  (60: 58 microseconds).  The ground motion is a ``UniformExcitation`` of a
  ``Trig`` series: ``xg_ddot = ap sin(omega t)`` for one period (Eq. 22), zero after.

Overturning (as the model's default ``topple`` criterion): overturned when
``|theta|`` reaches 1.5 rad; safe when, after the pulse, the block is inside
``|theta| < alpha`` with less mechanical energy than the barrier
``m g (R - h)`` (it can never reach ``alpha`` again: the rule of
``analytic.equations.overturn_energy_barrier``), or at ``t_max``.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from trilith_xval.analytic.parameters import G_STANDARD

__all__ = ["ContactSettings", "free_rocking", "one_sine_overturns", "threshold",
           "housner_restitution", "rocking_cycles", "version", "G", "SUBSTEPS"]

G = G_STANDARD  # m/s^2: the model's g (analytic.parameters)
DENSITY = 2500.0  # kg/m^3 (mass drops out of rigid rocking; sets force scales only)
TOPPLE_ANGLE = 1.5  # rad, analytic.trajectory.DEFAULT_TOPPLE_ANGLE


def _ops():
    try:
        import openseespy.opensees as ops
    except ImportError as exc:  # pragma: no cover - the extra is optional
        raise ImportError("the OpenSees peer needs openseespy: pip install -e '.[peers]' "
                          "(on Linux it also needs the system BLAS, libblas.so.3)") from exc
    global _QUIET
    if not _QUIET:  # OpenSees' own warnings (a Newton step retried in sub-steps)
        import os
        ops.logFile(os.devnull, "-noEcho")
        _QUIET = True
    return ops


_QUIET = False
SUBSTEPS = {"count": 0}  # steps retried in sub-steps since import (reported)


def version() -> str:
    from importlib.metadata import version as _v
    return _v("openseespy")


def housner_restitution(b: float, h: float) -> float:
    """Housner's angular-velocity ratio ``1 - 1.5 sin^2(alpha)`` of a rectangle."""
    return 1.0 - 1.5 * math.sin(math.atan2(b, h)) ** 2


@dataclass(frozen=True)
class ContactSettings:
    """The contact and integration parameters (see the module docstring)."""

    penetration: float = 1e-5   # static penetration delta over the half-width b
    zeta: float = 0.5           # damping ratio of the vertical contact mode (0: elastic)
    friction: float = 10.0      # Coulomb coefficient of the corner contacts (no sliding)
    steps_per_contact: float = 60.0  # time steps per contact period T_c
    body_ratio: float = 10.0    # bar axial stiffness over the contact stiffness
    tol: float = 1e-12          # Newton: norm of the displacement increment [m]
    # Time integrator: 'Newmark' (average acceleration: no numerical damping),
    # 'HHT' (alpha = hht_alpha), 'TRBDF2'.
    integrator: str = "HHT"
    hht_alpha: float = 0.9

    def describe(self) -> dict:
        return asdict(self)


class _Block:
    """One OpenSees domain holding the block (the interpreter is global: one at a time)."""

    # node tags: ground left/right 1, 2; corners BL 3, BR 4, TR 6, TL 7; centre 5
    def __init__(self, b: float, h: float, cs: ContactSettings, theta0: float = 0.0):
        self.ops = ops = _ops()
        self.b, self.h, self.cs = b, h, cs
        self.m = DENSITY * (2 * b) * (2 * h) * 1.0  # per metre of depth
        self.delta = cs.penetration * b
        self.kn = self.m * G / (2.0 * self.delta)
        self.omega_c = math.sqrt(G / self.delta)
        self.dt = 2.0 * math.pi / self.omega_c / cs.steps_per_contact
        ops.wipe()
        # 3 dof per node: the bearing elements need a rotation; the bars do not
        # use it, so it is fixed on every body node (a dummy, no physics).
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        ops.node(1, -b, 0.0)
        ops.node(2, b, 0.0)
        ops.fix(1, 1, 1, 1)
        ops.fix(2, 1, 1, 1)
        corners = {3: (-b, 0.0), 4: (b, 0.0), 6: (b, 2 * h), 7: (-b, 2 * h), 5: (0.0, h)}
        for tag, (x, y) in corners.items():
            ops.node(tag, x, y)
            ops.fix(tag, 0, 0, 1)
        mq = self.m / 12.0
        for tag in (3, 4, 6, 7):
            ops.mass(tag, mq, mq, 0.0)
        ops.mass(5, 2.0 * self.m / 3.0, 2.0 * self.m / 3.0, 0.0)
        self.masses = {3: mq, 4: mq, 6: mq, 7: mq, 5: 2.0 * self.m / 3.0}
        ops.uniaxialMaterial("Elastic", 1, 1.0)
        bars = [(3, 4), (4, 6), (6, 7), (7, 3), (3, 5), (4, 5), (6, 5), (7, 5)]
        ea = cs.body_ratio * self.kn * 2.0 * h  # EA/L >= body_ratio k_n on every bar
        for i, (a, c) in enumerate(bars):
            ops.element("corotTruss", 10 + i, a, c, ea, 1)
        # Contact, per corner: a flat slider bearing (axial compression-only
        # spring of k_n/2, Coulomb friction on its axial force, no damping) beside
        # a vertical zeroLength (compression-only spring of k_n/2 whose
        # stiffness-proportional damping acts only while it is compressed: the
        # bearing's own shear tangent stays on when the corner is lifted, so its
        # Rayleigh damping would brake the flight).  Normal stiffness k_n in all.
        ops.uniaxialMaterial("ENT", 2, 0.5 * self.kn)
        ops.uniaxialMaterial("Elastic", 3, self.kn * b * b)  # Mz on a fixed dummy dof
        ops.frictionModel("Coulomb", 1, 2.0 * cs.friction)  # on half the normal force
        for tag, (ground, corner) in ((1, (1, 3)), (2, (2, 4))):
            ops.element("flatSliderBearing", tag, ground, corner, 1, self.kn, "-P", 2,
                        "-Mz", 3, "-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)
        if cs.zeta > 0.0:
            for tag, (ground, corner) in ((3, (1, 3)), (4, (2, 4))):
                ops.element("zeroLength", tag, ground, corner, "-mat", 2, "-dir", 2,
                            "-doRayleigh", 1)
            # c = beta_K k_n / 2 on a compressed damper = 2 zeta k_n / omega_c, the
            # damping ratio zeta of the vertical contact mode (omega_c^2 = 2 k_n / m).
            # On the dampers only (a global `rayleigh` would also damp the bars'
            # geometric stiffness, which brakes a rigid rotation).
            ops.region(1, "-ele", 3, 4, "-rayleigh", 0.0, 4.0 * cs.zeta / self.omega_c,
                       0.0, 0.0)
        else:  # the same stiffness, no damper
            for tag, (ground, corner) in ((3, (1, 3)), (4, (2, 4))):
                ops.element("zeroLength", tag, ground, corner, "-mat", 2, "-dir", 2)
        if theta0 != 0.0:
            self._rotate(theta0)
        self._gravity()

    def _rotate(self, theta0: float) -> None:
        """Place the body rotated by ``theta0`` about its bottom corner (left for
        ``theta0 > 0``), at rest, its pivot corner at its static penetration."""
        ops, b = self.ops, self.b
        px = -b if theta0 > 0 else b
        c, s = math.cos(theta0), math.sin(theta0)
        for tag in (3, 4, 5, 6, 7):
            x, y = ops.nodeCoord(tag)
            dx, dy = x - px, y
            nx, ny = px + c * dx - s * dy, s * dx + c * dy - self.delta
            ops.setNodeDisp(tag, 1, nx - x, "-commit")
            ops.setNodeDisp(tag, 2, ny - y, "-commit")

    def _gravity(self) -> None:
        ops = self.ops
        ops.timeSeries("Constant", 1)
        ops.pattern("Plain", 1, 1)
        for tag, mi in self.masses.items():
            ops.load(tag, 0.0, -mi * G, 0.0)

    def _solver(self) -> None:
        """What the static settle and the transient share: constraints, equation
        numbering, a banded system, Newton on the displacement increment."""
        ops = self.ops
        ops.constraints("Plain")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", self.cs.tol, 50)
        ops.algorithm("Newton")

    def transient(self) -> None:
        ops = self.ops
        self._solver()
        if self.cs.integrator == "HHT":
            ops.integrator("HHT", self.cs.hht_alpha)
        elif self.cs.integrator == "TRBDF2":
            ops.integrator("TRBDF2")
        else:
            ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")

    def settle(self) -> None:
        """Upright block: let it sink onto its contacts (a static step)."""
        ops = self.ops
        self._solver()
        ops.integrator("LoadControl", 1.0)
        ops.analysis("Static")
        if ops.analyze(1) != 0:
            raise RuntimeError("OpenSees: the static settle did not converge")
        ops.loadConst("-time", 0.0)
        ops.wipeAnalysis()

    def theta(self) -> float:
        x3, y3 = np.add(self.ops.nodeCoord(3), self.ops.nodeDisp(3)[:2])
        x4, y4 = np.add(self.ops.nodeCoord(4), self.ops.nodeDisp(4)[:2])
        return math.atan2(y4 - y3, x4 - x3)

    def energy(self) -> float:
        """Kinetic + gravity energy [J], zero for the block at rest upright."""
        ops, e = self.ops, 0.0
        for tag, mi in self.masses.items():
            vx, vy = ops.nodeVel(tag)[:2]
            e += 0.5 * mi * (vx * vx + vy * vy) + mi * G * (ops.nodeDisp(tag)[1] + self.delta)
        return e

    def step(self) -> None:
        ops = self.ops
        if ops.analyze(1, self.dt) != 0:
            SUBSTEPS["count"] += 1
            for n in (4, 16):  # sub-step once before giving up
                ops.algorithm("NewtonLineSearch")
                ok = ops.analyze(n, self.dt / n)
                ops.algorithm("Newton")
                if ok == 0:
                    return
            raise RuntimeError(f"OpenSees: no convergence at t = {ops.getTime():.6f} s")


def free_rocking(b: float, h: float, theta0: float, t_end: float,
                 cs: ContactSettings | None = None, every: int = 1):
    """Free rocking from rest at ``theta0`` [rad] for ``t_end`` [s].

    Returns ``(t, theta)`` arrays (every ``every``-th step).  ``theta`` is the
    rotation of the bottom edge, positive counter-clockwise (rocking on the left
    corner, the model's convention).
    """
    cs = ContactSettings() if cs is None else cs
    blk = _Block(b, h, cs, theta0=theta0)
    blk.transient()
    n = int(math.ceil(t_end / blk.dt))
    ts, th = [0.0], [blk.theta()]
    for i in range(1, n + 1):
        blk.step()
        if i % every == 0:
            ts.append(blk.ops.getTime())
            th.append(blk.theta())
    blk.ops.wipe()
    return np.array(ts), np.array(th)


def one_sine_overturns(b: float, h: float, ap: float, omega: float,
                       cs: ContactSettings | None = None, t_max: float = 30.0) -> bool:
    """Does the one-sine ``ap sin(omega t)`` [m/s^2, rad/s] overturn the block?"""
    cs = ContactSettings() if cs is None else cs
    blk = _Block(b, h, cs)
    ops = blk.ops
    blk.settle()
    t_pulse = 2.0 * math.pi / omega
    ops.timeSeries("Trig", 2, 0.0, t_pulse, t_pulse, "-factor", ap)
    ops.pattern("UniformExcitation", 2, 1, "-accel", 2)
    blk.transient()
    alpha = math.atan2(b, h)
    barrier = blk.m * G * (math.hypot(b, h) - h)
    check = max(1, int(0.01 / blk.dt))  # energy test every ~10 ms
    i = 0
    try:
        while ops.getTime() < t_max:
            blk.step()
            i += 1
            th = blk.theta()
            if abs(th) >= TOPPLE_ANGLE:
                return True
            if i % check == 0 and ops.getTime() > t_pulse and abs(th) < alpha \
                    and blk.energy() < barrier:
                return False
        return False
    finally:
        ops.wipe()


def threshold(b: float, h: float, omega: float, cs: ContactSettings | None = None,
              lo: float | None = None, hi: float | None = None, rtol: float = 2e-3,
              t_max: float = 30.0) -> dict:
    """Lowest one-sine amplitude [m/s^2] that overturns, by bisection.

    ``lo`` must be safe and ``hi`` must overturn (defaults: ``g tan(alpha)``, the
    uplift acceleration, and 20 of it; both are checked).  Bisection assumes one
    safe-to-overturn transition inside ``[lo, hi]``: choose a bracket close to
    the model's threshold (the model's overturning map has safe islands above
    the first threshold at some frequencies).  Returns ``a_over``, ``a_safe``
    (``a_over - a_safe <= rtol a_over``) and the run count.
    """
    cs = ContactSettings() if cs is None else cs
    lo = G * b / h if lo is None else lo
    hi = 20.0 * G * b / h if hi is None else hi
    runs = 2
    if one_sine_overturns(b, h, lo, omega, cs, t_max):
        raise ValueError(f"the lower bracket {lo:g} m/s^2 overturns at omega {omega:g}")
    if not one_sine_overturns(b, h, hi, omega, cs, t_max):
        raise ValueError(f"the upper bracket {hi:g} m/s^2 does not overturn at omega {omega:g}")
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        runs += 1
        if one_sine_overturns(b, h, mid, omega, cs, t_max):
            hi = mid
        else:
            lo = mid
    return {"a_over": hi, "a_safe": lo, "runs": runs}


def rocking_cycles(t, theta, alpha: float) -> dict:
    """Impacts and peaks of a free-rocking record (any backend).

    An impact is a sign change of ``theta`` (its time interpolated linearly);
    a peak is the largest ``|theta|`` between two impacts (or before the first).
    ``restitution[n]`` is Housner's angular-velocity ratio at impact ``n``
    measured from the peaks on either side of it: ``sqrt(E_{n+1} / E_n)`` with
    ``E = cos(alpha - |theta_peak|) - cos(alpha)`` (the energy of a peak per
    ``m g R``), exact for a rigid block whose only loss is at the impacts.
    """
    t, theta = np.asarray(t, float), np.asarray(theta, float)
    s = np.sign(theta)
    idx = np.nonzero(s[1:] * s[:-1] < 0)[0]
    impacts = [float(t[i] - theta[i] * (t[i + 1] - t[i]) / (theta[i + 1] - theta[i]))
               for i in idx]
    bounds = [0, *(int(i) + 1 for i in idx), len(t)]
    peaks = []
    for a, c in zip(bounds[:-1], bounds[1:]):
        if c - a < 3:
            continue
        k = a + int(np.argmax(np.abs(theta[a:c])))
        peaks.append((float(t[k]), float(abs(theta[k]))))
    if len(peaks) and len(idx) and peaks[-1][0] > impacts[-1] and bounds[-2] + 1 < len(t):
        # the last peak only counts if the record goes past it (the block came back)
        k = int(np.argmax(np.abs(theta[bounds[-2]:]))) + bounds[-2]
        if k >= len(t) - 2:
            peaks = peaks[:-1]
    energy = [math.cos(alpha - p) - math.cos(alpha) for _, p in peaks]
    r = [math.sqrt(energy[n + 1] / energy[n]) for n in range(len(energy) - 1)
         if energy[n] > 0 and energy[n + 1] > 0]
    return {"impacts": impacts, "peaks": peaks, "restitution": r,
            "half_cycles": list(np.diff(impacts))}
