"""Maxwell branches (a spring in series with a damper, beside the elastic law) against
references written here: the complex stiffness k j w c / (k + j w c), the exact FRF
of the linear SDOF (continuous, and that of the leapfrog master's discretisation),
a fine-step RK4 integration of the branch's ODE, the static working point without
them. Runtime about 4 s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drymount.fmu_src.linear_branches import (maxwell_complex_stiffness,
                                              maxwell_step)
from drymount.fmu_src.mount_law import (AxisParameters, MaxwellAxisState,
                                        MountParameters, axis_force, conform_state,
                                        initial_sliders, slider_position)
from drymount.hbm.analysis import frequency_response
from drymount.hbm.characterise import dynamic_stiffness
from drymount.hbm.systems import sdof
from drymount.vehicle.batch import steady_states
from drymount.vehicle.steady import steady_state

M, K1, C = 70.0, 9.0e4, 400.0
BRANCHES = ((4.0e4, 300.0), (2.0e4, 20.0))
F0 = 100.0


def _axis(**kw) -> AxisParameters:
    mx = {}
    for i, (k, c) in enumerate(BRANCHES, start=1):
        mx[f"maxwell_k{i}"], mx[f"maxwell_c{i}"] = k, c
    mx.update(kw)
    return AxisParameters(**{"law": "linear", "k1": K1, "c": C, **mx})


def _K(omega):
    """The reference complex stiffness of the axis, written out."""
    w = np.asarray(omega, dtype=float)
    out = K1 + 1j * w * C
    for k, c in BRANCHES:
        out = out + k * 1j * w * c / (k + 1j * w * c)
    return out


def _system(kind="force", amplitude=F0, axis=None):
    ax = axis or _axis()
    return sdof(M, MountParameters(ax, ax, ax), kind, amplitude)


def test_closed_form_and_step_against_rk4():
    w = [0.0, 3.0, 60.0, 1e4]
    got = maxwell_complex_stiffness([k for k, _ in BRANCHES], [c for _, c in BRANCHES],
                                    w)
    ref = _K(w) - K1 - 1j * np.asarray(w) * C
    np.testing.assert_allclose(got, ref, rtol=1e-14, atol=1e-9)
    # one increment with a linear input path against RK4 at 2e4 substeps
    k, c = BRANCHES[0]
    uc, w0, u, dt = 1e-3, 4e-4, 3.2e-3, 6e-3
    f, w1, _kt = maxwell_step(k, c, uc, w0, u, dt)
    n, h, x = 20000, dt / 20000, w0
    def g(t, x):
        return k * (uc + (u - uc) * t / dt - x) / c
    for i in range(n):
        t = i * h
        a1 = g(t, x)
        a2 = g(t + h / 2, x + h / 2 * a1)
        a3 = g(t + h / 2, x + h / 2 * a2)
        a4 = g(t + h, x + h * a3)
        x += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    assert abs(w1 - x) < 1e-14
    assert abs(f - k * (u - x)) < 1e-9
    # a jump (dt = 0): the damper holds, the spring takes the whole increment
    assert maxwell_step(k, c, uc, w0, u, 0.0) == (k * (u - w0), w0, k)


def test_state_carries_the_strokes():
    ax = _axis(friction=True, friction_kind="lugre", kf=6e4, n0=30.0, sigma1=50.0)
    w = initial_sliders(ax, 1e-3)
    assert isinstance(w, MaxwellAxisState) and len(w) == 2 + 1 + 3
    r = axis_force(2e-3, 0.1, w, ax, None, 1e-3)
    # a flat list (a serialized FMU state) reads back as the same state
    again = conform_state(ax, list(r.w_new))
    assert tuple(again) == tuple(r.w_new) and isinstance(again, MaxwellAxisState)
    # w_<axis> is the element's position (LuGre: its committed deflection), the
    # branches' uc and strokes follow it in the state
    assert slider_position(ax, again) == 2e-3 == again[2]


def test_characterise_equals_closed_form():
    f = np.array([0.5, 2.0, 10.0, 47.0, 200.0])
    m = dynamic_stiffness(_axis(), f, [1e-3])
    ref = _K(2 * np.pi * f)
    assert np.max(np.abs(m.K[0, 0] - ref) / np.abs(ref)) < 1e-10
    # beside friction the branches add their closed form to the friction loop's
    fr = dict(law="piecewise", k2=4e5, delta=0.01, friction=True, kf=6e4, n0=40.0)
    with_b = dynamic_stiffness(_axis(**fr), f, [3e-3]).K[0, 0]
    without = dynamic_stiffness(_axis(**fr, maxwell_k1=0.0, maxwell_k2=0.0), f,
                                [3e-3]).K[0, 0]
    branches = _K(2 * np.pi * f) - K1 - 1j * 2 * np.pi * f * C
    assert np.max(np.abs(with_b - without - branches) / np.abs(with_b)) < 1e-10


@pytest.mark.parametrize("kind", ["force", "base"])
def test_hbm_equals_exact_frf(kind):
    amp = F0 if kind == "force" else 1e-3
    r = frequency_response(_system(kind, amp), 1.0, 40.0, harmonics=3)
    assert r.success
    w = 2 * np.pi * r.freq_hz
    K = _K(w)
    if kind == "force":
        X = amp / (K - w * w * M)
    else:   # engine over chassis displacement
        X = K * amp / (K - w * w * M)
    A = r.amplitude[:, 0]
    err = np.max(np.abs(A - np.abs(X)) / np.abs(X))
    assert err < 1e-10, err
    # the higher harmonics of a linear system vanish
    assert np.max(np.abs(r.coefficients[:, 0, 3:])) < 1e-12 * np.max(np.abs(X))


def _discrete_frf(f_hz: float, h: float) -> complex:
    """Steady response Q of the master's leapfrog with the velocity predictor (its
    docstring's scheme) on the SDOF, the branches stepped exactly for the linear
    path between samples: the z-transform at z = exp(j omega h)."""
    w = 2 * np.pi * f_hz
    z = np.exp(1j * w * h)
    Kd = 0j
    for k, c in BRANCHES:
        x = h * k / c
        e = math.exp(-x)
        r = -math.expm1(-x) / x
        Kd += k * r * (1 - 1 / z) / (1 - e / z)
    acc = (z - 1) ** 2 / (h * h * z)                      # a_k / q_k
    vel = (z - 1) / (h * z) + (z - 1) ** 2 / (2 * h * z * z)   # v_k / q_k
    return F0 / (M * acc + K1 + C * vel + Kd)


@pytest.mark.parametrize("f_hz", [3.0, 7.0, 15.0])
def test_cosim_equals_exact_frf_of_the_discretised_system(f_hz):
    """The co-simulation (inproc) equals the exact FRF of the discretised system to
    1e-10 (the branches add no error of their own); against the continuous FRF it is
    the leapfrog's second-order error, which the test bounds too."""
    s = _system()
    ss = steady_state(s, f_hz, backend="inproc", steps_per_period=128, rtol=1e-13,
                      max_periods=4000)
    assert ss.converged
    Qd = _discrete_frf(f_hz, ss.dt)
    assert abs(ss.phasor[0] - Qd) / abs(Qd) < 1e-10
    w = 2 * np.pi * f_hz
    Qc = F0 / (_K(w) - w * w * M)
    assert abs(ss.amplitude[0] - abs(Qc)) / abs(Qc) < 2e-3   # (2 pi / 128)^2 order


