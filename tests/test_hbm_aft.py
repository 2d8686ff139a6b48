"""AFT evaluation and the harmonic-balance residual: analytic Jacobians vs finite
differences, and the Fourier basis."""

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.aft import FourierBasis, aft_forces, default_n_samples
from drymount.hbm.elements import nonlinear_axes
from drymount.hbm.residual import HarmonicBalance
from drymount.hbm.systems import quarter_car, rigid_engine, sdof

# Analytic vs central differences. The laws are piecewise smooth; with generic
# coefficients no sample sits on a kink, so the only error is the FD truncation and
# round-off: measured <= 6e-10 of the Jacobian's largest entry.
RTOL_FD = 1e-6


def test_fourier_basis_projection_and_derivative():
    b = FourierBasis(5, 32)
    np.testing.assert_allclose(b.P @ b.E, np.eye(11), atol=1e-14)
    U = np.random.default_rng(0).normal(size=11)
    th = 2 * np.pi * np.arange(32) / 32
    # E D U is d/dtheta of E U: compare with the analytic series derivative
    k = np.arange(1, 6)
    du = ((-np.sin(np.outer(th, k)) * k) @ U[1::2]
          + (np.cos(np.outer(th, k)) * k) @ U[2::2])
    np.testing.assert_allclose(b.E @ b.D @ U, du, atol=1e-12)
    assert default_n_samples(1) == 64 and default_n_samples(7) == 64
    assert default_n_samples(9) == 128 and default_n_samples(15) == 128
    with pytest.raises(ValueError, match="n_samples"):
        FourierBasis(5, 10)


LAWS = [
    AxisParameters(law="cubic", k1=34770.0, kc=5.708e8),
    AxisParameters(law="piecewise", delta=0.002),
    AxisParameters(law="piecewise_asym", delta=0.002, delta_neg=0.001),
    AxisParameters(law="linear", friction=True, n0=20.0),
    AxisParameters(law="piecewise", delta=0.002, friction=True, n0=20.0),
    AxisParameters(law="piecewise", delta=0.002, friction=True, n0=200.0),  # stuck
    # micro-slip (7 sliders, some stuck) and non-symmetric friction
    AxisParameters(law="linear", friction=True, n0=60.0, sliders=7, spread=0.7),
    AxisParameters(law="linear", friction=True, n0=20.0, fs_ratio=0.4),
    AxisParameters(law="piecewise", delta=0.002, friction=True, n0=60.0, sliders=5,
                   spread=0.5, fs_ratio=1.8),
]


@pytest.mark.parametrize("p", LAWS, ids=lambda p: f"{p.law}-fr{p.friction}-{p.n0}"
                         f"-s{p.sliders}-r{p.fs_ratio}")
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_aft_jacobian_vs_fd(p, seed):
    ax = nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 1.0))
    H = 5
    b = FourierBasis(H, 64)
    rng = np.random.default_rng(seed)
    U = rng.normal(size=(2 * H + 1, 1)) * 1e-3 / np.r_[1, np.repeat(np.arange(1, H + 1),
                                                                     2)][:, None]
    U[2] += 3e-3
    F, dF = aft_forces(U, ax, b)
    scale = np.abs(dF).max()
    for g in range(2 * H + 1):
        h = 1e-9
        Up, Um = U.copy(), U.copy()
        Up[g] += h
        Um[g] -= h
        fd = (aft_forces(Up, ax, b, False)[0]
              - aft_forces(Um, ax, b, False)[0]) / (2 * h)
        np.testing.assert_allclose(dF[0, :, g], fd[:, 0], rtol=0, atol=RTOL_FD * scale)


def _systems():
    fr = AxisParameters(law="piecewise", delta=0.002, friction=True, n0=30.0)
    cub = AxisParameters(law="cubic", kc=5e8, friction=True, n0=30.0)
    mps = [MountParameters.from_axial(fr, 1.2, (a,)) for a in ("radial1", "radial2")]
    mps.append(MountParameters.from_axial(cub, 1.0, ("axial",)))
    return {
        "sdof-unbalance": sdof(70.0, MountParameters(axial=fr), "unbalance", 0.01),
        "sdof-base": sdof(70.0, MountParameters(axial=cub), "base", 0.003),
        "quarter_car": quarter_car(70, 230, 30, 15000, 1000, 200000, 50.0,
                                   MountParameters(axial=fr), road_amplitude=0.01),
        "rigid_engine": rigid_engine(140.8, [8.63, 10.02, 10.22],
                                     [(-0.5, 0.25, 0), (0.5, 0.25, 0),
                                      (0, -0.25, -0.5)],
                                     mps, amplitude=(0.001, 0.0, 0.0035)),
    }


@pytest.mark.parametrize("name", ["sdof-unbalance", "sdof-base", "quarter_car",
                                  "rigid_engine"])
@pytest.mark.parametrize("H", [1, 3])
def test_residual_jacobian_vs_fd(name, H):
    system = _systems()[name]
    for closed in ([False, True] if H == 1 else [False]):
        if closed and system.name == "rigid_engine":
            closed = None
        hb = HarmonicBalance(system, H, 64, closed_form=closed)
        rng = np.random.default_rng(7)
        X = rng.normal(size=hb.size) * 2e-3
        w = 2 * np.pi * 7.3
        R, J, Jw = hb.residual(X, w)
        scale = np.abs(J).max()
        h = 1e-9
        for i in range(hb.size):
            Xp, Xm = X.copy(), X.copy()
            Xp[i] += h
            Xm[i] -= h
            fd = (hb.residual(Xp, w, False)[0] - hb.residual(Xm, w, False)[0]) / (2 * h)
            np.testing.assert_allclose(J[:, i], fd, rtol=0, atol=RTOL_FD * scale)
        hw = 1e-5
        fdw = (hb.residual(X, w + hw, False)[0] - hb.residual(X, w - hw, False)[0]) / (
            2 * hw)
        np.testing.assert_allclose(Jw, fdw, rtol=0,
                                   atol=RTOL_FD * max(np.abs(Jw).max(), 1.0))
