"""Harmonic balance of a mass on the inclined two-surface friction mount (Ch. 5).

The element's normal forces N and N2 vary over the period with its own kinematics
(:mod:`fmu_src.inclined`); the AFT march (:func:`inclined_periodic`) carries them
sample by sample with the element's exact return map, so the periodic force, and the
normal forces, come from the one law. The system is the thesis's SDOF (Sec. 2.1.1): an
engine mass ``m`` on an elastomer (``k1``, ``c``) in parallel with the element, a
harmonic force on the mass, the chassis fixed. :func:`inclined_time_reference`
integrates the same system in time (velocity Verlet, the element's exact map per
step) for the independent check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from fmu_src.inclined import ContactLost, InclinedParameters, inclined_update
from hbm.aft import FourierBasis, default_n_samples

__all__ = ["InclinedSDOF", "PeriodicElement", "InclinedHBMResult", "inclined_periodic",
           "solve_inclined_hbm", "inclined_time_reference"]

#: passes of the periodic march before it gives up (sliders repeat after two or three)
_MAX_PASSES = 20
#: a solution's residual norm, relative to the force amplitude (a root, not a minimum)
_RESIDUAL_TOL = 1e-8


@dataclass(frozen=True)
class InclinedSDOF:
    """Mass ``m`` (kg) on an elastomer ``k1`` (N/m), ``c`` (N s/m) and the element
    ``p``; force ``force_amp * sin(omega t)`` (N) on the mass, plus the static
    ``weight`` (N)."""

    m: float = 70.0
    k1: float = 45935.0
    c: float = 150.0
    p: InclinedParameters = InclinedParameters()
    force_amp: float = 200.0
    weight: float = 0.0


@dataclass(frozen=True)
class PeriodicElement:
    """Periodic response of the element to sampled motion: force F = N2, normal force
    N of the inclined surface, friction forces, all in N, and whether the sliders
    repeated (``converged``) within the passes."""

    force: np.ndarray
    n1: np.ndarray
    n2: np.ndarray
    f1: np.ndarray
    f2: np.ndarray
    converged: bool


def inclined_periodic(x: np.ndarray, p: InclinedParameters, tol: float = 1e-13
                      ) -> PeriodicElement:
    """March the exact return map over the samples ``x`` (m) until the period repeats.

    The element is assembled at x = 0 with relaxed sliders (w1 = w2 = 0) and moved to
    ``x[0]`` in one increment; passes over the period follow until both sliders repeat
    to ``tol`` (relative to the slip displacement scale).
    """
    xs = [float(v) for v in x]
    n = len(xs)
    st = inclined_update(xs[0], 0.0, 0.0, 0.0, p)
    w1, w2 = st.w1, st.w2
    out = np.zeros((5, n))
    scale = tol * (max(abs(v) for v in xs) + 1e-12)
    converged = False
    for _ in range(_MAX_PASSES):
        w_start = (w1, w2)
        xo = xs[-1] if _ else xs[0]
        for i, xi in enumerate(xs):
            st = inclined_update(xi, xo, w1, w2, p)
            w1, w2, xo = st.w1, st.w2, xi
            out[:, i] = (st.force, st.n1, st.n2, st.f1, st.f2)
        if abs(w1 - w_start[0]) <= scale and abs(w2 - w_start[1]) <= scale:
            converged = True
            break
    return PeriodicElement(out[0], out[1], out[2], out[3], out[4], converged)


@dataclass(frozen=True)
class InclinedHBMResult:
    """Steady state by HBM at one frequency: displacement coefficients ``X`` (m, the
    order of :class:`hbm.aft.FourierBasis`), the element's periodic response, the
    residual norm and whether the solver succeeded (``message`` says why not)."""

    freq_hz: float
    X: np.ndarray
    element: PeriodicElement
    residual: float
    success: bool
    message: str


def _linear_matrix(sys: InclinedSDOF, omega: float, H: int) -> np.ndarray:
    A = np.zeros((2 * H + 1, 2 * H + 1))
    A[0, 0] = sys.k1
    for k in range(1, H + 1):
        kw = k * omega
        blk = np.array([[sys.k1 - sys.m * kw ** 2, sys.c * kw],
                        [-sys.c * kw, sys.k1 - sys.m * kw ** 2]])
        A[2 * k - 1:2 * k + 1, 2 * k - 1:2 * k + 1] = blk
    return A


def solve_inclined_hbm(sys: InclinedSDOF, freq_hz: float, harmonics: int = 7,
                       n_samples: int | None = None, x0: np.ndarray | None = None
                       ) -> InclinedHBMResult:
    """Harmonic balance of :class:`InclinedSDOF` at ``freq_hz`` with AFT.

    ``R(X) = A(omega) X + P F(E X) - f``; ``F`` the element's force from
    :func:`inclined_periodic` (the varying normal force inside), ``f`` the weight
    (constant term) and the harmonic force (sine of harmonic 1). Solved by
    ``scipy.optimize.root`` (hybrid Powell, then Levenberg-Marquardt if that fails,
    finite-difference Jacobians) from ``x0`` or the linear response. Raises
    :class:`fmu_src.inclined.ContactLost` when the solution found needs a negative
    normal force.
    """
    H = harmonics
    basis = FourierBasis(H, n_samples or default_n_samples(H))
    omega = 2 * math.pi * freq_hz
    A = _linear_matrix(sys, omega, H)
    f = np.zeros(2 * H + 1)
    f[0] = sys.weight
    f[2] = sys.force_amp
    if x0 is None:
        # start: the linear system with the element stuck (about kf in series)
        x0 = np.linalg.solve(A + 0.5 * sys.p.kf * np.eye(2 * H + 1), f)
    scale = max(np.abs(x0).max(), 1e-6)
    norm = max(sys.force_amp, 1.0)

    def resid(z):
        try:
            el = inclined_periodic(basis.E @ (z * scale), sys.p)
        except ContactLost:
            # a trial iterate outside the contact domain: a large residual makes
            # the trust region shrink (only the converged point must keep contact)
            return np.full(z.shape, 1e6)
        return (A @ (z * scale) + basis.P @ el.force - f) / norm

    sol = root(resid, x0 / scale, method="hybr", options={"xtol": 1e-12})
    if not sol.success:   # Levenberg-Marquardt from the same start
        sol = root(resid, x0 / scale, method="lm", options={"xtol": 1e-13})
    X = sol.x * scale
    el = inclined_periodic(basis.E @ X, sys.p)   # raises ContactLost if it has none
    res = float(np.linalg.norm(resid(sol.x)))
    ok = bool(sol.success) and el.converged and res <= _RESIDUAL_TOL
    return InclinedHBMResult(freq_hz, X, el, res, ok,
                             str(sol.message) + ("" if res <= _RESIDUAL_TOL else
                                                 f" (residual {res:.3g} not a root)"))


class _LawElement:
    """The element's exact map, committed at every call: ``element(x, v, t) -> F``."""

    def __init__(self, p: InclinedParameters):
        self.p, self.x, self.w1, self.w2 = p, 0.0, 0.0, 0.0

    def __call__(self, x: float, v: float, t: float) -> float:
        st = inclined_update(x, self.x, self.w1, self.w2, self.p)
        self.x, self.w1, self.w2 = x, st.w1, st.w2
        return st.force


