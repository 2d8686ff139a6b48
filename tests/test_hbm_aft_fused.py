"""The compiled harmonic-form AFT (issue 27, item 3) gives the NumPy one's numbers.

:func:`hbm.aft._aft_harmonic_compiled` (the elastic remainders, the Jenkins march,
the tangent's sums and the slip memory in two numba calls) must equal the NumPy code
of :func:`hbm.aft._aft_harmonic` bit for bit: a round-off change of the Jacobian moves
the points of a continuation on the kinked residual of a sampled nonsmooth law. Also:
the NumPy scan march on arrays that are not C-ordered (the AFT's ``u[..., fr]``), and
the problem's memo of its last evaluation.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from drymount.hbm import aft
from drymount.hbm import friction_march as fm
from drymount.hbm.aft import FourierBasis
from drymount.hbm.elements import jenkins_periodic
from aft_axes import random_axes

pytest.importorskip("numba")


_axes = random_axes


def _both(U, ax, basis, monkeypatch):
    """(NumPy code with the compiled march, the compiled AFT: numba's kernels, not
    the C ones of tests/test_hbm_aft_native.py)."""
    monkeypatch.setattr(fm, "_DEFAULT", "numba")
    monkeypatch.setattr(fm, "C_IN_AUTO", False)
    plan = aft._plan(ax)
    aft._PLANS[ax] = dataclasses.replace(plan, codes=None)
    try:
        ref = aft._aft_harmonic(U, ax, basis)
    finally:
        aft._PLANS[ax] = plan
    assert plan.codes is not None
    return ref, aft._aft_harmonic(U, ax, basis)


@pytest.mark.parametrize("laws, kf", [
    (["piecewise", "piecewise", "piecewise"], [6e4, 0.0, 3e4]),
    (["cubic", "linear", "piecewise_asym", "piecewise"], [0.0, 6e4, 6e4, 1e5]),
    (["linear", "linear"], [6e4, 6e4]),
])
def test_compiled_aft_equals_numpy_bit_for_bit(laws, kf, monkeypatch):
    rng = np.random.default_rng(len(laws))
    ax = _axes(laws, kf, rng)
    basis = FourierBasis(7, 1024)
    m = basis.E.shape[1]
    decay = 1.0 / np.arange(1, m + 1)[:, None]
    for trial in range(12):
        U = 2e-3 * rng.uniform(0.1, 3) * rng.standard_normal((m, len(laws))) * decay
        if trial % 3 == 2:  # a batch of motions
            U = np.stack([U, 0.3 * U, 2.5 * U])
        (F1, d1), (F2, d2) = _both(U, ax, basis, monkeypatch)
        assert np.array_equal(F1, F2) and np.array_equal(d1, d2)


def test_compiled_aft_on_the_six_dof_preset(monkeypatch):
    from drymount.config.loading import load_preset
    from drymount.hbm.problem import build_problem

    prob = build_problem(load_preset("six_dof_halved").system, 2.0, 25.0, 7, 1024)
    hb = prob.hb
    X, _ = prob.x_of(prob.linear_guess(9.5, stuck=False))
    rng = np.random.default_rng(3)
    for scale in (0.5, 1.0, 3.0, 8.0):
        U = hb.axis_coefficients(X * scale * (1 + 0.2 * rng.standard_normal(X.size)))
        (F1, d1), (F2, d2) = _both(U, hb.axes, hb.basis, monkeypatch)
        assert np.array_equal(F1, F2) and np.array_equal(d1, d2)


def test_scan_march_of_a_non_c_ordered_motion_equals_the_scalar():
    # the case that found the bug: a column slipping at both extrema whose first
    # sample (its maximum, w = u_max - eps) sticks within round-off of Fs
    rng = np.random.default_rng(5)
    N = 64
    th = 2 * np.pi * np.arange(N) / N
    kf, fs = np.full(3, 6e4), np.array([20.0, 5.0, 250.0])
    for _ in range(40):
        U = rng.standard_normal((7, 3)) * 3e-3
        u = np.column_stack([sum(U[k, c] * np.cos(k * th + c) for k in range(7))
                             for c in range(3)])
        u_f = np.asfortranarray(u)
        got = fm._march(u_f[None], kf, fs, np.zeros(3))
        for c in range(3):
            ref = jenkins_periodic(u[:, c], kf[c], fs[c], 0.0)
            assert np.array_equal(got[0][0, :, c], ref.force)
            assert np.array_equal(got[1][0, :, c], ref.stuck)
            assert np.array_equal(got[2][0, :, c], ref.last_slip)


def test_problem_hands_out_its_last_evaluation_again():
    from drymount.config.loading import load_preset
    from drymount.hbm.problem import build_problem

    prob = build_problem(load_preset("quarter_car_halved").system, 2.0, 25.0, 5, 64)
    y = prob.linear_guess(8.0, stuck=False)
    R1, J1 = prob(y)
    R1[:] = 0.0  # the caller's arrays are its own
    J1[:] = 0.0
    R2, J2 = prob(y.copy())
    assert prob.n_eval == 1
    R3, J3 = prob._evaluate(y)
    assert np.array_equal(R2, R3) and np.array_equal(J2, J3)
    assert np.any(R2 != 0.0)
    prob.hb.exc_scale = 0.5  # load stepping changes the residual: evaluated anew
    try:
        R4, _ = prob(y)
    finally:
        prob.hb.exc_scale = 1.0
    assert prob.n_eval == 3 and not np.array_equal(R4, R2)
