"""Fold and peak bisection (``hbm.folds._bisect``) at a jump of the sampled residual.

A sign change of the tangent's component can be a root of a smooth function or a
jump (a stick-slip transition crossing an AFT sample point). At a root the Brent
iteration runs to ``ARC_TOL`` as before (the same points, the same result); at a
jump it stops once the bracket is within ``JUMP_TOL`` of the chord, with the end of
smaller ``|g|``, instead of bisecting a step to ``ARC_TOL`` (re-solves fewer).
"""

from __future__ import annotations

import math

import pytest

from drymount.hbm import folds
from drymount.hbm.roots import brentq


class _FakeArc:
    """The part of ``folds._Arc`` that ``_bisect`` uses: ``h`` and ``point(s)``,
    here ``(s, None)`` so that ``g`` sees the chord parameter."""

    def __init__(self, h: float):
        self.h = h
        self.solved = []

    def point(self, s: float):
        self.solved.append(s)
        return s, None


H = 0.0937
S0 = 0.41 * H / math.sqrt(2)


def _step(s, _t):
    return 9.3e-6 if s < S0 else -1.1e-4  # values measured at six_dof_halved's fold


def _smooth(s, _t):
    return math.sin(3.0 * (S0 - s)) + 0.2 * (S0 - s) ** 2


def _steep_root(s, _t):  # continuous, root at S0, slope 1e3 times its mean
    return math.atan(1e3 * (S0 - s) / H)


def test_a_jump_stops_at_jump_tol_with_the_better_end():
    arc = _FakeArc(H)
    s, ok = folds._bisect(arc, _step, None, folds.ARC_TOL * H)
    assert ok
    assert abs(s - S0) <= folds.JUMP_TOL * H
    assert s < S0  # the side of the smaller |g|
    plain = []
    brentq(lambda x: plain.append(x) or _step(x, None), 0.0, H,
           xtol=folds.ARC_TOL * H, rtol=4 * 2.220446049250313e-16, maxiter=200)
    assert len(set(arc.solved)) <= len(plain) - 5, (len(arc.solved), len(plain))


@pytest.mark.parametrize("g", [_smooth, _steep_root])
def test_a_root_is_located_exactly_as_before(g):
    arc = _FakeArc(H)
    s, ok = folds._bisect(arc, g, None, folds.ARC_TOL * H)
    ref = brentq(lambda x: g(x, None), 0.0, H, xtol=folds.ARC_TOL * H,
                 rtol=4 * 2.220446049250313e-16, maxiter=200)
    assert ok and s == ref
    assert abs(s - S0) <= 2 * folds.ARC_TOL * H
