"""The hydraulic mount's closed form and fluid step (fmu_src/linear_branches.py)
against references written here: a direct solve of the chamber and passage
equations per frequency, the lossless notch/peak formula by a dense scan, and
scipy's matrix exponential of the augmented fluid system. Runtime < 1 s."""

from __future__ import annotations

import numpy as np
import scipy.linalg

from drymount.fmu_src.linear_branches import (HydraulicParameters, fluid_propagator,
                                              fluid_relaxed, fluid_step,
                                              hydraulic_complex_stiffness,
                                              hydraulic_notch_peak)

P = HydraulicParameters(kr=2.5e5, br=100.0, Ap=3.5e-3, C1=3e-11, C2=2e-9,
                        I_i=3.2e6, R_i=1.2e8, I_d=2e5, R_d=5e6)


def _direct(p, w):
    """K* from the four balances (upper, lower chamber, two passages), U = 1."""
    jw = 1j * w
    A = np.array([[jw * p.C1, 0, 1, 1], [0, jw * p.C2, -1, -1],
                  [-1, 1, p.R_i + jw * p.I_i, 0], [-1, 1, 0, p.R_d + jw * p.I_d]])
    x = np.linalg.solve(A, np.array([jw * p.Ap, 0, 0, 0]))
    return p.kr + jw * p.br + p.Ap * x[0]


def test_closed_form_equals_direct_solve():
    for w in (0.3, 10.0, 63.0, 300.0, 2e3, 2e4):
        ref = _direct(P, w)
        assert abs(hydraulic_complex_stiffness(P, w) - ref) <= 1e-12 * abs(ref)
    static = P.kr + P.Ap ** 2 / (P.C1 + P.C2)
    assert abs(hydraulic_complex_stiffness(P, 0.0) - static) <= 1e-12 * static


def test_notch_and_peak_of_the_lossless_mount():
    p = P._replace(br=0.0, R_i=0.0, I_d=0.0, R_d=0.0)
    wn, wp = hydraulic_notch_peak(p)
    w = np.linspace(0.5 * wn, 1.5 * wp, 200001)
    K = np.array(hydraulic_complex_stiffness(p, w.tolist())).real
    i_notch = np.argmin(np.abs(K[w < wp]))
    assert abs(w[i_notch] - wn) < 2 * (w[1] - w[0])
    # the pole: K changes sign through infinity between neighbours at wp
    j = np.searchsorted(w, wp)
    assert K[j - 1] < -1e9 and K[j] > 1e9


def test_fluid_step_equals_the_matrix_exponential():
    rng = np.random.default_rng(5)
    for dt in (1e-5, 1e-4, 1e-3):
        a = np.array([[0, 0, -1, -1], [0, 0, 1 / P.C2, 1 / P.C2],
                      [1 / (P.C1 * P.I_i), -1 / P.I_i, -P.R_i / P.I_i, 0],
                      [1 / (P.C1 * P.I_d), -1 / P.I_d, 0, -P.R_d / P.I_d]])
        b = np.array([0, 0, P.Ap / (P.C1 * P.I_i), P.Ap / (P.C1 * P.I_d)])
        m = np.zeros((6, 6))
        m[:4, :4], m[:4, 4], m[4, 5] = a * dt, b * dt, dt
        e = scipy.linalg.expm(m)
        prop = fluid_propagator(P, dt)
        x0 = np.array(fluid_relaxed(P, 1e-3)) + rng.normal(0, 1, 4) * [
            1e-9, 1e3, 1e-6, 1e-6]
        uc, u = 1e-3, 1.4e-3
        f, x, _ = fluid_step(P, prop, tuple(x0), uc, u, dt)
        ref = e[:4, :4] @ x0 + e[:4, 4] * uc + e[:4, 5] * (u - uc) / dt
        f_ref = P.Ap * (ref[0] + P.Ap * u) / P.C1
        assert abs(f - f_ref) <= 1e-9 * abs(f_ref), (dt, f, f_ref)
    # at rest the relaxed fluid stays put and carries the static fluid force
    x = fluid_relaxed(P, 2e-3)
    f, x1, _ = fluid_step(P, fluid_propagator(P, 1e-3), x, 2e-3, 2e-3, 1e-3)
    static = P.Ap ** 2 * 2e-3 / (P.C1 + P.C2)
    assert abs(f - static) <= 1e-9 * static
