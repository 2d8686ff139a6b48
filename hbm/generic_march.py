"""The HBM's generic AFT path: any friction element's own step marched over the period.

An axis whose friction element has no fast form here (``AxisParameters.fast_form`` not
among :data:`HBM_FAST_FORMS`) is evaluated by marching the element's bound step
(``fmu_src.friction.FrictionElement.bind``) over the N samples of one period,
starting relaxed at ``w_start``: a first pass settles the state, the second is the
periodic response (NLvib marches hysteretic elements two periods and keeps the last;
a pass more is run while the state at the period's end still changes, any of its
floats by more than :data:`REPEAT_TOL` of its size or of the largest |u|, at most
:data:`MAX_PASSES`: the whole state, since an element's position may repeat while its
other floats still settle, as a reference force kept from the last reversal does).
A rate-dependent element gets the velocity samples ``v = omega dU/dtheta`` and the
step ``dt = T / N``.

The Jacobian ``dF/dU`` is by central differences of the marched force coefficients
(step :data:`FD_STEP` times the largest |U|), 2 (2H+1) marches more: the contract
gives the element's tangents at a sample but not the sensitivity of its state, and a
hysteretic element's force depends on the state (so a per-sample tangent alone would
be a wrong Jacobian). A new element thus runs in the HBM before anyone writes a fast
form for it; a test compares it with a fine-step integration of the law.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["HBM_FAST_FORMS", "generic_periodic", "generic_aft", "MAX_PASSES"]

#: The fast forms the HBM holds: ``hbm.friction_march`` (one symmetric slider, with
#: its closed form), ``hbm.aft._aft_banks`` (banks of sliders) and ``hbm.inclined``.
HBM_FAST_FORMS = ("symmetric_slider", "slider_bank", "inclined")
#: passes over the period at most (two suffice for an element that settles at once)
MAX_PASSES = 20
#: the state at the period's end repeats when each of its floats changes by less than
#: this times its size or the largest |u| of the period (m/m) over a pass
REPEAT_TOL = 1e-13
#: central-difference step of the Jacobian, relative to the largest |U| (m/m)
FD_STEP = 1e-7


def generic_periodic(u, v, p, w_start: float, dt: float, start_state=None
                     ) -> np.ndarray:
    """The periodic friction force (N) at the samples ``u`` (m), ``v`` (m/s) of the
    element of axis ``p``, marched from its state relaxed at ``w_start`` (m), or
    from ``start_state`` (the element's own state) if given."""
    step, n = p.friction_step, p.n0
    el = p.element
    us, vs = [float(x) for x in u], [float(x) for x in v]
    state = el.start(p, w_start) if start_state is None else start_state
    out = [0.0] * len(us)
    scale = REPEAT_TOL * (max(abs(x) for x in us) + 1e-12)
    for passes in range(1, MAX_PASSES + 1):
        begin = _floats(state)
        for i, (ui, vi) in enumerate(zip(us, vs)):
            r = step(state, ui, vi, n, dt)
            state = r[1]
            out[i] = r[0]
        if passes > 1 and all(abs(a - b) <= max(REPEAT_TOL * max(abs(a), abs(b)),
                                                scale)
                              for a, b in zip(begin, _floats(state))):
            break
    return np.array(out)


def _floats(state) -> tuple:
    return (state,) if isinstance(state, float) else tuple(state)


def generic_aft(U: np.ndarray, p, w_start: float, basis, omega, jacobian: bool,
                start_state=None):
    """Force coefficients ``(2H+1,)`` of the element of axis ``p`` for the deflection
    coefficients ``U`` (2H+1,), m, and their Jacobian ``(2H+1, 2H+1)`` (None
    without ``jacobian``). ``omega`` (rad/s) is needed by rate-dependent elements;
    ``start_state`` (the element's own state) replaces the relaxed start at
    ``w_start``."""
    if p.element.rate_dependent and omega is None:
        raise ValueError(f"the friction element {p.friction_kind!r} is rate-dependent: "
                         f"its AFT needs the frequency omega")
    w = 1.0 if omega is None else float(omega)
    dt = 2.0 * math.pi / (w * basis.N)

    def force(Uc):
        u = basis.E @ Uc
        v = w * (basis.E @ (basis.D @ Uc))
        return basis.P @ generic_periodic(u, v, p, w_start, dt, start_state)

    F = force(U)
    if not jacobian:
        return F, None
    h = FD_STEP * max(float(np.max(np.abs(U))), 1e-9)
    dF = np.empty((U.size, U.size))
    for g in range(U.size):
        e = np.zeros(U.size)
        e[g] = h
        dF[:, g] = (force(U + e) - force(U - e)) / (2.0 * h)
    return F, dF
