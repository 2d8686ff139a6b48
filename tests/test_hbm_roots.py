"""hbm.roots.brentq against scipy.optimize.brentq (the independent reference): the
same points visited in the same order and the same root, bit for bit, on smooth,
kinked, flat, noisy and exactly-zero functions; the errors it raises."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq

from drymount.hbm.roots import RootNotConverged, brentq


def _recorded(f):
    calls = []

    def g(x):
        calls.append(x)
        return f(x)
    return g, calls


def _cases():
    rng = np.random.default_rng(7)
    yield lambda x: x**3 - 2 * x - 5, 2.0, 3.0, 1e-12, 4 * np.finfo(float).eps
    yield math.cos, 0.0, 3.0, 1e-15, 1e-15
    yield lambda x: math.exp(x) - 10.0, -3.0, 5.0, 1e-9, 4 * np.finfo(float).eps
    yield lambda x: abs(x - 0.3) - 0.1, 0.0, 0.3, 1e-13, 1e-14       # a kink
    yield lambda x: (x - 0.7) ** 9, 0.0, 1.0, 1e-14, 4 * np.finfo(float).eps  # flat
    yield lambda x: 1.0 if x > 0.41 else -1.0, 0.0, 1.0, 1e-12, 1e-13  # a jump
    yield lambda x: 0.0 if abs(x) < 1e-3 else x, -1.0, 2.0, 1e-12, 1e-13
    for _ in range(40):   # kinked piecewise-linear functions with noise, as the
        # tangents of a sampled residual (hbm.folds) are
        knots = np.sort(rng.uniform(0, 1, 6))
        vals = np.sort(rng.normal(size=6))
        noise = 10.0 ** rng.uniform(-14, -8)
        root = float(rng.uniform(0.05, 0.95))
        c = rng.normal()

        def f(x, knots=knots, vals=vals, noise=noise, root=root, c=c):
            return (float(np.interp(x, knots, vals)) - float(np.interp(root, knots,
                                                                      vals))
                    + noise * math.sin(1e7 * x + c))
        yield f, 0.0, 1.0, float(10.0 ** rng.uniform(-12, -6)), 4 * np.finfo(float).eps


@pytest.mark.parametrize("case", list(_cases()))
def test_same_points_and_root_as_scipy(case):
    f, a, b, xtol, rtol = case
    g1, c1 = _recorded(f)
    g2, c2 = _recorded(f)
    try:
        ref = scipy_brentq(g1, a, b, xtol=xtol, rtol=rtol, maxiter=200)
    except ValueError:   # same signs at the ends: both must refuse
        with pytest.raises(ValueError):
            brentq(g2, a, b, xtol=xtol, rtol=rtol, maxiter=200)
        return
    got = brentq(g2, a, b, xtol=xtol, rtol=rtol, maxiter=200)
    assert c2 == c1          # every point, in order, bit for bit
    assert got == ref


def test_exact_zero_at_an_end_is_returned():
    assert brentq(lambda x: x - 1.0, 1.0, 2.0) == 1.0
    assert brentq(lambda x: x - 2.0, 1.0, 2.0) == 2.0


def test_errors_name_the_values():
    with pytest.raises(ValueError, match="signs must differ"):
        brentq(lambda x: x * x + 1, -1.0, 1.0)
    with pytest.raises(ValueError, match="xtol = 0"):
        brentq(lambda x: x, -1.0, 1.0, xtol=0)
    with pytest.raises(ValueError, match="rtol"):
        brentq(lambda x: x, -1.0, 1.0, rtol=1e-17)
    with pytest.raises(ValueError, match="NaN at x"):
        brentq(lambda x: math.nan if x > 0 else -1.0, -1.0, 1.0)
    with pytest.raises(RootNotConverged) as info:
        brentq(lambda x: 1.0 if x > 0.41 else -1.0, 0.0, 1.0, xtol=1e-15, maxiter=5)
    assert 0.0 <= info.value.x <= 1.0
    with pytest.raises(RuntimeError):   # as SciPy after as many iterations
        scipy_brentq(lambda x: 1.0 if x > 0.41 else -1.0, 0.0, 1.0, xtol=1e-15,
                     maxiter=5)
