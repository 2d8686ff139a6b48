"""Newton without the Jacobian at its root (issue 27 item 3: the error estimate's
re-solves): ``jacobian_at_root=False`` gives the same iterates and root bit for bit
and makes one Jacobian fewer per converged solve; the residual without its
Jacobian is the residual with it."""

import dataclasses

import numpy as np
import pytest

from drymount.config.loading import load_preset
from drymount.hbm.continuation import newton
from drymount.hbm.options import HBMOptions
from drymount.hbm.problem import build_problem


class _Counted:
    """A problem counting its full (R, J) and residual-only evaluations."""

    def __init__(self, prob):
        self.prob, self.full, self.r_only = prob, 0, 0

    def __call__(self, y):
        self.full += 1
        return self.prob(y)

    def residual_only(self, y):
        self.r_only += 1
        return self.prob.residual_only(y)


@pytest.mark.parametrize("name, H, N", [("six_dof_halved", 5, 128),
                                        ("six_dof_halved", 13, 1024),
                                        ("sdof_microslip", 7, 256),
                                        ("quarter_car_inclined", 7, 128)])
def test_root_only_newton_is_the_same_newton(name, H, N):
    rng = np.random.default_rng(11)
    settings = dataclasses.replace(HBMOptions().continuation_settings(), max_newton=20)
    saved = 0
    for f in (4.0, 6.5, 11.0):
        prob = build_problem(load_preset(name).system, 2.0, 25.0, H, N)
        y0 = prob.linear_guess(f, stuck=False)
        y_ref, ok, _, _ = newton(prob, y0, settings, fixed=prob.hb.size)
        assert ok
        for _ in range(2):
            start = y_ref * (1.0 + 1e-3 * rng.standard_normal(y_ref.size))
            t = rng.standard_normal(y_ref.size)
            t /= np.linalg.norm(t)
            out = []
            for at_root in (True, False):
                fun = _Counted(build_problem(load_preset(name).system, 2.0, 25.0, H, N))
                res = newton(fun, start, settings, tangent=t, y_pred=start,
                             jacobian_at_root=at_root)
                out.append((res, fun.full, fun.r_only))
            (a, full_a, r_a), (b, full_b, r_b) = out
            assert a.converged == b.converged and a.n_iter == b.n_iter
            assert np.array_equal(a.y, b.y) and a.message == b.message
            assert r_a == 0
            if a.converged:   # the root's Jacobian is not made
                assert full_b <= full_a - 1 and full_b + r_b >= full_a
                saved += full_a - full_b
    assert saved >= 3


@pytest.mark.parametrize("name", ["six_dof_halved", "sdof_microslip", "sdof_maxwell",
                                  "sdof_hydraulic", "quarter_car_inclined"])
def test_residual_only_is_the_residual(name):
    prob = build_problem(load_preset(name).system, 2.0, 25.0, 7, 512)
    rng = np.random.default_rng(2)
    y = prob.linear_guess(7.0, stuck=False)
    for _ in range(3):
        yk = y * (1.0 + 0.05 * rng.standard_normal(y.size))
        R_only = prob.residual_only(yk)
        R, _ = build_problem(load_preset(name).system, 2.0, 25.0, 7, 512)(yk)
        assert np.array_equal(R_only, R)
