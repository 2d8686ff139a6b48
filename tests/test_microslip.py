"""Micro-slip (Iwan) and non-symmetric friction of fmu_src.mount_law vs closed forms.

References: the Iwan backbone of the uniform slip-displacement fit (sum of clipped
springs, and its continuum limit), Masing's rules for unloading/reloading branches,
the Masing loop energy 8 int_0^A F_bb - 4 A F_bb(A), and the non-symmetric Jenkins
loop energy (Fp + Fn) (2 A - (Fp + Fn) / kf).
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from drymount.fmu_src.mount_law import (AxisParameters, ParameterError, axis_force,
                               initial_sliders, jenkins_update, mean_slider,
                               slider_bank)

#: exact arithmetic paths (same operations in a different order): measured <= 3e-16
EXACT = 1e-12
#: loop area by the trapezoid rule on 20 001 samples vs the closed form: measured 1.3e-8
AREA = 1e-6
#: 64-slider midpoint fit vs the continuum uniform distribution: measured 4.9e-5 (of Fs)
CONTINUUM = 1e-4

KF, FS = 60000.0, 120.0
EPS = FS / KF


def _axis(**kw) -> AxisParameters:
    base = dict(law="linear", k1=0.0, c=0.0, friction=True, kf=KF, mu=1.0, n0=FS)
    base.update(kw)
    return AxisParameters(**base)


def _march(p, us):
    w = initial_sliders(p)
    f, e = [], 0.0
    for u in us:
        r = axis_force(u, 0.0, w, p)
        w = r.w_new
        f.append(r.friction_force)
        e += r.dissipated
    return np.array(f), e, w


def _backbone(u, p):
    """Iwan backbone: sum over sliders of k_i min(u, eps_i), eps_i = eps r_i."""
    s, n = p.spread, p.sliders
    r = 1.0 + s * ((2 * np.arange(n) + 1) / n - 1.0)
    return (KF / n) * np.minimum(np.asarray(u)[..., None], EPS * r).sum(-1)


def _backbone_integral(a, p):
    """int_0^a F_bb(s) ds in closed form."""
    s, n = p.spread, p.sliders
    out = 0.0
    for i in range(n):
        e = EPS * (1.0 + s * ((2 * i + 1) / n - 1.0))
        k = KF / n
        out += k * a * a / 2 if a <= e else k * (e * e / 2 + e * (a - e))
    return out


def test_spread_zero_is_jenkins_and_general_path_matches():
    rng = random.Random(3)
    us = [0.0]
    for _ in range(400):
        us.append(us[-1] + rng.gauss(0.0, 0.6 * EPS))
    for p in (_axis(sliders=7, spread=0.0), _axis(fs_ratio=1.0 + 0.0)):
        f, _, _ = _march(p, us)
        w, ref = 0.0, []
        for u in us:
            r = jenkins_update(u, w, KF, FS)
            w = r.w_new
            ref.append(r.force)
        assert np.max(np.abs(f - ref)) <= EXACT * FS


@pytest.mark.parametrize("sliders,spread", [(5, 0.6), (64, 0.9)])
def test_iwan_backbone_and_masing_branches(sliders, spread):
    p = _axis(sliders=sliders, spread=spread)
    amp = 2.5 * EPS
    up = np.linspace(0.0, amp, 801)
    down = np.linspace(amp, -amp, 1601)
    reload = np.linspace(-amp, amp, 1601)
    f, _, _ = _march(p, np.concatenate([up, down, reload]))
    fb, fd, fr = f[:801], f[801:2402], f[2402:]
    assert np.max(np.abs(fb - _backbone(up, p))) <= EXACT * FS
    top = _backbone(amp, p)
    masing_down = top - 2.0 * _backbone((amp - down) / 2.0, p)
    masing_up = -top + 2.0 * _backbone((reload + amp) / 2.0, p)
    assert np.max(np.abs(fd - masing_down)) <= EXACT * FS
    assert np.max(np.abs(fr - masing_up)) <= EXACT * FS
    # total stiffness kf at the origin, full-slip force Fs beyond (1 + spread) eps
    assert fb[1] / up[1] == pytest.approx(KF, rel=EXACT)
    assert top == pytest.approx(FS, rel=EXACT)


def test_iwan_backbone_continuum_limit():
    s = 0.8
    p = _axis(sliders=64, spread=s)
    a, b = EPS * (1 - s), EPS * (1 + s)
    u = np.linspace(0.0, 1.2 * b, 2001)
    cont = np.where(u < a, KF * u,
                    np.where(u < b, KF * (u - (u - a) ** 2 / (2 * (b - a))), FS))
    assert np.max(np.abs(_backbone(u, p) - cont)) <= CONTINUUM * FS
    f, _, _ = _march(p, u)
    assert np.max(np.abs(f - cont)) <= CONTINUUM * FS


@pytest.mark.parametrize("amp_eps", [0.7, 1.3, 3.0])
def test_iwan_loop_energy_masing_closed_form(amp_eps):
    p = _axis(sliders=9, spread=0.5)
    amp = amp_eps * EPS
    th = np.linspace(0.0, 2 * math.pi, 20001)
    u = amp * np.cos(th)
    # first cycle from the origin reaches the loop; measure the second one
    _, _, w = _march(p, np.concatenate([np.linspace(0, amp, 200), u]))
    r_f, r_e, w2 = [], 0.0, w
    for x in u:
        r = axis_force(float(x), 0.0, w2, p)
        w2 = r.w_new
        r_f.append(r.friction_force)
        r_e += r.dissipated
    closed = 8.0 * _backbone_integral(amp, p) - 4.0 * amp * _backbone(amp, p)
    assert r_e == pytest.approx(closed, rel=EXACT, abs=EXACT * FS * EPS)
    area = np.trapezoid(r_f, u)  # work of the friction force around the loop
    assert area == pytest.approx(closed, rel=AREA, abs=AREA * FS * EPS)
    assert mean_slider(w2) == pytest.approx(mean_slider(w), abs=EXACT * EPS)


@pytest.mark.parametrize("ratio", [0.4, 1.0, 2.5])
def test_non_symmetric_jenkins_loop(ratio):
    p = _axis(fs_ratio=ratio)
    fp, fn = FS, FS * ratio
    amp = 3.0 * EPS * max(1.0, ratio)
    th = np.linspace(0.0, 4 * math.pi, 40001)
    u = amp * np.sin(th)
    f, _, _ = _march(p, u)
    half = len(u) // 2
    _, e2, _ = _march(p, u[:half + 1])
    _, e_all, _ = _march(p, u)
    cycle = e_all - e2  # second period
    assert cycle == pytest.approx((fp + fn) * (2 * amp - (fp + fn) / KF), rel=EXACT)
    assert f.max() == pytest.approx(fp, rel=EXACT)
    assert f.min() == pytest.approx(-fn, rel=EXACT)


def test_non_symmetric_iwan_bank_and_energy():
    p = _axis(sliders=6, spread=0.4, fs_ratio=0.5)
    bank = slider_bank(p)
    assert sum(k for k, _, _ in bank) == pytest.approx(KF, rel=EXACT)
    assert sum(fp for _, fp, _ in bank) == pytest.approx(FS, rel=EXACT)
    assert sum(fn for _, _, fn in bank) == pytest.approx(0.5 * FS, rel=EXACT)
    amp = 4.0 * EPS
    u = amp * np.sin(np.linspace(0.0, 4 * math.pi, 40001))
    _, e_all, _ = _march(p, u)
    _, e1, _ = _march(p, u[:20001])
    # every slider slips both ways: the sum of its non-symmetric Jenkins loops
    closed = sum((fp + fn) * (2 * amp - (fp + fn) / k) for k, fp, fn in bank)
    assert e_all - e1 == pytest.approx(closed, rel=EXACT)


def test_parameter_errors_name_field_value_and_rule():
    with pytest.raises(ParameterError) as err:
        _axis(sliders=65, spread=-0.1, fs_ratio=math.nan)
    text = str(err.value)
    assert "`sliders` must be an integer from 1 to 64" in text and "got 65" in text
    assert "`spread` must be finite and in [0, 1)" in text and "got -0.1" in text
    assert "`fs_ratio` must be finite and >= 0, got nan" in text


# ------------------------------------------------------------------ HBM (AFT) forms
@pytest.mark.parametrize("kw", [dict(sliders=6, spread=0.7),
                                dict(fs_ratio=0.35),
                                dict(sliders=4, spread=0.5, fs_ratio=2.0)])
def test_aft_friction_equals_the_law_marched_to_its_periodic_state(kw):
    """The AFT friction force of a micro-slip / non-symmetric axis equals the law
    (axis_force) marched over the same samples until periodic."""
    from drymount.fmu_src.mount_law import MountParameters
    from drymount.hbm.aft import FourierBasis, aft_forces
    from drymount.hbm.systems import sdof

    p = _axis(**kw)
    ax = nonlinear_axes_of(sdof(70.0, MountParameters(axial=p), "force", 1.0))
    H, N = 5, 128
    b = FourierBasis(H, N)
    U = np.zeros((2 * H + 1, 1))
    U[1], U[2], U[5] = 1.6 * EPS, 0.9 * EPS, 0.3 * EPS
    U[0] = 0.2 * EPS
    F, _ = aft_forces(U, ax, b, jacobian=False)
    u = (b.E @ U)[:, 0]
    f, _, w = _march(p, u.tolist() * 3)  # two periods settle, keep the third
    ref = b.P @ f[-N:]
    assert np.max(np.abs(F[:, 0] - ref)) <= EXACT * FS


def nonlinear_axes_of(system):
    from drymount.hbm.elements import nonlinear_axes
    return nonlinear_axes(system)
