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


def _same_bits(a, b):
    """Equal values, NaN where NaN, and the same sign on every zero."""
    return (np.array_equal(a, b, equal_nan=True)
            and np.array_equal(np.signbit(a), np.signbit(b)))


@pytest.mark.parametrize("name, H", [("six_dof_halved", 13), ("six_dof_halved", 5),
                                     ("six_dof_hydraulic", 7),
                                     ("quarter_car_halved", 13)])
def test_linear_matrices_on_their_pattern_equal_the_dense_sums(name, H):
    """The linear matrix and d/domega summed on the entries A0, A1, A2 fill
    (hbm.residual._linear_pattern) are the dense sums bit for bit, signed zeros
    included, for the omegas of a curve and the odd ones (negative, -0, NaN, inf,
    huge: the dense sums there)."""
    hb = build_problem(load_preset(name).system, 2.0, 25.0, H, 8 * H + 8).hb
    assert hb._nz is not None and hb._nz.size < 0.2 * hb.size ** 2
    with np.errstate(invalid="ignore", over="ignore"):
        for w in (0.0, -0.0, 1e-300, 12.566, 2 * np.pi * 9.1, 157.0, -12.5,
                  1e200, np.inf, -np.inf, np.nan):
            dense = hb.A0 + w * hb.A1 + (w * w) * hb.A2
            assert _same_bits(hb.linear_matrix(w), dense), w
            assert _same_bits(hb._omega_matrix(w), hb.A1 + (2.0 * w) * hb.A2), w


def test_small_systems_keep_the_dense_sums():
    hb = build_problem(load_preset("sdof_halved").system, 2.0, 25.0, 7, 64).hb
    assert hb._nz is None
    w = 30.0
    assert _same_bits(hb.linear_matrix(w), hb.A0 + w * hb.A1 + (w * w) * hb.A2)
