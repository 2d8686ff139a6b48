"""The C kernels of the harmonic-form AFT (:mod:`hbm.aft_native`) give the numba
kernels' and the NumPy code's numbers bit for bit (issue 27, item 3).

Driven with the same random motions (several laws, stuck, slipping and partly
slipping columns, batches) and on the 6-DOF preset: every output of
:func:`hbm.aft_native.aft_samples` and :func:`hbm.aft_native.slip_memory` equals
:mod:`hbm.friction_march_numba`'s, and the AFT through them equals the NumPy AFT
(the reference march of :mod:`hbm.friction_march`) exactly. A round-off change of
the Jacobian would move the points of a continuation on the kinked residual of a
sampled nonsmooth law.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest

from drymount.hbm import aft, aft_native
from drymount.hbm import friction_march as fm
from drymount.hbm.aft import FourierBasis
from aft_axes import random_axes

if aft_native.library() is None:
    pytest.skip("no C compiler for hbm/aft_native.c", allow_module_level=True)


_axes = random_axes


CASES = [
    (["piecewise", "piecewise", "piecewise"], [6e4, 0.0, 3e4]),
    (["cubic", "linear", "piecewise_asym", "piecewise"], [0.0, 6e4, 6e4, 1e5]),
    (["linear", "linear"], [6e4, 6e4]),
]


def _motions(ax, basis, rng):
    m = basis.E.shape[1]
    decay = 1.0 / np.arange(1, m + 1)[:, None]
    for trial in range(12):
        # amplitudes from mostly stuck (0.1) to mostly slipping (3 x 2 mm)
        U = 2e-3 * rng.uniform(0.05, 3) * rng.standard_normal((m, ax.n)) * decay
        if trial % 3 == 2:  # a batch of motions
            U = np.stack([U, 0.3 * U, 2.5 * U])
        yield U


@pytest.mark.parametrize("laws, kf", CASES)
@pytest.mark.parametrize("N", [64, 1024])
def test_c_kernels_equal_numba_kernels_bit_for_bit(laws, kf, N):
    nb = pytest.importorskip("drymount.hbm.friction_march_numba")
    rng = np.random.default_rng(len(laws) + N)
    ax = _axes(laws, kf, rng)
    basis = FourierBasis(7, N)
    plan = aft._plan(ax)
    args = (*plan.codes, plan.friction_i8, plan.kf, plan.fs, plan.w_start)
    cum = basis.cumulative_projection()
    for U in _motions(ax, basis, rng):
        u = (basis.E @ U).reshape(-1, N, ax.n)
        for kernel in ("march", "march_and_samples"):
            more = (basis.E,) if kernel != "march" else ()
            fr = plan.friction_i8
            a = getattr(nb, kernel)(u[..., fr].copy(), plan.kf, plan.fs, plan.w_start,
                                    *more)
            b = getattr(aft_native, kernel)(u[..., fr], plan.kf, plan.fs,
                                            plan.w_start, *more)
            assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
        ref, got = nb.aft_samples(u, *args), aft_native.aft_samples(u, *args)
        for a, b in zip(ref, got, strict=True):
            assert a.dtype == b.dtype and np.array_equal(a, b)
        dF = basis.gram(ref[1])
        d1, d2 = dF.copy(), dF.copy()
        nb.slip_memory(d1, ref[2], ref[3], plan.friction_i8, plan.kf, cum, basis.E)
        aft_native.slip_memory(d2, got[2], got[3], plan.friction_i8, plan.kf, cum,
                               basis.E)
        assert np.array_equal(d1, d2)
        assert not np.array_equal(d1, dF) or not np.any(ref[2] & (ref[3] >= 0))


def _numpy_and_c(U, ax, basis, monkeypatch):
    """The AFT by the NumPy code (its reference march) and through the C kernels."""
    monkeypatch.setattr(fm, "_DEFAULT", "numpy")
    plan = aft._plan(ax)
    monkeypatch.setattr(fm, "C_IN_AUTO", False)
    aft._PLANS[ax] = dataclasses.replace(plan, codes=None)
    try:
        ref = aft._aft_harmonic(U, ax, basis), aft._aft_dense(U, ax, basis, True)
    finally:
        aft._PLANS[ax] = plan
    monkeypatch.setattr(fm, "C_IN_AUTO", True)
    assert fm._chosen(None) == "c"
    got = aft._aft_harmonic(U, ax, basis), aft._aft_dense(U, ax, basis, True)
    # a law without a compiled form (plan.codes None): the march still in C
    aft._PLANS[ax] = dataclasses.replace(plan, codes=None)
    try:
        no_codes = aft._aft_dense(U, ax, basis, True)
    finally:
        aft._PLANS[ax] = plan
    assert all(np.array_equal(a, b) for a, b in zip(ref[1], no_codes, strict=True))
    return ref, got


@pytest.mark.parametrize("laws, kf", CASES)
def test_native_aft_equals_numpy_aft_bit_for_bit(laws, kf, monkeypatch):
    rng = np.random.default_rng(7 * len(laws))
    ax = _axes(laws, kf, rng)
    for N in (64, 1024):
        basis = FourierBasis(7, N)
        for U in _motions(ax, basis, rng):
            ref, got = _numpy_and_c(U, ax, basis, monkeypatch)
            for (F1, d1), (F2, d2) in zip(ref, got, strict=True):
                assert np.array_equal(F1, F2) and np.array_equal(d1, d2)


def test_native_aft_on_the_six_dof_preset(monkeypatch):
    from drymount.config.loading import load_preset
    from drymount.hbm.problem import build_problem

    prob = build_problem(load_preset("six_dof_halved").system, 2.0, 25.0, 7, 1024)
    hb = prob.hb
    X, _ = prob.x_of(prob.linear_guess(9.5, stuck=False))
    rng = np.random.default_rng(3)
    for scale in (0.5, 1.0, 3.0, 8.0):
        U = hb.axis_coefficients(X * scale * (1 + 0.2 * rng.standard_normal(X.size)))
        ref, got = _numpy_and_c(U, hb.axes, hb.basis, monkeypatch)
        for (F1, d1), (F2, d2) in zip(ref, got, strict=True):
            assert np.array_equal(F1, F2) and np.array_equal(d1, d2)


def test_c_march_equals_the_scalar_march():
    from drymount.hbm.elements import jenkins_periodic

    rng = np.random.default_rng(11)
    N = 128
    th = 2 * np.pi * np.arange(N) / N
    kf, fs = np.array([6e4, 3e4, 1e5]), np.array([20.0, 5.0, 250.0])
    for _ in range(30):
        U = rng.standard_normal((7, 3)) * 3e-3 * rng.uniform(0.02, 2)
        u = np.column_stack([sum(U[k, c] * np.cos(k * th + c) for k in range(7))
                             for c in range(3)])
        w0 = rng.uniform(-1e-4, 1e-4, 3)
        got = fm.jenkins_march(np.asfortranarray(u), kf, fs, w0, backend="c")
        assert got.backend == "c"
        for c in range(3):
            ref = jenkins_periodic(u[:, c], kf[c], fs[c], w0[c])
            assert np.array_equal(got.force[:, c], ref.force)
            assert np.array_equal(got.stuck[:, c], ref.stuck)
            assert np.array_equal(got.last_slip[:, c], ref.last_slip)


def test_bad_arguments_are_refused_before_c_sees_them():
    u = np.zeros((1, 8, 2))
    i2, d2 = np.zeros(2, np.int64), np.zeros(2)
    with pytest.raises(ValueError, match="do not fit 2 axes"):
        aft_native.aft_samples(u, i2, d2, d2, d2, np.array([2]), d2[:1], d2[:1],
                               d2[:1])
    with pytest.raises(ValueError, match="inconsistent shapes"):
        aft_native.slip_memory(np.zeros((1, 2, 3, 3)), np.zeros((1, 8, 1), bool),
                               np.zeros((1, 8, 1), np.int64), np.array([0]),
                               np.ones(1), np.zeros((8, 3)), np.zeros((8, 3)))


def test_cache_folder_is_the_native_cache(monkeypatch, tmp_path):
    from drymount.fmu_build.native import cache_folder
    from drymount.hbm.c_build import cache_folder as light

    for env in ({"DRYMOUNT_NATIVE_CACHE": str(tmp_path)}, {"DRYMOUNT_NATIVE_CACHE": ""},
                {"XDG_CACHE_HOME": str(tmp_path / "x")}, {}):
        for k in ("DRYMOUNT_NATIVE_CACHE", "XDG_CACHE_HOME"):
            monkeypatch.delenv(k, raising=False)
        for k, v in env.items():
            monkeypatch.setenv(k, v)
        assert light() == cache_folder()


def test_switched_off_by_the_environment(monkeypatch):
    monkeypatch.setenv("DRYMOUNT_NATIVE_AFT", "0")
    aft_native.library.cache_clear()
    try:
        assert aft_native.library() is None
    finally:
        monkeypatch.delenv("DRYMOUNT_NATIVE_AFT")
        aft_native.library.cache_clear()
    assert aft_native.library() is not None
    assert Path(os.fspath(aft_native.SOURCE)).is_file()
