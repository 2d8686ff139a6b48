"""Vehicle harness inputs: harmonic, crank mechanism, roads, base sine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.vehicle import simulate
from drymount.vehicle.inputs import (
    BaseSine,
    BumpRoad,
    CrankInput,
    HarmonicInput,
    RandomRoad,
    SineRoad,
    SumInput,
    SweptSineRoad,
    iso8608_gd0,
)
from drymount.hbm.systems import quarter_car, rigid_engine, sdof

#: Series of eq. 1.3 against exact slider-crank kinematics: the force keeps
#: A2 = R/l, whose truncation is lambda^2/4 = 2.2 % of the second order (measured
#: 2.45 %); the torque series keeps the exact second-order term (measured 0.31 %).
RTOL_CRANK_FORCE = 3e-2
RTOL_CRANK_TORQUE = 1e-2
#: Central differences with step 1e-6 s against the analytic base velocity.
RTOL_RATE = 1e-5
#: Midpoint-rule sum of Gd(n_i) dn against the integral of Gd over the band
#: (n^-2 is steep at the low end, where the first band is 1.5 dn .. 2.5 dn):
#: measured 3.3 % with the default 500 waves.
RTOL_ROAD_VARIANCE = 5e-2
#: Linear response to the crank input against the exact FRF at orders 2 and 4 (the
#: master's accuracy target).
RTOL_FRF = 5e-3

LINEAR = MountParameters.from_axial(AxisParameters(law="linear"))
POSITIONS = [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)]


def qc():
    return quarter_car(70.0, 230.0, 30.0, 15000.0, 1000.0, 200000.0, 0.0, LINEAR, 0.01)


def six():
    return rigid_engine(140.8, [8.63, 10.02, 10.22], POSITIONS, [LINEAR] * 3)


def test_harmonic_input_follows_the_excitation_kinds():
    t = np.linspace(0.0, 0.3, 7)
    w = 2 * math.pi * 8.0
    s = sdof(70.0, LINEAR, "unbalance", 0.02)
    inp = HarmonicInput(s, 8.0)
    np.testing.assert_allclose(inp.force(t)[:, 0], 0.02 * w ** 2 * np.sin(w * t))
    assert inp.base(t).shape == (7, 0)
    s = sdof(70.0, LINEAR, "base", 0.001)
    inp = HarmonicInput(s, 8.0)
    np.testing.assert_allclose(inp.base(t)[:, 0], 0.001 * np.sin(w * t))
    np.testing.assert_allclose(inp.base_velocity(t)[:, 0], 0.001 * w * np.cos(w * t))
    np.testing.assert_array_equal(inp.force(0.1), [0.0])
    assert inp.base(0.1).shape == (1,)


@pytest.mark.parametrize("make", [
    lambda: SineRoad(qc(), 0.01, 3.0, phase=0.4),
    lambda: SweptSineRoad(qc(), 0.01, 1.0, 20.0, 2.0),
    lambda: SweptSineRoad(qc(), 0.01, 1.0, 20.0, 2.0, spacing="log"),
    lambda: BumpRoad(qc(), 0.05, 0.5, 10.0, t_start=0.1),
    lambda: RandomRoad(qc(), "D", 20.0, seed=3),
    lambda: BaseSine(six(), 7.0),
    lambda: HarmonicInput(six(), 7.0),
])
def test_base_velocity_is_the_derivative_of_the_base(make):
    inp = make()
    t = np.linspace(0.05, 1.9, 37)
    d = 1e-6
    fd = (inp.base(t + d) - inp.base(t - d)) / (2 * d)
    rate = inp.base_velocity(t)
    scale = np.abs(rate).max()
    assert scale > 0
    np.testing.assert_allclose(rate, fd, rtol=0, atol=RTOL_RATE * scale)


def test_base_sine_is_vertical_0_0035_m():
    inp = BaseSine(six(), 5.0)
    y = inp.base(np.linspace(0, 0.2, 400))
    assert np.abs(y[:, :2]).max() == 0.0
    assert np.abs(y[:, 2]).max() == pytest.approx(0.0035, rel=1e-3)


def test_bump_shape():
    b = BumpRoad(qc(), 0.05, 0.5, 10.0, t_start=0.1)
    assert b.base(0.05)[0] == 0.0 and b.base(0.2)[0] == 0.0
    assert b.base(0.125)[0] == pytest.approx(0.05)
    assert b.base_velocity(0.1)[0] == pytest.approx(0.0, abs=1e-12)


def test_swept_sine_frequency_ends():
    s = SweptSineRoad(qc(), 0.01, 2.0, 30.0, 4.0, spacing="log")
    assert s.frequency(0.0) == pytest.approx(2.0)
    assert s.frequency(4.0) == pytest.approx(30.0)
    assert s.frequency(2.0) == pytest.approx(math.sqrt(60.0))


def exact_crank(m_rec, R, l, omega, theta):  # noqa: E741 (thesis symbol)
    """Inertia force -m x'' and crankshaft torque -m x'' dx/dtheta of four cylinders
    (cranks 0, 180, 180, 0 deg) from the exact slider-crank position."""
    def x(t):
        return R * np.cos(t) + np.sqrt(l * l - (R * np.sin(t)) ** 2)
    d = 1e-4
    F = np.zeros_like(theta)
    T = np.zeros_like(theta)
    for ph in (0.0, math.pi, math.pi, 0.0):
        t = theta + ph
        xdd = (x(t + d) - 2 * x(t) + x(t - d)) / d ** 2 * omega ** 2
        dx = (x(t + d) - x(t - d)) / (2 * d)
        F += -m_rec * xdd
        T += -m_rec * xdd * dx
    return F, T


def test_crank_excitation_against_exact_kinematics():
    s = six()
    inp = CrankInput(s, 3000.0)
    assert inp.second_order_hz == pytest.approx(100.0)
    w = 2 * math.pi * 3000.0 / 60.0
    t = np.linspace(0.0, 2 * math.pi / w, 2048, endpoint=False)
    F, T = exact_crank(inp.m_rec, inp.R, inp.l, w, w * t)
    f = inp.force(t)
    z, beta = s.dof_names.index("z"), s.dof_names.index("beta")
    assert np.abs(f[:, z] - F).max() < RTOL_CRANK_FORCE * np.abs(F).max()
    # the block feels the reaction to the inertia torque on the crankshaft
    assert np.abs(f[:, beta] + T).max() < RTOL_CRANK_TORQUE * np.abs(T).max()
    others = [i for i in range(6) if i not in (z, beta)]
    assert np.abs(f[:, others]).max() == 0.0
    # first order cancels in the inline four: the exact force has none either
    spec = np.abs(np.fft.rfft(F)) / len(t)
    assert spec[1] < 1e-6 * spec[2]  # finite-difference noise only


def test_crank_input_defaults_for_single_dof():
    inp = CrankInput(sdof(70.0, LINEAR, "force", 1.0), 1200.0)
    assert inp.force_dof == 0 and inp.moment_dof is None
    with pytest.raises(ValueError, match="`moment_dof` must be one of"):
        CrankInput(six(), 1200.0, moment_dof="roll")
    with pytest.raises(ValueError, match="`speed_rpm` must be finite and > 0"):
        CrankInput(six(), -5.0)


def test_iso8608_classes():
    assert iso8608_gd0("A") == pytest.approx(16e-6)
    assert iso8608_gd0("C") == pytest.approx(256e-6)
    assert iso8608_gd0("h") == pytest.approx(262144e-6)
    with pytest.raises(ValueError, match="`road_class` must be one of A-H"):
        iso8608_gd0("J")


def test_random_road_statistics_and_seed():
    road = RandomRoad(qc(), "C", 20.0, seed=7)
    # one full period L = 1 / dn: the sample variance is exactly sum a^2 / 2 (the
    # products of two waves have at most 2 (k0 + K) ~ 1000 cycles in L: 8192
    # samples resolve them)
    L = 1.0 / road.dn
    t = np.linspace(0.0, L / road.speed, 8192, endpoint=False)
    r = road.base(t)[:, 0]
    lo, hi = road.band
    assert lo <= road.n_min + road.dn and hi >= road.n_max - road.dn
    integral = road.gd0 * 0.1 ** 2 * (1 / lo - 1 / hi)
    assert np.var(r) == pytest.approx(road.variance, rel=1e-9)
    assert road.variance == pytest.approx(integral, rel=RTOL_ROAD_VARIANCE)
    again = RandomRoad(qc(), "C", 20.0, seed=7).base(t[:100])
    np.testing.assert_array_equal(again[:, 0], r[:100])
    other = RandomRoad(qc(), "C", 20.0, seed=8).base(t[:100])
    assert np.abs(other[:, 0] - r[:100]).max() > 1e-4
    # class D has 4 times the PSD of class C: twice the rms
    d = RandomRoad(qc(), "D", 20.0, seed=7)
    assert d.variance == pytest.approx(4 * road.variance)


def test_sum_input():
    s = six()
    a, b = CrankInput(s, 2000.0), BaseSine(s, 5.0)
    t = np.linspace(0, 0.1, 11)
    both = SumInput([a, b])
    np.testing.assert_allclose(both.force(t), a.force(t))
    np.testing.assert_allclose(both.base(t), b.base(t))


def test_simulated_crank_response_equals_linear_frf():
    """Linear, well-damped SDOF under the crank input: after the transient the
    response at orders 2 and 4 equals the exact FRF (inputs on the step grid)."""
    mount = MountParameters.from_axial(AxisParameters(law="linear", c=3000.0))
    s = sdof(70.0, mount, "force", 0.0)
    inp = CrankInput(s, 900.0)  # second order 30 Hz
    w2 = 2 * (2 * math.pi * 900.0 / 60.0)
    period = 2 * math.pi / w2
    n_per = 256
    th = simulate(s, None, 40 * period, backend="inproc", inputs=inp,
                  dt=period / n_per)
    q = th.q[-n_per - 1:-1, 0]  # last second-order period
    spec = np.fft.rfft(q) / n_per * 2
    for order, amp in ((1, 4 * inp.m_rec * inp.R * (w2 / 2) ** 2 * inp.A2),
                       (2, 4 * inp.m_rec * inp.R * (w2 / 2) ** 2 * inp.A4)):
        w = order * w2
        H = 1.0 / (91870.0 - 70.0 * w ** 2 + 1j * w * 3000.0)
        assert abs(spec[order]) == pytest.approx(amp * abs(H), rel=RTOL_FRF)


def test_random_road_time_history_through_the_fmu(tmp_path):
    """Quarter car with a friction mount on an ISO 8608 class C road at 20 m/s: the
    FMU and the in-process law give the same history; friction energy only grows."""
    from drymount.fmu_build import build_fmu

    fmu = build_fmu(tmp_path / "FrictionMount.fmu")
    ax = AxisParameters(law="piecewise", k1=45935.0, k2=256900.0, friction=True,
                        n0=30.0)
    s = quarter_car(70.0, 230.0, 30.0, 15000.0, 1000.0, 200000.0, 0.0,
                    MountParameters.from_axial(ax), 0.0)
    road = RandomRoad(s, "C", 20.0, seed=2)
    a = simulate(s, None, 1.0, backend="inproc", inputs=road)
    b = simulate(s, None, 1.0, backend="fmu", inputs=road, fmu_path=fmu)
    np.testing.assert_allclose(b.q, a.q, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(b.friction_energy, a.friction_energy, rtol=1e-9,
                               atol=1e-15)
    assert a.friction_energy[-1] > 0
    assert np.all(np.diff(a.friction_energy) >= 0)


def test_simulate_rejects_bad_arguments():
    s = sdof(70.0, LINEAR, "force", 1.0)
    with pytest.raises(ValueError, match="give `freq_hz`"):
        simulate(s, None, 0.1, backend="inproc")
    with pytest.raises(ValueError, match="`duration` must be finite and > 0"):
        simulate(s, 5.0, -1.0, backend="inproc")
    with pytest.raises(ValueError, match="exceeds the step limit"):
        simulate(s, 5.0, 0.1, backend="inproc", dt=0.05)
    with pytest.raises(ValueError, match="made for another system"):
        simulate(s, None, 0.1, backend="inproc", inputs=SineRoad(qc(), 0.01, 2.0))
