"""HBM of a system with an inclined axis (hbm/inclined.py) through the general route,
against independent references: the scalar law stepped by hand, central finite
differences of the residual, Newton's convergence rate, and the co-simulated steady
state (native backend) of the same system. About 10 s."""

import math
from dataclasses import replace

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount.fmu_src.inclined import inclined_update
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.aft import FourierBasis
from drymount.hbm.branches import solutions_at
from drymount.hbm.inclined import inclined_periodic
from drymount.hbm.options import HBMOptions
from drymount.hbm.problem import build_problem
from drymount.hbm.residual import HarmonicBalance
from drymount.hbm.systems import sdof
from drymount.vehicle import steady_state

#: periodic march vs the scalar map stepped by hand, N (measured 0)
MARCH_TOL = 1e-12
#: analytic Jacobian vs central differences, relative to its largest entry (measured
#: 4.8e-12)
JACOBIAN_TOL = 1e-7
#: HBM (H = 7) vs the co-simulated steady state: fundamental amplitude relative to the
#: co-simulated amplitude (measured 2.8e-6 at 5 Hz, 6.9e-6 at 8 Hz)
HBM_VS_COSIM_TOL = 0.01

AXIS = AxisParameters(law="linear", k1=45935.0, k2=45935.0, c=150.0, friction=True,
                      friction_kind="inclined", theta_deg=60.0, k=2e4, kf=6e4,
                      kf2=6e4, mu1=0.3, mu2=0.3, preload=200.0)
BARE = AxisParameters(law="linear", k1=45935.0, k2=45935.0, c=150.0)
SYSTEM = replace(sdof(70.0, MountParameters(AXIS, BARE, BARE), "force", 150.0),
                 static_load=np.array([-70.0 * 9.81]))


def test_periodic_march_equals_the_hand_stepped_map():
    b = FourierBasis(7, 64)
    U = np.zeros(15)
    U[0], U[1], U[2], U[5] = -0.011, 0.004, 0.002, 0.0005
    u = b.E @ U
    el = inclined_periodic(u, AXIS.inclined, -0.011)
    assert el.converged
    # by hand: relaxed at -0.011, then the same number of passes
    s, c = math.sin(math.radians(60)), math.cos(math.radians(60))
    w1, w2, x_old = 0.011 / s, 0.011 * c / s, 0.011
    for _ in range(el.passes):
        ref = []
        for ui in u:
            st = inclined_update(-ui, x_old, w1, w2, AXIS.inclined)
            w1, w2, x_old = st.w1, st.w2, -ui
            ref.append(-st.force)
    assert np.abs(el.force - ref).max() <= MARCH_TOL
    assert np.ptp(el.n1) > 100.0   # the normal force varies over the period


@pytest.mark.parametrize("freq_hz", [5.0, 8.0])
def test_jacobian_equals_finite_differences(freq_hz):
    hb = HarmonicBalance(SYSTEM, 7)
    rng = np.random.default_rng(1)
    X = np.zeros(hb.size)
    X[0] = hb.static.q[0]
    X[1], X[2] = 1.5e-3, 1e-3
    X[3:] += 1e-5 * rng.standard_normal(hb.size - 3)
    w = 2 * np.pi * freq_hz
    J = hb.residual(X, w).dR_dX
    h = 1e-9
    Jfd = np.column_stack([
        (hb.residual(X + h * e, w, False).R - hb.residual(X - h * e, w, False).R)
        / (2 * h) for e in np.eye(hb.size)])
    assert np.abs(J - Jfd).max() <= JACOBIAN_TOL * np.abs(J).max()


def test_newton_converges_quadratically():
    hb = HarmonicBalance(SYSTEM, 7)
    curve = hbm.frequency_response(SYSTEM, 6.0, 6.5, options=HBMOptions(tol=None))
    X = np.asarray(curve.coefficients[-1]).T.ravel().copy()
    w = 2 * np.pi * curve.freq_hz[-1]
    X[1:] *= 1.02   # 2 % off the solution
    norms = []
    for _ in range(5):
        r = hb.residual(X, w)
        norms.append(np.linalg.norm(r.R))
        if norms[-1] < 1e-9:
            break
        X = X - np.linalg.solve(r.dR_dX, r.R)
    # each step squares the error (measured 6.9, 0.35, 1.7e-13 N: converged in two)
    assert len(norms) <= 5 and norms[-1] < 1e-9, norms
    assert norms[2] <= 10 * norms[1] ** 2 / norms[0], norms


def test_frequency_response_is_complete_and_matches_cosimulation():
    curve = hbm.frequency_response(SYSTEM, 4.0, 9.0, options=HBMOptions(tol=None))
    assert curve.success, curve.message
    for f in (5.0, 8.0):
        ss = steady_state(SYSTEM, f, backend="inproc", steps_per_period=1000,
                          rtol=1e-8, max_periods=600)
        a_co = ss.amplitude[0]
        sols = solutions_at(SYSTEM, curve, f)
        amps = []
        for y, stable, _ in sols:
            prob = build_problem(SYSTEM, 4.0, 9.0, 7, curve.n_samples, False)
            X, _ = prob.x_of(y)
            amps.append(math.hypot(X[1], X[2]))
        assert sols, f
        err = min(abs(a - a_co) for a in amps) / a_co
        assert err <= HBM_VS_COSIM_TOL, (f, err)
