"""Closed-form H = 1 coefficients vs numerical Fourier integrals of the exact law.

The thesis's printed forms are wrong for the gap spring (eq. 3.32, pi times too large)
and the Jenkins sine coefficient (eq. 3.46, wrong sign): PHYSICS.md section 6. The
corrected forms of hbm/closed_form.py must match ``scipy.integrate.quad`` (with the
kinks as breakpoints) of the exact law of fmu_src/mount_law.py.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from drymount.fmu_src.mount_law import (AxisParameters, MountParameters, elastic_force,
                               jenkins_update)
from drymount.hbm.aft import FourierBasis, aft_forces
from drymount.hbm.closed_form import (closed_form_forces, cubic_coefficients,
                                      gap_coefficients, jenkins_coefficients)
from drymount.hbm.elements import nonlinear_axes
from drymount.hbm.systems import sdof

RTOL_QUAD = 1e-9   # closed form vs quad: the requirement; measured <= 2.2e-13
RTOL_FD = 1e-6     # analytic vs central differences: measured <= 3.3e-9
RTOL_AFT = 1e-6    # closed form vs AFT with N = 2**14 (kinks: O(N^-2)); measured 4e-8

KF, FS = 60000.0, 20.0
K1, K2, DELTA = 91870.0, 513800.0, 0.01225
KC = 5.708e8


def _fourier(F, points, period_start=0.0, scale=1.0):
    """(F_s, F_c) = (1/pi) int F(theta) (sin, cos) over one period.

    ``scale``: force magnitude, sets the absolute quadrature tolerance (1e-13 of it).
    """
    a, b = period_start, period_start + 2 * np.pi
    kw = dict(points=points, limit=200, epsabs=1e-13 * scale, epsrel=1e-12)
    fs_ = quad(lambda th: F(th) * math.sin(th), a, b, **kw)[0] / np.pi
    fc_ = quad(lambda th: F(th) * math.cos(th), a, b, **kw)[0] / np.pi
    return fs_, fc_


def _jenkins_exact(X):
    """Exact steady loop for u = X sin(theta): from theta = pi/2 the slider sits at
    X - eps (it slipped up to the maximum) and u decreases monotonically until
    3 pi/2, where it sits at -X + eps; the return map is exact for monotonic u."""
    eps = FS / KF

    def F(th):
        u = X * math.sin(th)
        w = X - eps if th < 1.5 * np.pi else -X + eps
        return jenkins_update(u, w, KF, FS)[0]

    a = math.asin(1 - 2 * eps / X)
    return _fourier(F, [np.pi - a, 1.5 * np.pi, 2 * np.pi - a], period_start=np.pi / 2,
                    scale=FS)


@pytest.mark.parametrize("X", [2e-4, 5e-4, 1e-3, 3e-3, 2e-2])
def test_jenkins_closed_form_vs_quad(X):
    F_s, F_c, _, _ = jenkins_coefficients(X, KF, FS)
    if KF * X > FS:
        ref_s, ref_c = _jenkins_exact(X)
    else:
        ref_s, ref_c = KF * X, 0.0  # never slips: F = kf u
    assert F_s == pytest.approx(ref_s, rel=RTOL_QUAD)
    assert F_c == pytest.approx(ref_c, rel=RTOL_QUAD, abs=RTOL_QUAD * FS)
    # eq. 3.47 compact form, and the energy 4 Fs (X - eps) = pi X F_c
    if KF * X > FS:
        assert math.pi * X * F_c == pytest.approx(4 * FS * (X - FS / KF), rel=1e-13)


def test_jenkins_printed_sine_coefficient_has_wrong_sign():
    X = 1e-3
    F_s, _, _, _ = jenkins_coefficients(X, KF, FS)
    a2 = math.asin(1 - 2 * FS / (KF * X))
    printed = -(KF * X / math.pi) * (math.pi / 2 - a2 - math.sin(a2) * math.cos(a2))
    ref_s, _ = _jenkins_exact(X)
    assert printed == pytest.approx(-ref_s, rel=1e-9)
    assert F_s == pytest.approx(ref_s, rel=RTOL_QUAD)


@pytest.mark.parametrize("X", [0.005, 0.0123, 0.015, 0.03, 0.1])
def test_gap_closed_form_vs_quad(X):
    F_s, F_c, _, _ = gap_coefficients(X, K2 - K1, DELTA)

    law = AxisParameters(law="piecewise", k1=K1, k2=K2, delta=DELTA)

    def F(th):
        u = X * math.sin(th)
        return elastic_force(u, law)[0] - K1 * u

    pts = []
    if X > DELTA:
        a1 = math.asin(DELTA / X)
        pts = [a1, np.pi - a1, np.pi + a1, 2 * np.pi - a1]
    scale = (K2 - K1) * X
    ref_s, ref_c = _fourier(F, pts or None, scale=scale)
    assert F_s == pytest.approx(ref_s, rel=RTOL_QUAD, abs=RTOL_QUAD * scale * 1e-3)
    assert abs(F_c - ref_c) <= RTOL_QUAD * scale
    if X > DELTA:  # the printed eq. 3.32 is pi times the right value
        a1 = math.asin(DELTA / X)
        printed = (K2 - K1) * (X * math.sin(2 * a1) + math.pi * X
                               - 4 * DELTA * math.cos(a1) - 2 * X * a1)
        assert printed == pytest.approx(math.pi * ref_s, rel=1e-9)


@pytest.mark.parametrize("X", [1e-3, 1e-2, 5e-2])
def test_cubic_closed_form_vs_quad(X):
    F_s, F_c, _, _ = cubic_coefficients(X, KC)
    ref_s, ref_c = _fourier(lambda th: KC * (X * math.sin(th)) ** 3, None,
                           scale=KC * X**3)
    assert F_s == pytest.approx(ref_s, rel=RTOL_QUAD)
    assert abs(F_c - ref_c) <= RTOL_QUAD * abs(ref_s)


@pytest.mark.parametrize("fun,args", [(jenkins_coefficients, (KF, FS)),
                                      (gap_coefficients, (K2 - K1, DELTA)),
                                      (cubic_coefficients, (KC,))])
@pytest.mark.parametrize("X", [4e-4, 2e-3, 2e-2])
def test_scalar_derivatives_vs_finite_differences(fun, args, X):
    h = 1e-6 * X
    _, _, dFs, dFc = fun(X, *args)
    p = fun(X + h, *args)
    m = fun(X - h, *args)
    fd_s = (p[0] - m[0]) / (2 * h)
    fd_c = (p[1] - m[1]) / (2 * h)
    scale = max(abs(fd_s), abs(fd_c), 1.0)
    assert abs(dFs - fd_s) <= RTOL_FD * scale
    assert abs(dFc - fd_c) <= RTOL_FD * scale


def _axes(law, friction):
    p = AxisParameters(law=law, k1=K1, kc=KC, k2=K2, delta=DELTA, friction=friction,
                       kf=KF, n0=FS)
    return nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 1.0))


CASES = [("piecewise", True), ("cubic", True), ("linear", True), ("piecewise", False),
         ("cubic", False)]
DEFLECTIONS = [(0.0, 3e-3, -9e-3), (0.0, -1.2e-2, 1.1e-2), (0.0, 2e-4, 1e-4)]


@pytest.mark.parametrize("law,friction", CASES)
@pytest.mark.parametrize("U", DEFLECTIONS)
def test_closed_form_forces_jacobian_vs_fd(law, friction, U):
    ax = _axes(law, friction)
    U = np.array(U, dtype=float)
    if law == "cubic":
        U[0] = 1.5e-3  # exact static term for the cubic
    F, dF = closed_form_forces(U[:, None], ax)
    for g in range(3):
        h = 1e-7 * max(np.abs(U).max(), 1e-4)
        Up, Um = U.copy(), U.copy()
        Up[g] += h
        Um[g] -= h
        fd = (closed_form_forces(Up[:, None], ax)[0][:, 0]
              - closed_form_forces(Um[:, None], ax)[0][:, 0]) / (2 * h)
        scale = max(np.abs(dF[0]).max(), 1.0)
        np.testing.assert_allclose(dF[0, :, g], fd, rtol=0, atol=RTOL_FD * scale)


@pytest.mark.parametrize("law,friction", CASES)
@pytest.mark.parametrize("U", DEFLECTIONS)
def test_closed_form_forces_vs_aft(law, friction, U):
    """Phase rotation of the coefficients: closed form == sampled law (H = 1)."""
    ax = _axes(law, friction)
    U = np.array(U, dtype=float)[:, None]
    F, _ = closed_form_forces(U, ax)
    Fa, _ = aft_forces(U, ax, FourierBasis(1, 2**14), jacobian=False)
    scale = np.abs(Fa).max()
    np.testing.assert_allclose(F, Fa, rtol=0, atol=RTOL_AFT * scale)
