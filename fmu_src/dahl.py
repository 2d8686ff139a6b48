"""The Dahl friction element (``friction_kind = "dahl"``): a smooth, rate-independent
model of pre-sliding friction (Dahl 1968; docs/physics.md "Dahl friction").

The friction force F follows the deflection u through

    dF/du = kf (1 - sign(du) F / Fc),     Fc = mu * n   (n: the normal force)

so it starts with the contact stiffness kf after a reversal and tends to +-Fc while
u keeps moving (exponent 1 of Dahl's law). For a monotonic increment du from a state
(F0, uc) the equation has the exact solution

    F = s Fc - (s Fc - F0) exp(-kf |du| / Fc),    s = sign(du)

with the consistent tangent dF/du = kf (1 - s F / Fc) (kf at du = 0, the mean of the
two one-sided tangents). The energy dissipated in the increment is the work done,
``Fc |du| - s (Fc / kf)(F - F0)``, less the change of the energy stored in the
bristle, ``(F^2 - F0^2) / (2 kf)``: the integral of ``F^2 / Fc`` over the path (>= 0).
A lost contact (n <= 0) drops the force and releases the stored energy. The state is
:class:`DahlState` (the force and the committed deflection). Standard library only.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .friction import ElementStep, FrictionElement
from .jenkins import JENKINS, contact_normal_forces

__all__ = ["DAHL", "DahlState"]

_new = tuple.__new__


class DahlState(NamedTuple):
    """Committed state: the friction force ``force`` (N) and deflection ``uc`` (m)."""

    force: float
    uc: float


def _bind(p):
    kf, mu = p.kf, p.mu

    def step(state, u, v, n, dt):
        f0, uc = state
        fc = mu * n if n > 0.0 else 0.0
        du = u - uc
        if fc <= 0.0:   # lost contact: no force, the stored energy is released
            return _new(ElementStep, (0.0, _new(DahlState, (0.0, u)), 0.0, 0.0,
                                      du != 0.0, f0 * f0 / (2.0 * kf)))
        if du == 0.0:
            return _new(ElementStep, (f0, state, kf, 0.0, False, 0.0))
        s = 1.0 if du > 0.0 else -1.0
        sfc = s * fc
        f1 = sfc - (sfc - f0) * math.exp(-kf * abs(du) / fc)
        work = fc * abs(du) - s * (fc / kf) * (f1 - f0)
        diss = work - (f1 * f1 - f0 * f0) / (2.0 * kf)
        return _new(ElementStep, (f1, _new(DahlState, (f1, u)),
                                  kf * (1.0 - s * f1 / fc), 0.0, True,
                                  diss if diss > 0.0 else 0.0))
    return step


DAHL = FrictionElement(
    name="dahl",
    summary="Dahl element: dF/du = kf (1 - sign(du) F / Fc), Fc = mu n (smooth "
            "pre-sliding; kf the stiffness after a reversal)",
    fields=tuple(f for f in JENKINS.fields if f.name in ("kf", "mu", "n0")),
    bind=_bind,
    state_size=lambda p: 2,
    start=lambda p, w=0.0: DahlState(0.0, float(w)),
    position=lambda state: state.uc,
    stuck_stiffness=lambda p: p.kf,
    normal_forces=contact_normal_forces,
    c_port="ml_dahl",
)