def test_cosim_converges_at_second_order_to_the_exact_frf():
    w = 2 * np.pi * 7.0
    Qc = F0 / (_K(w) - w * w * M)
    errs = []
    for n in (64, 128, 256):
        ss = steady_state(_system(), 7.0, backend="inproc", steps_per_period=n,
                          rtol=1e-13, max_periods=4000)
        errs.append(abs(ss.phasor[0] - Qc) / abs(Qc))
    assert 3.6 < errs[0] / errs[1] < 4.4 and 3.6 < errs[1] / errs[2] < 4.4, errs


def test_batched_sweep_equals_inproc():
    s = _system()
    rows = steady_states(s, [3.0, 7.0], rtol=1e-12, max_periods=4000)
    for f, r in zip([3.0, 7.0], rows, strict=True):
        one = steady_state(s, f, backend="inproc", rtol=1e-12, max_periods=4000)
        assert abs(r.phasor[0] - one.phasor[0]) <= 1e-13 * abs(one.phasor[0])


def test_static_carries_no_maxwell_force():
    """The engine's weight on the mount: the sag is that of k1 alone (with friction,
    the lowered contact as without branches)."""
    from drymount.hbm.static import StaticStatus, static_equilibrium

    load = np.array([M * 9.81])
    pt = static_equilibrium(_system(), load)
    assert pt.status is StaticStatus.CONVERGED
    assert abs(pt.q[0] - M * 9.81 / K1) < 1e-12 * M * 9.81 / K1
    fr = dict(friction=True, kf=6e4, n0=40.0)
    a = static_equilibrium(_system(axis=_axis(**fr)), load)
    b = static_equilibrium(_system(axis=_axis(**fr, maxwell_k1=0.0, maxwell_k2=0.0)),
                           load)
    assert a.q[0] == b.q[0]
