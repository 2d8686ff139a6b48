"""Vehicle harness, linear mounts: co-simulated steady states against the exact FRF.

The reference is computed here with numpy from the system's linearisation (exact for
linear laws without friction): X = (K_tot - w^2 M + i w C_tot)^-1 (F + (Kb_tot +
i w Cb_tot) Y), q(t) = Im(X exp(i w t)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.vehicle.master import Master
from drymount.hbm.systems import quarter_car, rigid_engine, sdof
from drymount.vehicle.steady import run_steady, steady_state

#: Issue 4 target at the default step (256 steps per period); measured worst
#: 1.5e-4 (SDOF), 4.9e-4 (quarter car), see vehicle.master.
RTOL_FRF = 5e-3
#: FMU and native backends run the same arithmetic: equal to rounding.
RTOL_BACKENDS = 1e-9

LINEAR = AxisParameters(law="linear", k1=91870.0, c=150.0)
MOUNT = MountParameters.from_axial(LINEAR)
POSITIONS = [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)]
F_N_SDOF = math.sqrt(91870.0 / 70.0) / (2 * math.pi)  # 5.77 Hz


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory):
    from drymount.fmu_build import build_fmu

    return build_fmu(tmp_path_factory.mktemp("fmu") / "FrictionMount.fmu")


def exact_frf(system, freq_hz: float) -> np.ndarray:
    """Complex amplitude X (n_dof,) of the linear steady state, sine convention."""
    w = 2 * math.pi * freq_hz
    K, C = system.linearized()
    Kb, Cb = system.linearized_base()
    exc = system.excitation
    if exc.kind == "base":
        rhs = (Kb + 1j * w * Cb) @ np.asarray(exc.amplitude)
    elif exc.kind == "unbalance":
        rhs = w ** 2 * np.asarray(exc.amplitude, dtype=complex)
    else:
        rhs = np.asarray(exc.amplitude, dtype=complex)
    return np.linalg.solve(K - w ** 2 * system.M + 1j * w * C, rhs)


def sdof_unbalance():
    return sdof(70.0, MOUNT, "unbalance", 0.01)


def sdof_force():
    return sdof(70.0, MOUNT, "force", 100.0)


def quarter():
    # k_t = 200 kN/m: a passenger-car tyre (PHYSICS.md: 150-250 kN/m); c_t = 0
    return quarter_car(70.0, 230.0, 30.0, 15000.0, 1000.0, 200000.0, 0.0, MOUNT, 0.01)


def six_dof():
    return rigid_engine(140.8, [8.63, 10.02, 10.22], POSITIONS,
                        [MountParameters.from_axial(LINEAR, 1.0)] * 3)


def rel_err(amp, X, floor):
    """|amp - |X|| / max(|X|, floor) per DOF."""
    return np.abs(amp - np.abs(X)) / np.maximum(np.abs(X), floor)


@pytest.mark.parametrize("make, freqs", [
    (sdof_unbalance, np.geomspace(1.5, 60.0, 8)),
    (sdof_force, np.geomspace(1.5, 60.0, 8)),
    (quarter, np.geomspace(0.5, 40.0, 8)),
])
def test_native_sweep_equals_exact_frf_over_band(make, freqs):
    """Stepped sweep from rest over the band (resonances included), default step."""
    system = make()
    worst = 0.0
    with Master(system, "inproc") as m:
        for i, f in enumerate(freqs):
            ss = run_steady(m, f, start="rest" if i == 0 else "continue")
            assert ss.converged, ss.message
            assert ss.steps_per_period >= 256
            X = exact_frf(system, f)
            err = rel_err(ss.amplitude, X, 0.0)
            worst = max(worst, float(err.max()))
            # transmissibility as System.transmissibility defines it
            tr = system.transmissibility
            if tr.kind == "displacement":
                ref = abs(X[tr.reference]) if tr.reference is not None else \
                    system.excitation.scalar_amplitude(2 * math.pi * f)
                assert ss.transmissibility == pytest.approx(abs(X[tr.dof]) / ref,
                                                            rel=RTOL_FRF)
            else:
                # force transmitted by spring + damper: |k + i w c| |X| / |F|
                w = 2 * math.pi * f
                ft = abs(91870.0 + 1j * w * 150.0) * abs(X[0])
                assert ss.transmissibility == pytest.approx(
                    ft / system.excitation.scalar_amplitude(w), rel=RTOL_FRF)
    assert worst < RTOL_FRF


@pytest.mark.parametrize("make, freqs", [
    (sdof_unbalance, [0.8 * F_N_SDOF, F_N_SDOF, 2.0 * F_N_SDOF]),
    (quarter, [1.2, 6.0, 14.0]),
])
def test_fmu_steady_state_equals_exact_frf(make, freqs, fmu_path):
    """Co-simulation through the FMU, each frequency from rest."""
    system = make()
    for f in freqs:
        ss = steady_state(system, f, backend="fmu", fmu_path=fmu_path, start="rest")
        assert ss.converged, ss.message
        assert ss.backend == "fmu"
        assert np.all(rel_err(ss.amplitude, exact_frf(system, f), 0.0) < RTOL_FRF)


def test_six_dof_linear_equals_exact_frf(fmu_path):
    """6-DOF engine on three linear mounts, base excitation 0.0035 m along z."""
    system = six_dof()
    with Master(system, "fmu", fmu_path=fmu_path) as m:
        for i, f in enumerate([4.0, 7.5, 12.0]):
            ss = run_steady(m, f, start="rest" if i == 0 else "continue")
            assert ss.converged, ss.message
            X = exact_frf(system, f)
            # DOFs that barely move are compared against 1e-3 of the largest motion
            # (translations in m, rotations in rad times a 0.5 m lever arm)
            scale = np.where(np.arange(6) < 3, 1.0, 0.5)
            floor = 1e-3 * np.max(np.abs(X) * scale) / scale
            assert np.all(rel_err(ss.amplitude, X, floor) < RTOL_FRF), (f, ss.amplitude,
                                                                       np.abs(X))
            assert ss.transmissibility == pytest.approx(abs(X[2]) / 0.0035,
                                                        rel=RTOL_FRF)


def test_second_order_convergence_in_step_size():
    """Error against the exact FRF falls ~4x per halving of the step (leapfrog with
    the velocity predictor), measured at the resonance flank."""
    system = sdof_unbalance()
    f = 1.1 * F_N_SDOF
    X = exact_frf(system, f)
    errs = []
    for n in (32, 64, 128):
        ss = steady_state(system, f, steps_per_period=n, rtol=1e-9, max_periods=3000)
        assert ss.steps_per_period == n
        errs.append(abs(ss.amplitude[0] - abs(X[0])) / abs(X[0]))
    ratios = [errs[0] / errs[1], errs[1] / errs[2]]
    # second order: ratio 4 (measured 4.1, 4.0); first order would give 2
    assert all(3.5 < r < 4.6 for r in ratios), (errs, ratios)


def test_backends_give_identical_linear_histories(fmu_path):
    """simulate(): the FMU and the in-process law produce the same time history."""
    from drymount.vehicle import simulate

    system = sdof_force()
    a = simulate(system, 7.0, 0.3, backend="inproc")
    b = simulate(system, 7.0, 0.3, backend="fmu", fmu_path=fmu_path)
    assert a.q.shape == b.q.shape == (len(a.t), 1)
    np.testing.assert_allclose(b.q, a.q, rtol=RTOL_BACKENDS, atol=1e-15)
    np.testing.assert_allclose(b.forces, a.forces, rtol=RTOL_BACKENDS, atol=1e-12)
    assert a.t[-1] == pytest.approx(0.3, rel=1e-12)
