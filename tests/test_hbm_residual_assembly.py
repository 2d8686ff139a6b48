"""The Jacobian assembly of hbm.residual (issue 27 item 3: its Python removed): the
nonlinear axes' part ``J[h i, g j] += sum_a dF[a, h, g] B[a, i] B[a, j]`` equals the
former ``A + np.tensordot(dF, BB, axes=(0, 0))`` assembly bit for bit."""

import numpy as np
import pytest

from drymount.config.loading import load_preset
from drymount.hbm.problem import build_problem


@pytest.mark.parametrize("name, H, N", [("six_dof_halved", 7, 1024),
                                        ("six_dof_halved", 5, 64),
                                        ("quarter_car_halved", 7, 256)])
def test_assembly_equals_tensordot(name, H, N):
    prob = build_problem(load_preset(name).system, 2.0, 25.0, H, N)
    hb = prob.hb
    X, w = prob.x_of(prob.linear_guess(9.5, stuck=False))
    rng = np.random.default_rng(3)
    for _ in range(4):
        Xk = X * (1.0 + 0.3 * rng.standard_normal(X.size))
        J = hb.residual(Xk, w).dR_dX
        _, dF = hb.nonlinear_forces(Xk, True, w)
        ref = hb.linear_matrix(w) + np.tensordot(dF, hb.BB, axes=(0, 0)).transpose(
            0, 2, 1, 3).reshape(hb.size, hb.size)
        assert np.array_equal(J, ref)
