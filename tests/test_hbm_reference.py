"""Multi-harmonic HBM vs independent time integration with event-exact stick-slip
(hbm/reference.py, scipy solve_ivp), on the single-DOF and quarter-car friction presets.

Fundamental amplitudes are compared, normalised by the peak amplitude of the curve
(the issue: H >= 7 within 0.5 % of the peak amplitude). In stuck bands both start the
slider at w = 0 (PHYSICS.md section 1), so the offsets agree there too.
"""

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.reference import periodic_response
from drymount.hbm.systems import quarter_car, sdof

RTOL_HBM_VS_TIME = 5e-3  # the requirement; measured <= 7.2e-4 at H = 7 (peak)
RTOL_REF_LINEAR = 1e-7   # reference on a linear system; measured 1.2e-8 (period tol)


def sdof_preset():
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        mu=1.0, n0=20.0)
    return sdof(70.0, MountParameters(axial=ax), "force", 40.0)


def quarter_car_preset():
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        mu=1.0, n0=30.0)
    return quarter_car(70, 230, 30, 15000, 1000, 200000, 0.0,
                       MountParameters(axial=ax), road_amplitude=0.01)


def _compare(system, fmin, fmax, freqs, H):
    curve = hbm.frequency_response(system, fmin, fmax, harmonics=H)
    assert curve.success
    peak = curve.amplitude.max(axis=0)
    r = hbm.solve_frequencies(system, freqs, harmonics=H)
    assert r.success
    errs = []
    for i, f in enumerate(freqs):
        ref = periodic_response(system, float(f))
        assert ref.converged
        errs.append(np.abs(r.amplitude[i] - ref.amplitude) / peak)
    return np.array(errs)


def test_sdof_vs_time_integration():
    err = _compare(sdof_preset(), 2.0, 15.0, [4.0, 5.8, 7.0], 7)
    assert err.max() <= RTOL_HBM_VS_TIME


def test_quarter_car_vs_time_integration():
    err = _compare(quarter_car_preset(), 1.0, 25.0, [6.2, 9.0], 7)
    assert err.max() <= RTOL_HBM_VS_TIME


@pytest.mark.slow
@pytest.mark.parametrize("H", [7, 15])
def test_sdof_vs_time_integration_full(H):
    err = _compare(sdof_preset(), 2.0, 15.0, np.arange(2.5, 15.0, 1.0), H)
    assert err.max() <= RTOL_HBM_VS_TIME


@pytest.mark.slow
def test_quarter_car_vs_time_integration_full():
    err = _compare(quarter_car_preset(), 1.0, 25.0, [1.2, 3.0, 5.0, 6.2, 7.5, 9.0,
                                                      12.0, 16.0, 20.0, 24.0], 9)
    assert err.max() <= RTOL_HBM_VS_TIME


def test_reference_on_linear_system():
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0)
    s = sdof(70.0, MountParameters(axial=ax), "base", 0.002)
    for f in (3.0, 5.8):
        ref = periodic_response(s, f, initial="rest")
        Q = hbm.linear_frf(s, [f])[0, 0]
        assert ref.converged
        tol = RTOL_REF_LINEAR * abs(Q)
        assert ref.coefficients[0, 1] == pytest.approx(Q.imag, abs=tol)
        assert ref.coefficients[0, 2] == pytest.approx(Q.real, abs=tol)


def test_reference_energy_balance_and_input_check():
    """Steady state: the excitation's work per cycle equals the viscous plus the
    friction dissipation; friction dissipates >= 0 and < 4 Fs X (it slips)."""
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        n0=20.0)
    s = sdof(70.0, MountParameters(axial=ax), "force", 40.0)
    f = 7.0
    ref = periodic_response(s, f, harmonics=200, n_out=4096)
    assert ref.converged and ref.n_events > 0
    w = 2 * np.pi * f
    qc = ref.coefficients[0, 1::2]
    qs = ref.coefficients[0, 2::2]
    k = np.arange(1, qc.size + 1)
    w_exc = -np.pi * 40.0 * qc[0]                       # int F sin(wt) dq
    w_visc = np.pi * 150.0 * w * np.sum(k**2 * (qc**2 + qs**2))  # int c q'^2 dt
    w_fr = w_exc - w_visc
    X = ref.amplitude[0]
    assert 0.0 < w_fr < 4 * 20.0 * X
    # a harmonic deflection of amplitude X would dissipate 4 Fs (X - eps)
    # higher harmonics make it differ: measured 0.47 %, 4x margin
    assert w_fr == pytest.approx(4 * 20.0 * (X - 20.0 / 60000.0), rel=0.02)
    with pytest.raises(ValueError, match="freq_hz"):
        periodic_response(s, -1.0)


def test_symmetric_piecewise_reference_ignores_delta_neg():
    """The symmetric piecewise law has its knees at +-delta whatever delta_neg says:
    the event-exact reference must stop at u = -delta (regression: it used
    -delta_neg, so a step straddled the real kink and an event fired at a point that
    is no kink). With delta_neg = delta / 2 the run must equal the one with
    delta_neg = delta exactly, and cross both knees."""
    def system(delta_neg):
        ax = AxisParameters(law="piecewise", k1=91870.0, k2=513800.0, delta=0.004,
                            delta_neg=delta_neg, c=150.0)
        return sdof(70.0, MountParameters(axial=ax), "force", 800.0)

    a = periodic_response(system(0.004), 6.0, max_periods=12, n_out=64)
    b = periodic_response(system(0.002), 6.0, max_periods=12, n_out=64)
    assert a.q.min() < -0.004 and a.q.max() > 0.004  # both knees are crossed
    assert a.n_events == b.n_events and np.array_equal(a.q, b.q)
