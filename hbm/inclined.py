"""The inclined two-surface friction element (thesis Ch. 5) in the AFT of the HBM.

A mount axis whose friction element is the inclined one (``friction_kind =
"inclined"``, :mod:`fmu_src.inclined`) carries normal forces N and N2 that vary over
the period with the element's own kinematics. :func:`inclined_periodic` marches the
element's exact return map over the samples of one period, so the periodic force
(and the normal forces) come from the one law, in axis coordinates exactly as
:func:`fmu_src.mount_law.axis_force` (element deflection ``x = -u``, axis force
``-N2``). :func:`inclined_aft` adds the force's Fourier coefficients and their
Jacobian to :func:`hbm.aft.aft_forces`, so systems with inclined axes go through the
general :func:`hbm.frequency_response` (continuation, stability, folds, the error
estimate).

Convention (as the Jenkins element's, PHYSICS.md section 1): the element starts
from the static working point's state (``NonlinearAxes.start_states``: by default
the engine lowered onto the assembled mount, ``hbm.static.lowered_equilibrium``), or
relaxed at the axis deflection ``w_start`` (:func:`fmu_src.inclined.relaxed_state`)
without one, moves to the first sample in one increment and passes over the period
follow until both sliders repeat.

Jacobian: exact, by forward differentiation of the march. In one increment the end
forces are affine in the end deflection and the stuck surfaces' sliders
(:func:`fmu_src.inclined.step_derivatives`); the sliders' derivatives with respect to
the coefficients are carried from sample to sample through every pass (the start
state does not depend on them), so the derivative is that of the computed function
(Newton converges quadratically, tests/test_hbm_inclined.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drymount.fmu_src.inclined import (InclinedParameters, InclinedState,
                                       inclined_update, relaxed_state,
                                       step_derivatives)

__all__ = ["PeriodicElement", "inclined_periodic", "inclined_aft",
           "normal_force_range", "STUCK_INCLINED", "STUCK_FLAT", "stuck_codes",
           "orbit_element_states"]

#: passes of the periodic march before it gives up (sliders repeat after two or three)
MAX_PASSES = 20
#: sliders repeat when they change by less than this times the largest |u| of the
#: period (m/m) over a pass
REPEAT_TOL = 1e-13
#: a surface sticks for the whole period when its slider moves by less than this
#: times the largest |u| of the period (m/m) over the last pass
STUCK_TOL = 1e-9
#: bits of :attr:`PeriodicElement.stuck_code`: the inclined surface (1) or the flat
#: surface (2) sticks for the whole period (3: both, the element is linear)
STUCK_INCLINED, STUCK_FLAT = 1, 2


@dataclass(frozen=True)
class PeriodicElement:
    """Periodic response of the element on an axis to sampled deflections ``u``.

    ``force`` the axis force (N, = -N2), ``n1``, ``n2`` the normal forces N and N2
    (N); ``dforce`` (N, 2H+1) its derivative with respect to the deflection
    coefficients (N/m; None without the Jacobian); ``passes`` marched and whether the
    sliders repeated (``converged``); ``w1``, ``w2`` the sliders (m, element
    coordinates) after each sample of the last pass, ``u`` the samples (m)."""

    force: np.ndarray
    n1: np.ndarray
    n2: np.ndarray
    dforce: np.ndarray | None
    passes: int
    converged: bool
    w1: np.ndarray | None = None
    w2: np.ndarray | None = None
    u: np.ndarray | None = None

    @property
    def stuck_code(self) -> int:
        """Which surfaces stick for the whole period: ``STUCK_INCLINED`` (1),
        ``STUCK_FLAT`` (2), both (3) or none (0). Where exactly one sticks the
        periodic state is a family (its stuck slider is any value of an interval,
        fixed by the history) and this orbit is one member of it."""
        tol = STUCK_TOL * (float(np.max(np.abs(self.u))) + 1e-12)
        code = 0
        for bit, w in ((STUCK_INCLINED, self.w1), (STUCK_FLAT, self.w2)):
            if float(np.ptp(w)) <= tol:
                code |= bit
        return code

    def state_at(self, k: int) -> InclinedState:
        """The element's committed state after sample ``k`` of the periodic orbit
        (the state a time simulation started on the orbit at that phase needs)."""
        return InclinedState(float(self.w1[k]), float(self.w2[k]), float(self.u[k]))


def inclined_periodic(u: np.ndarray, p: InclinedParameters, w_start: float = 0.0,
                      E: np.ndarray | None = None, start_state=None) -> PeriodicElement:
    """March the element over the axis deflections ``u`` (m) until the period repeats.

    It starts relaxed at ``w_start``, or from ``start_state`` (an
    :class:`InclinedState`, e.g. the engine lowered onto the mount: ``hbm.static``).

    ``E`` (N, 2H+1): the Fourier basis of ``u = E U``; given, the derivative of the
    force at every sample with respect to ``U`` is carried along (``dforce``).
    Raises :class:`fmu_src.inclined.ContactLost` when the motion asks for N < 0 or
    N2 < 0.
    """
    us = [float(v) for v in u]
    n = len(us)
    jac = E is not None
    m = E.shape[1] if jac else 0
    st0 = relaxed_state(p, w_start) if start_state is None else start_state
    w1, w2, x_old = st0.w1, st0.w2, -st0.uc
    # rows: d x / dU, d x_old / dU (the start deflection is fixed), d w1 / dU, d w2 / dU
    sens = np.zeros((4, m))
    minus_E = -E if jac else None
    force = np.empty(n)
    dforce = np.empty((n, m)) if jac else None
    n1 = np.empty(n)
    n2 = np.empty(n)
    w1s = np.empty(n)
    w2s = np.empty(n)
    scale = REPEAT_TOL * (max(abs(v) for v in us) + 1e-12)
    converged, passes = False, 0
    for passes in range(1, MAX_PASSES + 1):
        w_begin = (w1, w2)
        for i, ui in enumerate(us):
            x = -ui
            st = inclined_update(x, x_old, w1, w2, p)
            if jac:
                dF, _, dw1, dw2 = step_derivatives(x, x_old, w1, w2, p, st)
                sens[0] = minus_E[i]
                new = np.array((dF, dw1, dw2)) @ sens
                dforce[i] = -new[0]
                sens[1] = sens[0]
                sens[2:] = new[1:]
            w1, w2, x_old = st.w1, st.w2, x
            force[i] = -st.force
            n1[i], n2[i] = st.n1, st.n2
            w1s[i], w2s[i] = w1, w2
        if passes > 1 and abs(w1 - w_begin[0]) <= scale \
                and abs(w2 - w_begin[1]) <= scale:
            converged = True
            break
    return PeriodicElement(force, n1, n2, dforce, passes, converged, w1s, w2s,
                           np.asarray(u, dtype=float).copy())


def inclined_aft(u: np.ndarray, ax, basis, jacobian: bool):
    """The inclined axes' forces and Jacobian for :func:`hbm.aft.aft_forces`.

    ``u`` (..., N, n_ax): deflection samples of every nonlinear axis; ``ax`` the
    :class:`hbm.elements.NonlinearAxes` (its ``inclined`` entries ``(a, p)``).
    Returns ``[(a, F_a, dF_a)]``: the force coefficients (..., 2H+1) of axis column
    ``a`` and their Jacobian (..., 2H+1, 2H+1) (None without ``jacobian``).
    """
    E, P = basis.E, basis.P
    out = []
    batch = u.shape[:-2]
    flat = u.reshape(-1, *u.shape[-2:])
    for a, p in ax.inclined:
        F = np.empty((flat.shape[0], P.shape[0]))
        dF = np.empty((flat.shape[0], P.shape[0], E.shape[1])) if jacobian else None
        for b, ub in enumerate(flat):
            el = inclined_periodic(ub[:, a], p, float(ax.w_start[a]),
                                   E if jacobian else None, ax.start_state(a))
            F[b] = P @ el.force
            if jacobian:
                dF[b] = P @ el.dforce
        out.append((a, F.reshape(*batch, -1),
                    dF.reshape(*batch, *dF.shape[1:]) if jacobian else None))
    return out


def normal_force_range(u: np.ndarray, p: InclinedParameters, w_start: float = 0.0
                       ) -> tuple[float, float, float, float]:
    """``(min N, max N, min N2, max N2)`` in N over the periodic response to ``u``."""
    el = inclined_periodic(u, p, w_start)
    return (float(el.n1.min()), float(el.n1.max()), float(el.n2.min()),
            float(el.n2.max()))



def _orbit_elements(hb, X: np.ndarray) -> list:
    """``[(a, PeriodicElement)]`` of the inclined axes of the HBM problem ``hb``
    (:class:`hbm.residual.HarmonicBalance`) on the solution ``X`` (m n,)."""
    ax = hb.axes
    if not ax.inclined:
        return []
    u = hb.basis.E @ hb.axis_coefficients(np.asarray(X, dtype=float))
    return [(a, inclined_periodic(u[:, a], p, float(ax.w_start[a]),
                                  start_state=ax.start_state(a)))
            for a, p in ax.inclined]


def stuck_codes(hb, coefficients: np.ndarray) -> np.ndarray | None:
    """Per point and inclined axis, which surfaces stick for the whole period
    (:attr:`PeriodicElement.stuck_code`), shape (n_points, n_inclined); None without
    inclined axes. ``coefficients`` (n_points, n, 2H+1) as
    :attr:`hbm.result.FrequencyResponse.coefficients` (NaN rows: gaps, code 0)."""
    if not hb.axes.inclined:
        return None
    out = np.zeros((len(coefficients), len(hb.axes.inclined)), dtype=int)
    for i, c in enumerate(coefficients):
        if not np.all(np.isfinite(c)):
            continue
        for k, (_, el) in enumerate(_orbit_elements(hb, np.asarray(c).T.ravel())):
            out[i, k] = el.stuck_code
    return out


def orbit_element_states(hb, X: np.ndarray) -> dict:
    """The inclined elements' states at phase 0 of the HBM orbit ``X`` (m n,):
    ``{(element index, axis index): InclinedState}`` after the first sample of the
    periodic march (the orbit's deflection at t = 0), what a time simulation started
    on the orbit needs besides the DOFs (:mod:`vehicle.steady`)."""
    return {hb.axes.index[a]: el.state_at(0) for a, el in _orbit_elements(hb, X)}
