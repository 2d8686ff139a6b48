"""The mount law (fmu_src.mount_law) against closed forms and independent checks.

References: the Jenkins loop dissipates 4 Fs (X - eps) per cycle, eps = Fs / kf, for
X > eps and nothing below (thesis eq. 2.10-2.13, Fig. 3.4); the piecewise laws are
continuous at their knees (eq. 2.15-2.20, 3.30); the symmetric laws are odd; the
tangents equal finite differences of the forces.
"""

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import (
    ELASTIC_LAWS,
    LAWS,
    AxisParameters,
    ElasticLaw,
    MountParameters,
    ParameterError,
    axis_force,
    elastic_force,
    jenkins_update,
    law_code,
    law_name,
)

KF, FS = 60000.0, 100.0  # contact stiffness N/m, slip force N
EPS = FS / KF  # slip displacement, m (thesis eq. 2.13)
N_PER_CYCLE = 4000  # samples per cycle, a multiple of 4 so the turning points are hit

# Summing Fs |dw| is exact when the samples hit the turning points (the return map is
# exact for monotonic increments): only rounding remains.
RTOL_ENERGY_SUM = 1e-12  # measured <= 2.2e-16
# The loop-area integral of F du by the trapezoidal rule misses O(du^2) at the two
# stick/slip corners per half cycle: measured 5.6e-7 relative at 4000 samples per cycle
# (X = 1.5 and 3 eps; 2.8e-7 at 20 eps), 5x margin.
RTOL_LOOP_AREA = 3e-6
# Finite differences: central, step 1e-9 m on forces ~1e3 N: truncation is zero for
# the piecewise-linear laws and ~kc h^2 for the cubic one; rounding ~1e-16 F / h.
RTOL_FD = 1e-6


def _sine_march(amplitude, n_cycles=3, law_params=None):
    """March the friction element of one axis along u = X sin(theta).

    Returns the last cycle's samples: u (N + 1,), friction force (N + 1,), total force,
    and the energies Fs |dw| per step (N,).
    """
    p = law_params or AxisParameters(law="linear", k1=0.0, c=0.0, friction=True,
                                     kf=KF, mu=1.0, n0=FS)
    theta = 2.0 * np.pi * np.arange(n_cycles * N_PER_CYCLE + 1) / N_PER_CYCLE
    u = amplitude * np.sin(theta)
    w = 0.0
    f_tot, f_fr, diss = [], [], []
    for uk in u:
        force, friction, w, _, _, dissipated = axis_force(float(uk), 0.0, w, p)
        f_tot.append(force)
        f_fr.append(friction)
        diss.append(dissipated)
    last = slice((n_cycles - 1) * N_PER_CYCLE, None)
    return (u[last], np.array(f_fr)[last], np.array(f_tot)[last],
            np.array(diss)[last][1:])


@pytest.mark.parametrize("ratio", [1.5, 3.0, 20.0])
def test_jenkins_loop_energy_above_slip(ratio):
    amplitude = ratio * EPS
    u, f_fr, f_tot, diss = _sine_march(amplitude)
    expected = 4.0 * FS * (amplitude - EPS)
    assert diss.sum() == pytest.approx(expected, rel=RTOL_ENERGY_SUM)
    area = float(np.sum(0.5 * (f_fr[1:] + f_fr[:-1]) * np.diff(u)))
    # closed integral of F du along the loop (positive = dissipated)
    assert area == pytest.approx(expected, rel=RTOL_LOOP_AREA)
    # the friction force is bounded by the slip force and reaches it
    assert np.max(np.abs(f_fr)) == pytest.approx(FS, rel=1e-15)


@pytest.mark.parametrize("ratio", [0.2, 0.999])
def test_jenkins_loop_no_energy_below_slip(ratio):
    u, f_fr, _, diss = _sine_march(ratio * EPS)
    assert np.all(diss == 0.0)
    area = float(np.sum(0.5 * (f_fr[1:] + f_fr[:-1]) * np.diff(u)))
    assert abs(area) <= 1e-12 * FS * EPS
    np.testing.assert_allclose(f_fr, KF * u, rtol=0, atol=1e-12 * FS)


