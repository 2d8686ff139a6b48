"""Bracketed scalar roots by Brent's method, without importing ``scipy.optimize``.

``scipy.optimize`` costs about 0.15 s to import (it pulls in ``scipy.fft``,
``scipy.special`` and the linear-programming modules), which every HBM curve paid
for one function: the fold and peak location of :mod:`hbm.folds`. :func:`brentq`
here is Brent's (1973) method in the form of ``scipy.optimize.brentq`` (inverse
quadratic or secant step when it is short enough, else bisection; the tolerance
``xtol + rtol |x|``), with the same arithmetic in the same order, so it visits the
same points and returns the same root bit for bit (``tests/test_hbm_roots.py``
checks it against SciPy on smooth, kinked and flat functions).
"""

from __future__ import annotations

import math
from collections.abc import Callable

__all__ = ["brentq", "RootNotConverged"]

_EPS = 2.220446049250313e-16


class RootNotConverged(RuntimeError):
    """The bracket did not shrink to the tolerance within ``maxiter`` iterations
    (``x`` the last iterate)."""

    def __init__(self, message: str, x: float):
        super().__init__(message)
        self.x = x


def _check(xtol: float, rtol: float, maxiter: int) -> None:
    if not xtol > 0:
        raise ValueError(f"xtol = {xtol!r}: must be > 0")
    if not rtol >= 4 * _EPS:
        raise ValueError(f"rtol = {rtol!r}: must be >= 4 eps = {4 * _EPS:.3g}")
    if maxiter < 0:
        raise ValueError(f"maxiter = {maxiter!r}: must be >= 0")


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = 2e-12,
           rtol: float = 4 * _EPS, maxiter: int = 100) -> float:
    """A root of ``f`` in ``[a, b]`` where ``f(a)`` and ``f(b)`` differ in sign.

    Returns ``x`` with the root within ``xtol + rtol |x|`` (about 2x that; an end
    where ``f`` is exactly 0 is returned as is). Raises ``ValueError`` if the signs
    are the same (or a tolerance is invalid) and :class:`RootNotConverged` after
    ``maxiter`` iterations. Exceptions raised by ``f`` propagate.
    """
    xtol, rtol = float(xtol), float(rtol)
    _check(xtol, rtol, maxiter)
    f = _finite(f)
    xpre, xcur = float(a), float(b)
    fpre, fcur = f(xpre), f(xcur)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError(f"f(a) = {fpre!r} and f(b) = {fcur!r} at a = {a!r}, "
                         f"b = {b!r}: the signs must differ")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and \
                math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        spre, scur = _step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, sbis,
                           delta)
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = f(xcur)
    raise RootNotConverged(f"no convergence in {maxiter} iterations (bracket "
                           f"[{min(xcur, xblk)!r}, {max(xcur, xblk)!r}])", xcur)


def _finite(f: Callable[[float], float]) -> Callable[[float], float]:
    """``f`` as a float, a NaN refused (``ValueError``, as SciPy's wrapper does)."""
    def g(x: float) -> float:
        v = float(f(x))
        if math.isnan(v):
            raise ValueError(f"the function is NaN at x = {x!r}")
        return v
    return g


def _step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, sbis, delta):
    """The next ``(spre, scur)``: interpolation (secant when only two distinct
    points are known, else inverse quadratic) if it is short enough, else
    bisection."""
    if abs(spre) > delta and abs(fcur) < abs(fpre):
        try:
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre
                                                              * (fblk - fpre))
        except ZeroDivisionError:   # IEEE: an infinite or NaN step, never taken
            return sbis, sbis
        if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
            return scur, stry
    return sbis, sbis
