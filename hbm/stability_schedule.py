"""Stability along a traced branch: Hill's eigenvalues (:func:`hbm.stability.is_stable`)
at a stride, at both ends and around every sign change of det J, with bisection
where the verdict changes (the schedule of docs/performance.md)."""

from __future__ import annotations

import numpy as np

from hbm.continuation import Branch
from hbm.problem import _Problem
from hbm.stability import is_stable


def _stability(prob: _Problem, ys, br: Branch, stride: int):
    """Hill stability along the branch.

    The eigenvalue problem is solved at every ``stride``-th point, at both ends and
    on both sides of every sign change of ``det J`` (folds, branch points: a real
    Floquet exponent crosses zero there); where two of these points have different
    verdicts, also at every ``stride // 4``-th point of that interval and of its
    two neighbours (changes cluster). Between two evaluated points with the same
    verdict, and no sign change of ``det J``, the verdict is carried over; where the
    verdicts differ the change is located by bisection (a complex pair crossing,
    which leaves ``det J`` alone); where ``det J`` changes sign every point between
    them is evaluated. ``stride = 1`` evaluates every point.
    """
    hb = prob.hb
    npts = len(ys)
    stable = np.ones(npts, dtype=bool)
    fmr = np.full(npts, np.nan)
    jac = []
    sign = np.empty(npts)
    for i, y in enumerate(ys):
        X, w = prob.x_of(y)
        if i < len(br.jacobian):
            J = br.jacobian[i][:, :-1] * (prob.rs / prob.xs)
        else:
            J = hb.residual(X, w)[1]
        jac.append((J, w))
        sign[i] = np.linalg.slogdet(J)[0]
    done = np.zeros(npts, dtype=bool)

    def evaluate(i):
        if not done[i]:
            J, w = jac[i]
            try:
                stable[i], fmr[i] = is_stable(hb, J, w)
            except (np.linalg.LinAlgError, ValueError):
                stable[i], fmr[i] = True, np.nan
            done[i] = True

    def bisect(a, b):
        """Verdicts at a < b known, det J of one sign on [a, b]."""
        while b - a >= 2:
            if stable[a] == stable[b]:
                stable[a + 1:b] = stable[a]
                return
            c = (a + b) // 2
            evaluate(c)
            bisect(a, c)
            a = c

    key = set(range(0, npts, stride)) | {npts - 1}
    for i in range(1, npts):
        if sign[i] != sign[i - 1]:
            key |= {i - 1, i}
    for i in sorted(key):
        evaluate(i)
    keys = sorted(key)
    fine = max(1, stride // 4)
    if fine < stride:
        # near a change of verdict (in that interval and its neighbours) changes
        # cluster (short islands of instability): evaluate every `fine`-th point there
        extra = set()
        for k in range(len(keys) - 1):
            if stable[keys[k]] != stable[keys[k + 1]]:
                for kk in range(max(0, k - 1), min(len(keys) - 1, k + 2)):
                    extra |= set(range(keys[kk], keys[kk + 1], fine))
        for i in sorted(extra):
            evaluate(i)
        keys = sorted(key | extra)
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        if np.all(sign[a:b + 1] == sign[a]):
            bisect(a, b)
        else:
            for i in range(a + 1, b):
                evaluate(i)
    return stable, fmr