def test_loop_area_with_elastic_law():
    # an elastic law stores and returns energy: the loop area of the total force is
    # the friction loop's alone
    p = AxisParameters(law="piecewise", k1=91870.0, k2=513800.0, delta=0.004, c=0.0,
                       friction=True, kf=KF, mu=2.0, n0=FS / 2.0)
    amplitude = 0.01
    u, _, f_tot, diss = _sine_march(amplitude, law_params=p)
    expected = 4.0 * FS * (amplitude - EPS)
    area = float(np.sum(0.5 * (f_tot[1:] + f_tot[:-1]) * np.diff(u)))
    assert area == pytest.approx(expected, rel=RTOL_LOOP_AREA)
    assert diss.sum() == pytest.approx(expected, rel=RTOL_ENERGY_SUM)


def _knee_jump(law, knee, **kw):
    p = AxisParameters(law=law, **kw)
    below = elastic_force(math.nextafter(knee, -math.inf), p)
    above = elastic_force(math.nextafter(knee, math.inf), p)
    at = elastic_force(knee, p)
    return below, at, above, p


@pytest.mark.parametrize("law,knee_attr,sign", [
    ("piecewise", "delta", 1), ("piecewise", "delta", -1),
    ("piecewise_asym", "delta", 1), ("piecewise_asym", "delta_neg", -1),
])
def test_piecewise_continuous_at_knees(law, knee_attr, sign):
    kw = dict(k1=91870.0, k2=513800.0, delta=0.01225, delta_neg=0.007)
    knee = sign * kw[knee_attr]
    (f_lo, k_lo), (f_at, _), (f_hi, k_hi), p = _knee_jump(law, knee, **kw)
    # two ulps of u times the stiffer slope, plus rounding of F
    bound = p.k2 * 2.0 * math.ulp(abs(knee)) + 4.0 * math.ulp(abs(f_at))
    assert abs(f_hi - f_lo) <= bound
    assert abs(f_at - f_lo) <= bound
    # the slope changes exactly at the knee: k1 inside, k2 outside
    inner, outer = (k_lo, k_hi) if sign > 0 else (k_hi, k_lo)
    assert (inner, outer) == (p.k1, p.k2)


def test_asymmetric_knees_are_where_declared():
    p = AxisParameters(law="piecewise_asym", k1=1e4, k2=5e4, delta=0.01,
                       delta_neg=0.004)
    assert elastic_force(-0.005, p)[1] == p.k2  # beyond -delta_neg
    assert elastic_force(0.005, p)[1] == p.k1  # inside +delta
    # F(-0.02) = k1 u + (k2 - k1)(u + delta_neg)
    assert elastic_force(-0.02, p)[0] == pytest.approx(
        1e4 * -0.02 + 4e4 * (-0.02 + 0.004), rel=1e-15)
    # and therefore not odd
    assert elastic_force(-0.02, p)[0] != -elastic_force(0.02, p)[0]


@pytest.mark.parametrize("law", ["linear", "cubic", "piecewise"])
def test_symmetric_laws_are_odd(law):
    p = AxisParameters(law=law, k1=34770.0, kc=5.708e8, k2=513800.0, delta=0.01225)
    for u in np.linspace(0.0, 0.05, 201):
        f_pos, k_pos = elastic_force(float(u), p)
        f_neg, k_neg = elastic_force(float(-u), p)
        assert f_neg == -f_pos and k_neg == k_pos
    # the Jenkins element is odd too: mirrored motion, mirrored slider and force
    for u, w in [(0.003, 0.0), (-0.001, 0.0005), (0.01, -0.002)]:
        f1, w1, k1, s1 = jenkins_update(u, w, KF, FS)
        f2, w2, k2, s2 = jenkins_update(-u, -w, KF, FS)
        assert (f2, w2, k2, s2) == (-f1, -w1, k1, s1)


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("friction", [False, True])
def test_tangent_stiffness_matches_finite_differences(law, friction):
    p = AxisParameters(law=law, k1=34770.0, kc=5.708e8, k2=513800.0, delta=0.01225,
                       delta_neg=0.008, c=150.0, friction=friction, kf=KF, mu=1.0,
                       n0=FS)
    rng = np.random.default_rng(7)
    h = 1e-9
    checked = 0
    for u in rng.uniform(-0.03, 0.03, 200):
        w = float(u + rng.uniform(-2.5, 2.5) * EPS)  # stuck or slipping
        u = float(u)
        if abs(abs(u) - p.delta) < 10 * h or abs(u + p.delta_neg) < 10 * h:
            continue  # kink of the elastic law inside the stencil
        if friction and abs(abs(KF * (u - w)) - FS) < 10 * h * KF:
            continue  # stick/slip switch inside the stencil
        f_hi = axis_force(u + h, 0.3, w, p)[0]
        f_lo = axis_force(u - h, 0.3, w, p)[0]
        kt = axis_force(u, 0.3, w, p)[3]
        fd = (f_hi - f_lo) / (2.0 * h)
        assert fd == pytest.approx(kt, rel=RTOL_FD, abs=RTOL_FD * p.k2)
        checked += 1
    assert checked > 150
    # damping tangent dF/dv = c
    u, w = 0.002, 0.0
    dv = (axis_force(u, 1.0, w, p)[0] - axis_force(u, -1.0, w, p)[0]) / 2.0
    assert dv == pytest.approx(p.c, rel=1e-9)


