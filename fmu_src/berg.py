"""Berg's smooth friction element (``friction_kind = "berg"``): the friction part of
Berg's rubber-spring model of rail-vehicle dynamics (Berg 1998, Vehicle System
Dynamics 30; docs/physics.md "Berg friction").

From the reference point (xs, Fxs), the last reversal of the motion, the friction
force follows a hyperbola towards the slip force s Fm (s the direction of motion):

    F = Fxs + kf d A / (A + kf |d|),   d = u - xs,   A = Fm - s Fxs,   Fm = mu n

which is Berg's form with x2 = Fm / kf (the deflection from the virgin state at which
F = Fm / 2) and alpha = Fxs / Fm. The tangent ``kf A^2 / (A + kf |d|)^2`` is kf after
every reversal and tends to 0 as F tends to s Fm. The reference moves to the
committed point (uc, F) when the increment reverses the direction (and at the first
motion from the relaxed start). Berg's model is rate independent and path dependent
only through its reversal points: it is not a semigroup (restarting the hyperbola
inside a branch would change it), so the state carries the reference. A reference
force beyond a lowered slip force is clipped to [-Fm, Fm] for the evaluation.

The energy dissipated in an increment is the exact work of F over it,
``((s Fxs + A) kf |du| - A^2 ln(1 + kf |du| / (A + t0))) / kf`` (t0 = kf |uc - xs|),
less the change of the energy ``F^2 / (2 kf)`` stored at the reversal stiffness,
clamped at 0 (right after a reversal from a large force Berg's slip runs against the
force: the hyperbola is not a Masing curve). A lost contact (n <= 0) drops the force
and releases the stored energy. The state is :class:`BergState`. Standard library
only.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .friction import ElementStep, FrictionElement
from .jenkins import JENKINS, contact_normal_forces

__all__ = ["BERG", "BergState"]

_new = tuple.__new__


class BergState(NamedTuple):
    """Committed state: the force ``force`` (N) at the deflection ``uc`` (m), the
    reference point (``xs`` m, ``fxs`` N) and the direction ``s`` of the last motion
    (1.0, -1.0; 0.0 at the relaxed start)."""

    force: float
    uc: float
    xs: float
    fxs: float
    s: float


def _bind(p):
    kf, mu = p.kf, p.mu

    def step(state, u, v, n, dt):
        f0, uc, xs, fxs, s0 = state
        fm = mu * n if n > 0.0 else 0.0
        du = u - uc
        if fm <= 0.0:   # lost contact: no force, the stored energy is released
            return _new(ElementStep, (0.0, _new(BergState, (0.0, u, u, 0.0, 0.0)),
                                      0.0, 0.0, du != 0.0, f0 * f0 / (2.0 * kf)))
        if du == 0.0:
            return _new(ElementStep, (f0, state, kf, 0.0, False, 0.0))
        s = 1.0 if du > 0.0 else -1.0
        if s != s0:   # a reversal (or the first motion): the reference moves here
            xs, fxs = uc, f0
        fr = fxs if -fm <= fxs <= fm else (fm if fxs > fm else -fm)
        a = fm - s * fr
        t0 = kf * s * (uc - xs)
        t1 = kf * s * (u - xs)
        h = kf * abs(du)
        den = a + t1
        f1 = fr + s * a * t1 / den
        work = (s * fr + a) * h
        if a > 0.0:
            work -= a * a * math.log1p(h / (a + t0))
        diss = work / kf - (f1 * f1 - f0 * f0) / (2.0 * kf)
        return _new(ElementStep, (f1, _new(BergState, (f1, u, xs, fxs, s)),
                                  kf * a * a / (den * den), 0.0, True,
                                  diss if diss > 0.0 else 0.0))
    return step


BERG = FrictionElement(
    name="berg",
    summary="Berg's smooth friction (Berg 1998): F = Fxs + kf d A / (A + kf |d|) from "
            "the last reversal (xs, Fxs), A = Fm - s Fxs, Fm = mu n",
    fields=tuple(f for f in JENKINS.fields if f.name in ("kf", "mu", "n0")),
    bind=_bind,
    state_size=lambda p: 5,
    start=lambda p, w=0.0: BergState(0.0, float(w), float(w), 0.0, 0.0),
    position=lambda state: state.uc,
    stuck_stiffness=lambda p: p.kf,
    normal_forces=contact_normal_forces,
    c_port="ml_berg",
)
