"""Stability along a traced branch: Hill's verdict (:func:`hbm.stability.hill_verdict`)
at a stride, at both ends and on both sides of every sign change of det J, and
between two evaluated points wherever their distance to the stability boundary is
small for their distance along the branch (the schedule of docs/performance.md)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drymount.hbm.continuation import Branch
from drymount.hbm.hill_arnoldi import lu_factors
from drymount.hbm.problem import _Problem
from drymount.hbm.stability import RTOL, hill_verdict, is_stable

#: Between two evaluated points a and b with the same verdict, the points between are
#: given that verdict only if the two margins ``|max Re - threshold| / omega`` add up
#: to at least MARGIN_SLOPE * (b - a); else the midpoint is evaluated (recursively).
#: The margin of the verdict changes by up to ~0.05 per point on the 6-DOF presets at
#: H = 7 (0.0003-0.0006 median), so this is a compromise: with it every point of
#: six_dof_halved and six_dof_lambda12 gets the verdict of evaluating every point,
#: six_dof_original all but 3 of 1208 (one-point islands; docs/performance.md).
MARGIN_SLOPE = 0.003


@dataclass
class Schedule:
    """Verdicts along a branch and where Hill's problem was solved.

    Attributes
    ----------
    stable : ndarray (npts,) bool
    max_real : ndarray (npts,)
        Largest real part of the Floquet exponents (1/s); NaN where not evaluated.
    evaluated : ndarray (npts,) bool
    """

    stable: np.ndarray
    max_real: np.ndarray
    evaluated: np.ndarray


def schedule_verdicts(det_sign: np.ndarray, evaluate: Callable[[int], tuple],
                      stride: int, slope: float = MARGIN_SLOPE) -> Schedule:
    """The verdicts of points ``0 .. len(det_sign) - 1`` of a branch.

    ``evaluate(i)`` returns ``(stable, max_real, margin)`` of point i (margin: the
    distance of the verdict's deciding real part to the threshold, relative to omega;
    NaN if unknown). It is called at every ``stride``-th point, at both ends, on both
    sides of every sign change of ``det_sign`` (a real Floquet exponent crosses zero
    there) and then, between two consecutive evaluated points a < b, at the midpoint
    while their verdicts differ (bisection of the change; a complex pair crossing
    leaves det J alone) or their margins add up to less than ``slope * (b - a)`` (a
    short island of the other verdict could fit between them). ``stride = 1``
    evaluates every point.
    """
    npts = len(det_sign)
    stable = np.ones(npts, dtype=bool)
    max_real = np.full(npts, np.nan)
    margin = np.zeros(npts)
    done = np.zeros(npts, dtype=bool)

    def visit(i):
        if not done[i]:
            stable[i], max_real[i], m = evaluate(i)
            margin[i] = m if np.isfinite(m) else 0.0
            done[i] = True

    key = set(range(0, npts, stride)) | {npts - 1} if npts else set()
    changes = np.nonzero(det_sign[1:] != det_sign[:-1])[0]
    key |= set(changes.tolist()) | set((changes + 1).tolist())
    keys = sorted(key)
    for i in keys:
        visit(i)
    stack = list(zip(keys[:-1], keys[1:], strict=True))
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        if stable[a] == stable[b] and margin[a] + margin[b] >= slope * (b - a):
            stable[a + 1:b] = stable[a]
            continue
        c = (a + b) // 2
        visit(c)
        stack += [(a, c), (c, b)]
    return Schedule(stable, max_real, done)


def _det_sign(J: np.ndarray) -> float:
    """Sign of det J (0 if singular, NaN if not finite) from its LU factors."""
    lu = lu_factors(J)
    if lu is None:
        return 0.0 if np.all(np.isfinite(J)) else np.nan
    lu_, piv = lu
    swaps = np.count_nonzero(piv != np.arange(len(piv)))
    return float((-1) ** swaps * np.prod(np.sign(np.diag(lu_))))


def _stability(prob: _Problem, ys, br: Branch, stride: int, dense: bool = False):
    """Hill stability along the branch: ``(stable, floquet_max_real)`` per point
    (:func:`schedule_verdicts`; ``floquet_max_real`` NaN where not evaluated).
    ``dense``: every eigenvalue by the dense problem (the reference,
    :func:`hbm.stability.is_stable`) instead of :func:`hbm.stability.hill_verdict`."""
    hb = prob.hb
    npts = len(ys)
    computed = {}

    def jac(i):
        """J and omega of point i (the Newton Jacobian where stored)."""
        X, w = prob.x_of(ys[i])
        if i < len(br.jacobian):
            return br.jacobian[i][:, :-1] * (prob.rs / prob.xs), w
        if i not in computed:
            computed[i] = hb.residual(X, w)[1]
        return computed[i], w

    # det J without the column scaling (a constant factor): recorded by the
    # continuation with each tangent, else from the LU of the stored or new Jacobian
    scale = float(np.prod(np.sign(prob.rs / prob.xs)))
    recorded = br.det_sign if len(br.det_sign) == len(br.jacobian) else []

    def det_sign(i):
        if i < len(recorded) and np.isfinite(recorded[i]):
            return recorded[i] * scale
        if i < len(br.jacobian):
            return _det_sign(br.jacobian[i][:, :-1]) * scale
        return _det_sign(jac(i)[0])

    sign = np.array([det_sign(i) for i in range(npts)])

    def evaluate(i):
        J, w = jac(i)
        try:
            v = is_stable(hb, J, w) if dense else hill_verdict(hb, J, w)
        except (np.linalg.LinAlgError, ValueError):
            return True, np.nan, np.nan
        return v.stable, v.max_real, abs(v.max_real - RTOL * w) / w

    s = schedule_verdicts(sign, evaluate, stride)
    return s.stable, s.max_real