def test_axis_force_without_friction_ignores_slider():
    p = AxisParameters(law="linear", k1=1e4, c=10.0)
    assert axis_force(0.01, 0.2, 0.5, p) == (1e4 * 0.01 + 10.0 * 0.2, 0.0, 0.5, 1e4,
                                               False, 0.0)


def test_from_axial_scales_radial_axes():
    mp = MountParameters.from_axial(
        AxisParameters(friction=True, n0=50.0), lam=1.2, friction_axes=("axial",
                                                                        "radial2"))
    assert mp.radial1.k1 == pytest.approx(1.2 * mp.axial.k1, rel=1e-15)
    assert not mp.radial1.friction and mp.radial2.friction


def test_registry_maps_fmu_codes_to_names_and_back():
    assert LAWS == tuple(ELASTIC_LAWS) == ("linear", "cubic", "piecewise",
                                           "piecewise_asym")
    for code, name in enumerate(LAWS):
        assert law_code(name) == code and law_name(code) == name
    for bad in (-1, len(LAWS), True, 1.0, "cubic", None):
        assert law_name(bad) is None
    assert all(isinstance(law, ElasticLaw) for law in ELASTIC_LAWS.values())


def test_piecewise_knees_follow_the_law():
    """The symmetric law ignores delta_neg (its knees are +-delta); the asymmetric
    one has its negative knee at -delta_neg. Regression: hbm/reference.py used
    delta_neg for the symmetric law."""
    kw = dict(k1=1e4, k2=5e4, delta=0.01, delta_neg=0.004)
    sym = AxisParameters(law="piecewise", **kw)
    asym = AxisParameters(law="piecewise_asym", **kw)
    assert sym.elastic.knees(sym) == (0.01, -0.01)
    assert asym.elastic.knees(asym) == (0.01, -0.004)
    assert elastic_force(-0.005, sym)[1] == sym.k1
    assert elastic_force(-0.005, asym)[1] == asym.k2


def test_normal_force_input_and_energy_nonnegative():
    """The normal-force input n = 160 N replaces n0: Fs = mu n = 80 N."""
    p = AxisParameters(law="linear", k1=0.0, friction=True, kf=KF, mu=0.5, n0=10.0)
    w = 0.0
    rng = np.random.default_rng(3)
    for u in rng.uniform(-0.01, 0.01, 500):
        f, ffr, w_new, _, _, diss = axis_force(float(u), 0.0, w, p, n=160.0)
        assert abs(ffr) <= 80.0 and diss >= 0.0
        assert diss == pytest.approx(80.0 * abs(w_new - w), rel=1e-15)
        w = w_new


@pytest.mark.parametrize("kwargs,message", [
    (dict(k1=-1.0), "`k1` must be finite and >= 0, got -1.0"),
    (dict(friction=True, kf=0.0),
     "`kf` must be finite and > 0 when friction is on, got 0.0"),
    (dict(delta=float("nan")), "`delta` must be finite and > 0, got nan"),
    (dict(law="quartic"), "`law` must be one of linear, cubic, piecewise, "
                          "piecewise_asym, got 'quartic'"),
    (dict(n0=-3.0), "`n0` must be finite and >= 0, got -3.0"),
])
def test_parameter_errors_name_field_and_value(kwargs, message):
    with pytest.raises(ParameterError) as info:
        AxisParameters(**kwargs)
    assert message in str(info.value)
    assert info.value.problems == [message]


def test_parameter_errors_are_collected():
    with pytest.raises(ParameterError) as info:
        AxisParameters(k1=-1.0, c=float("inf"), mu=-0.1)
    assert len(info.value.problems) == 3
    p = AxisParameters()
    assert p.problems("axial_") == []
