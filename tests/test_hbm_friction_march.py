"""The vectorised Jenkins march (hbm.friction_march) equals the scalar march
(hbm.elements.jenkins_periodic: fmu_src.mount_law.jenkins_update per sample),
over samples, elements and batches; its Jacobian equals the per-sample reference of the
scalar AFT; the numba backend equals the NumPy one."""

import numpy as np
import pytest

import drymount.hbm.friction_march as fm
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.aft import FourierBasis, aft_forces
from drymount.hbm.elements import jenkins_periodic, nonlinear_axes
from drymount.hbm.friction_march import (BACKENDS, jenkins_jacobian, jenkins_march,
                                resolve_backend)
from drymount.hbm.systems import sdof

# Same operations on the same floats: measured 0.0 (bitwise); the bound is the brief's.
ATOL_FORCE = 1e-12  # N
ATOL_JAC = 1e-12  # relative to the largest Jacobian entry; measured 0.0

HAVE_NUMBA = fm._HAVE_NUMBA
backends = pytest.mark.parametrize("backend", [
    "scan", "numpy", pytest.param("numba", marks=pytest.mark.skipif(
        not HAVE_NUMBA, reason="numba not installed: pip install 'drymount[fast]'"))])


def _motions(rng, shape, N, regime):
    """Random periodic motions (..., N, C) with many reversals (up to 12 harmonics)."""
    th = 2 * np.pi * np.arange(N) / N
    u = np.zeros((*shape[:-1], N, shape[-1]))
    for idx in np.ndindex(*shape):
        *b, c = idx
        H = int(rng.integers(1, 13))
        k = np.arange(H + 1)[:, None]
        a = rng.normal(size=(H + 1, 1)) / (k + 1.0)
        col = (a * np.cos(k * th + rng.uniform(0, 2 * np.pi, (H + 1, 1)))).sum(0)
        col /= np.ptp(col)  # unit range
        scale = {"mixed": 10 ** rng.uniform(-5, -2.5), "slip": 1e-2,
                 "stick": 1e-5}[regime]
        u[(*b, slice(None), c)] = scale * col
    return u


def _reference(u, kf, fs, w0):
    """The scalar march of every column, stacked like ``u``."""
    out = [np.empty(u.shape), np.empty(u.shape, bool), np.empty(u.shape, int)]
    for idx in np.ndindex(*u.shape[:-2], u.shape[-1]):
        *b, c = idx
        sl = (*b, slice(None), c)
        res = jenkins_periodic(u[sl], float(kf[c]), float(fs[c]), float(w0[c]))
        for o, r in zip(out, res, strict=True):
            o[sl] = r
    return out


@backends
@pytest.mark.parametrize("regime", ["mixed", "slip", "stick"])
@pytest.mark.parametrize("shape,N", [((4,), 64), ((3, 5), 256), ((2, 2, 3), 100),
                                     ((1,), 1024)])
def test_march_equals_scalar_march(backend, regime, shape, N):
    rng = np.random.default_rng([N, ["mixed", "slip", "stick"].index(regime)])
    C = shape[-1]
    kf = rng.uniform(1e4, 1e5, C)
    fs = rng.uniform(1.0, 50.0, C)  # eps = fs/kf in 1e-5 ... 5e-3 m
    w0 = rng.uniform(-1, 1, C) * fs / kf
    for _ in range(5):
        u = _motions(rng, shape, N, regime)
        m = jenkins_march(u, kf, fs, w0, backend=backend)
        f_ref, stuck_ref, last_ref = _reference(u, kf, fs, w0)
        assert np.max(np.abs(m.force - f_ref)) <= ATOL_FORCE
        assert np.array_equal(m.stuck, stuck_ref)
        assert np.array_equal(m.last_slip, last_ref)
        if regime == "slip":
            assert not m.stuck.all()
        if regime == "stick":
            assert m.stuck.all()


@backends
def test_march_tie_at_the_slip_threshold_falls_back_to_the_scalar_march(backend):
    """A slip decision within round-off: the scan (w < u - eps) and the scalar map
    (kf (u - w) > Fs) disagree; the scan detects it and re-marches that column."""
    kf, fs = 60000.0, 20.0
    w0 = -0.0002439722018352235
    u0 = 8.936113149810985e-05  # u0 - eps > w0 but kf (u0 - w0) <= fs (found by search)
    assert (w0 < u0 - fs / kf) and not (kf * (u0 - w0) > fs)
    u = np.array([u0, 5e-5, 0.0, -5e-5, 0.0, 5e-5])[:, None]  # range < 2 eps: sticks
    m = jenkins_march(u, [kf], [fs], [w0], backend=backend)
    f_ref, stuck_ref, last_ref = _reference(u, [kf], [fs], [w0])
    assert np.array_equal(m.force, f_ref) and np.array_equal(m.stuck, stuck_ref)
    assert np.array_equal(m.last_slip, last_ref)
    assert m.n_fallback == (1 if backend == "scan" else 0)


