"""Dynamic stiffness from the imposed-deflection harmonic balance (hbm/characterise.py).

References: the exact K* = k + i omega c of a linear spring and damper; the closed-form
Jenkins coefficients of hbm/closed_form.py (themselves checked against quadrature in
test_hbm_closed_form.py); an independent time march of the law; the hand-solved
working point of a linear law under a preload.
"""

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, elastic_force
from drymount.hbm.characterise import (DynamicStiffnessMap, dynamic_stiffness,
                              rate_independent_stiffness, time_domain_stiffness,
                              working_deflection)
from drymount.hbm.closed_form import gap_coefficients, jenkins_coefficients

#: Linear spring + damper vs k + i omega c: the issue's bound; measured 0 (exact in
#: floating point).
RTOL_LINEAR = 1e-9
#: Jenkins (and gap) vs the closed forms: the issue's bound; measured 5.6e-8
#: (Jenkins), 3.5e-8 (gap), N = 4096 samples.
RTOL_CLOSED = 1e-6
#: AFT vs time march of the law (2048 steps per period, rectangle rule in both);
#: measured 7.6e-8 relative.
RTOL_TIME = 1e-6
#: Working point vs the hand-solved value; measured 0 (k past the knee: 3e-15).
RTOL_U0 = 1e-10

K1, K2, DELTA, C = 45935.0, 256900.0, 0.01225, 150.0
KF, FS = 60000.0, 10.0
FREQS = (1.0, 7.0, 40.0)


def test_linear_spring_damper_is_k_plus_i_omega_c():
    axis = AxisParameters(law="linear", k1=K1, c=C)
    m = dynamic_stiffness(axis, FREQS, [1e-4, 3e-3], [0.0, 500.0])
    exact = K1 + 1j * 2 * np.pi * np.array(FREQS) * C
    err = np.max(np.abs(m.K - exact) / np.abs(exact))
    assert err < RTOL_LINEAR, err
    np.testing.assert_allclose(m.loss_angle_deg[0, 0],
                               np.degrees(np.arctan2(exact.imag, exact.real)),
                               rtol=RTOL_LINEAR)
    # the preload shifts the working point by P / k1, nothing else
    np.testing.assert_allclose(m.mean_deflection[1], 500.0 / K1, rtol=RTOL_U0)


@pytest.mark.parametrize("X", [1e-4, 2.5e-4, 1e-3, 4e-3])
def test_jenkins_matches_closed_form(X):
    """Stuck (X <= Fs/kf = 0.167 mm) and slipping amplitudes."""
    axis = AxisParameters(law="linear", k1=K1, c=C, friction=True, kf=KF, mu=1.0,
                          n0=FS)
    m = dynamic_stiffness(axis, FREQS, [X])
    F_s, F_c, _, _ = jenkins_coefficients(X, KF, FS)
    exact = K1 + F_s / X + 1j * (2 * np.pi * np.array(FREQS) * C + F_c / X)
    err = np.max(np.abs(m.K[0, 0] - exact) / np.abs(exact))
    assert err < RTOL_CLOSED, err
    # equivalent damping of the element alone: Im K* - omega c = 4 Fs (1 - eps/X)/(pi X)
    eq_damp = m.K[0, 0].imag - 2 * np.pi * np.array(FREQS) * C
    np.testing.assert_allclose(eq_damp, F_c / X, rtol=RTOL_CLOSED, atol=1e-9)


def test_piecewise_gap_matches_closed_form():
    axis = AxisParameters(law="piecewise", k1=K1, k2=K2, delta=DELTA, c=0.0)
    X = 0.02
    F_s, _, _, _ = gap_coefficients(X, K2 - K1, DELTA)
    k = rate_independent_stiffness(axis, X)
    assert abs(k - (K1 + F_s / X)) / abs(k) < RTOL_CLOSED
    assert abs(k.imag) < 1e-9 * K1


def test_aft_agrees_with_time_march_under_preload():
    """Piecewise + Jenkins about a preloaded working point past the knee."""
    axis = AxisParameters(law="piecewise", k1=K1, k2=K2, delta=DELTA, c=C,
                          friction=True, kf=KF, mu=1.0, n0=FS)
    P = 70.0 * 9.81
    for X in (1e-4, 1e-3, 5e-3):
        U0 = working_deflection(axis, P, X)
        k_hbm = dynamic_stiffness(axis, [12.0], [X], [P]).K[0, 0, 0]
        k_time = time_domain_stiffness(axis, 12.0, X, U0)
        assert abs(k_hbm - k_time) / abs(k_time) < RTOL_TIME, (X, k_hbm, k_time)


def test_working_point_is_the_static_balance():
    """Small amplitude inside one linear branch: U0 solves F_el(U0) = P by hand."""
    axis = AxisParameters(law="piecewise", k1=K1, k2=K2, delta=DELTA, c=C)
    P = 70.0 * 9.81  # past the knee: k1 delta = 562.7 N < P
    U0_hand = DELTA + (P - K1 * DELTA) / K2
    U0 = working_deflection(axis, P, 1e-4)
    assert abs(U0 - U0_hand) / U0_hand < RTOL_U0
    assert elastic_force(U0, axis)[0] == pytest.approx(P)
    # past the knee the dynamic stiffness is k2 (+ i omega c)
    k = rate_independent_stiffness(axis, 1e-4, U0)
    assert abs(k - K2) / K2 < RTOL_LINEAR


def test_map_shapes_and_bad_input():
    axis = AxisParameters(law="linear", k1=K1, c=C)
    m = dynamic_stiffness(axis, [1, 2, 3], [1e-3, 2e-3], [0.0])
    assert isinstance(m, DynamicStiffnessMap)
    assert m.K.shape == (1, 2, 3) and m.mean_deflection.shape == (1, 2)
    with pytest.raises(ValueError, match="amplitudes"):
        dynamic_stiffness(axis, [1.0], [0.0])
    with pytest.raises(ValueError, match="freqs_hz"):
        dynamic_stiffness(axis, [math.nan], [1e-3])
    with pytest.raises(ValueError, match="preload"):
        working_deflection(AxisParameters(law="linear", k1=0.0), 10.0, 1e-3)
