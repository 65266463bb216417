"""How far the contacts of a structure (engines.geometry.Structure) slip in an
engine run, measured from the bodies' poses; test code only.

At each support ``(upper, lower)`` the contact corner is the narrower body's:
the upper body's bottom corner on the side it leans to, in the lower body's
frame (the ground's for a body on the ground), or, when the upper body is the
wider one (a lintel on a column), the lower body's top corner on its side, in
the upper body's frame.  Without slip that corner stays where it was when the
contact started; its largest horizontal drift is the slip.  The run is followed
while every body stands below 0.9 of its own ``alpha`` (past it a body falls,
and its contacts are no longer a rocking pivot).
"""
from __future__ import annotations

import math

from trilith_xval.engines.diagnostics import Pose

__all__ = ["support_slip"]


def _corner(frame: Pose | None, body: Pose, b: float, h: float, side: int
            ) -> tuple[float, float]:
    """The bottom corner of the ``b x h`` box at ``body`` (``side`` +1: its left
    one), in the frame of ``frame`` (None: the world)."""
    sx = -0.5 * b if side > 0 else 0.5 * b
    c, s = math.cos(body.angle), math.sin(body.angle)
    x, y = body.x + c * sx + s * 0.5 * h, body.y + s * sx - c * 0.5 * h
    if frame is None:
        return x, y
    cf, sf = math.cos(frame.angle), math.sin(frame.angle)
    dx, dy = x - frame.x, y - frame.y
    return cf * dx + sf * dy, -sf * dx + cf * dy


def support_slip(backend, scene, excitation, settings, friction: float | None = None
                 ) -> dict[tuple[str, str], float]:
    """Largest slip [m] at every support of ``scene`` run by ``backend``.

    ``friction``: a coefficient forced on the built engine past its own checks
    (a control run below the no-sliding bound); None keeps the engine's.
    """
    engine = backend(scene, excitation, settings)
    if friction is not None:
        engine.friction = friction
    st, dt = engine.structure, settings.dt
    names = [box.name for box in st.bodies]
    t_end = settings.t_max if settings.t_max is not None else excitation.end_time + 1.0
    slip = {pair: 0.0 for pair in st.supports}
    start: dict[tuple, tuple[float, float]] = {}
    engine.build()
    try:
        while engine.step_index * dt < t_end:
            state = engine.read()
            poses = state.bodies
            if any(abs(p.angle) >= 0.9 * box.alpha for p, box in zip(poses, st.bodies)):
                break
            for upper, lower in st.supports:
                iu = names.index(upper)
                pu, bu = poses[iu], st.bodies[iu]
                if lower == "ground":
                    side = 1 if pu.angle > 0.0 else -1
                    x, y = _corner(None, pu, bu.b, bu.h, side)
                    corner = (x - state.ground_x, y)
                else:
                    il = names.index(lower)
                    pl, bl = poses[il], st.bodies[il]
                    side = 1 if pu.angle > pl.angle else -1
                    if bu.b > bl.b:
                        # The lower body's top corner is the bottom corner of that
                        # body turned by pi; it leans the other way.
                        side = -side
                        corner = _corner(pu, pl._replace(angle=pl.angle + math.pi), bl.b, bl.h,
                                         side)
                    else:
                        corner = _corner(pl, pu, bu.b, bu.h, side)
                key = (upper, lower, side)
                x0 = start.setdefault(key, corner)[0]
                slip[(upper, lower)] = max(slip[(upper, lower)], abs(corner[0] - x0))
            engine.advance(settings.sample_every)
    finally:
        engine.close()
    return slip