def _jacobian_reference(u, kf, fs, E, P):
    """The per-sample Jacobian of the scalar AFT (one column)."""
    _, stuck, last = jenkins_periodic(u, kf, fs)
    dF = P @ (np.where(stuck, kf, 0.0)[:, None] * E)
    sel = np.flatnonzero(stuck & (last >= 0))
    return dF - kf * (P[:, sel] @ E[last[sel]])


@backends
def test_jacobian_equals_the_per_sample_reference(backend):
    rng = np.random.default_rng(7)
    b = FourierBasis(7, 128)
    kf, fs = np.array([6e4, 3e4, 8e4]), np.array([20.0, 5.0, 400.0])  # last: stuck
    U = rng.normal(size=(4, 15, 3)) * 1e-4 / np.r_[1, np.repeat(np.arange(1, 8), 2)][
        :, None]
    U[:, 2] += 1e-3
    m = jenkins_march(b.E @ U, kf, fs, backend=backend)
    dF = jenkins_jacobian(m, kf, b.E, b.P)
    assert dF.shape == (4, 3, 15, 15)
    for i in range(4):
        for c in range(3):
            ref = _jacobian_reference((b.E @ U[i])[:, c], kf[c], fs[c], b.E, b.P)
            assert np.max(np.abs(dF[i, c] - ref)) <= ATOL_JAC * np.abs(ref).max()


def test_aft_batch_equals_one_at_a_time():
    """aft_forces over a batch of frequency points = each point on its own."""
    p = AxisParameters(law="piecewise", delta=0.002, friction=True, n0=20.0)
    ax = nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 1.0))
    b = FourierBasis(5, 64)
    U = np.random.default_rng(3).normal(size=(6, 11, 1)) * 1e-3
    F, dF = aft_forces(U, ax, b)
    for i in range(6):
        Fi, dFi = aft_forces(U[i], ax, b)
        assert np.array_equal(F[i], Fi) and np.array_equal(dF[i], dFi)


def test_aft_of_an_axis_without_remainder_is_zero():
    """A linear axis without friction handed to the AFT (hbm.characterise does):
    zero forces and Jacobian, single and batched."""
    sysm = sdof(70.0, MountParameters(axial=AxisParameters(law="linear", friction=True,
                                                           n0=20.0)), "force", 1.0)
    ax = nonlinear_axes(sysm)
    ax0 = type(ax)(**{**{k: getattr(ax, k) for k in (
        "labels", "index", "B", "G", "law", "k1", "kc", "k2", "delta", "delta_neg",
        "fs", "w_start")}, "kf": np.zeros(1)})
    b = FourierBasis(3, 16)
    for U in (np.ones((7, 1)), np.ones((2, 7, 1))):
        F, dF = aft_forces(U, ax0, b)
        assert F.shape == U.shape and not F.any()
        assert dF.shape == (*U.shape[:-2], 1, 7, 7) and not dF.any()


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
def test_numba_backend_equals_numpy_backend_in_the_aft():
    rng = np.random.default_rng(11)
    b = FourierBasis(7, 64)
    u = b.E @ (rng.normal(size=(8, 15, 2)) * 1e-3)
    kf, fs = np.array([6e4, 6e4]), np.array([20.0, 60.0])
    m1 = jenkins_march(u, kf, fs, backend="scan")
    m2 = jenkins_march(u, kf, fs, backend="numba")
    assert np.array_equal(m1.force, m2.force)
    assert np.array_equal(jenkins_jacobian(m1, kf, b.E, b.P),
                          jenkins_jacobian(m2, kf, b.E, b.P))


def test_bad_input_names_the_field():
    with pytest.raises(ValueError, match="`kf` must be > 0"):
        jenkins_march(np.zeros((8, 1)), [0.0], [1.0])
    with pytest.raises(ValueError, match=r"shape \(2,\)"):
        jenkins_march(np.zeros((8, 2)), [1.0], [1.0])
    with pytest.raises(ValueError, match="must be one of auto, numpy, numba"):
        resolve_backend("fortran")
    assert set(BACKENDS) == {"numpy", "numba", "scan", "scalar", "c"}


def test_auto_is_numpy_without_numba(monkeypatch):
    """Without numba (the default install) ``auto`` takes the pure-NumPy march and
    asking for numba says how to get it."""
    import drymount.hbm.friction_march as fm

    monkeypatch.setattr(fm, "_HAVE_NUMBA", False)
    assert resolve_backend("auto") == "numpy"
    monkeypatch.setenv("DRYMOUNT_MARCH", "auto")
    assert resolve_backend() == "numpy"
    with pytest.raises(ValueError, match=r"needs numba: pip install 'drymount\[fast"):
        resolve_backend("numba")
