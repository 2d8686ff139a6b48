"""Static working point (hbm/static.py) against hand-computed equilibria.

References: the single mount and the quarter car solved by hand (series springs, the
piecewise law's k2 branch past the knee); the 6-DOF engine against an independent
linear solve whose stiffness is assembled here from the Table 4.1 positions (eq. 2.9),
not from the system's B matrices, with every mount inside its linear range.
"""

import numpy as np
import pytest

from drymount.config import load_preset
from drymount.hbm.static import (StaticStatus, gravity_load, knee_warnings,
                        static_equilibrium)

G = 9.81
#: Hand-computed equilibria: Newton on piecewise-linear laws ends exactly on the right
#: branch; measured 1.4e-16 (single DOF), 0 (6 DOF against the hand-assembled solve).
RTOL = 1e-12
K1, K2, DELTA = 45935.0, 256900.0, 0.01225


def test_sdof_halved_sags_past_the_knee():
    system = load_preset("sdof_halved").system
    W = 70.0 * G
    point = static_equilibrium(system, gravity_load(system, [1.0], G))
    assert point.status is StaticStatus.CONVERGED
    # -12.733 mm: past the knee (k1 delta = 563 N)
    hand = -(DELTA + (W - K1 * DELTA) / K2)
    assert abs(point.q[0] - hand) / abs(hand) < RTOL
    assert point.deflection[0, 0] == point.q[0]
    assert abs(point.force[0, 0] + W) / W < RTOL  # compression carries the weight
    warnings = knee_warnings(system, point, travel=0.010)
    assert len(warnings) == 2
    assert "past the knee at -12.250 mm" in warnings[0]
    assert "exceeds the travel of 10.000 mm" in warnings[1]
    np.testing.assert_array_equal(point.sliders, point.deflection)


def test_sdof_original_stays_linear():
    system = load_preset("sdof_original").system
    point = static_equilibrium(system, gravity_load(system, [1.0], G))
    k1 = system.elements[0].params.axial.k1
    assert abs(point.q[0] + 70.0 * G / k1) < RTOL * 70.0 * G / k1
    assert knee_warnings(system, point) == []


def test_quarter_car_halved_by_hand():
    """Tyre carries all the weight, suspension engine + body, mount the engine."""
    system = load_preset("quarter_car_halved").system
    m_e, m_s, m_us = np.diag(system.M)
    k_s = system.K[1, 1]
    k_t = system.K[2, 2] - k_s
    point = static_equilibrium(system, gravity_load(system, [1.0, 1.0, 1.0], G))
    assert point.status is StaticStatus.CONVERGED
    q_us = -(m_e + m_s + m_us) * G / k_t
    q_s = q_us - (m_e + m_s) * G / k_s
    W = m_e * G
    u = -(DELTA + (W - K1 * DELTA) / K2) if W > K1 * DELTA else -W / K1
    np.testing.assert_allclose(point.q, [q_s + u, q_s, q_us], rtol=RTOL)


def _hand_stiffness(positions, k):
    """sum over mounts of T^T k T, T = [I, -S(a)] (t + theta x a, eq. 2.9)."""
    K = np.zeros((6, 6))
    for a in positions:
        ax, ay, az = a
        S = np.array([[0, -az, ay], [az, 0, -ax], [-ay, ax, 0]])
        T = np.hstack([np.eye(3), -S])
        K += k * T.T @ T
    return K


def test_six_dof_against_an_independent_linear_solve():
    system = load_preset("six_dof_original").system
    load = gravity_load(system, [0, 0, 1.0, 0, 0, 0], G)
    load[4] += 40.0  # a static torque about y, N m (the engine's drive torque, say)
    point = static_equilibrium(system, load)
    assert point.status is StaticStatus.CONVERGED
    assert np.all(np.abs(point.deflection) < DELTA)  # every mount in its linear range
    assert knee_warnings(system, point) == []
    positions = [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)]
    q_hand = np.linalg.solve(_hand_stiffness(positions, 91870.0), load)
    np.testing.assert_allclose(point.q, q_hand, rtol=1e-10, atol=1e-15)
    # the mounts carry the weight: sum of axial (z) forces = -m g
    assert point.force[:, 0].sum() == pytest.approx(-140.6 * G, rel=1e-12)


def test_six_dof_halved_under_gravity_converges_with_knees():
    system = load_preset("six_dof_halved").system
    point = static_equilibrium(system, gravity_load(system, [0, 0, 1.0, 0, 0, 0], G))
    assert point.status is StaticStatus.CONVERGED and point.iterations <= 10
    assert point.force[:, 0].sum() == pytest.approx(-140.6 * G, rel=1e-12)
    assert any("mount3 axial" in w for w in knee_warnings(system, point))


def test_bad_input():
    system = load_preset("sdof_halved").system
    with pytest.raises(ValueError, match="`load` must be finite"):
        static_equilibrium(system, [np.nan])
    with pytest.raises(ValueError, match="`vertical` must have shape"):
        gravity_load(system, [1.0, 0.0])
    with pytest.raises(ValueError, match="`g` must be finite"):
        gravity_load(system, [1.0], -1.0)