def inclined_time_reference(sys: InclinedSDOF, freq_hz: float, *, periods: int = 400,
                            steps: int = 1000, x_start: float = 0.0,
                            rtol: float = 1e-7, element=None) -> np.ndarray:
    """Last period of a time integration (velocity Verlet with a velocity predictor,
    ``steps`` per period, the element's exact map each step): displacement samples.

    Runs until two successive periods differ by less than ``rtol`` times the
    period's peak-to-peak displacement, at most ``periods`` periods (a stuck element
    damps the start-up transient only by ``c``). ``element(x, v, t)`` gives the
    element's force at deflection ``x`` (m), rate ``v`` (m/s, the half-step
    velocity) and time ``t`` (s) and commits its state there (called once per step,
    first at t = 0 from the relaxed element at x = 0); default the law in-process,
    ``vehicle.inclined.InclinedFMU`` drives the InclinedMount FMU instead."""
    T = 1.0 / freq_hz
    dt = T / steps
    om = 2 * math.pi * freq_hz
    element = _LawElement(sys.p) if element is None else element
    x, v = x_start, 0.0
    acc = (sys.weight - sys.k1 * x - sys.c * v - element(x, v, 0.0)) / sys.m
    prev, cur = np.full(steps, np.inf), np.empty(steps)
    for period in range(periods):
        for j in range(steps):
            t = (period * steps + j) * dt
            v_half = v + 0.5 * dt * acc
            x_new = x + dt * v_half
            force = element(x_new, v_half, t + dt)
            v_pred = v_half + 0.5 * dt * acc        # predictor for the damper
            acc = (sys.weight + sys.force_amp * math.sin(om * (t + dt))
                   - sys.k1 * x_new - sys.c * v_pred - force) / sys.m
            v = v_half + 0.5 * dt * acc
            x = x_new
            cur[j] = x
        if np.abs(cur - prev).max() <= rtol * np.ptp(cur):
            break
        prev, cur = cur, prev
    return cur.copy()
