"""The HBM's array wrappers over the mount law equal the scalar law
(fmu_src.mount_law)."""

import math

import numpy as np
import pytest

from drymount.fmu_src.mount_law import (AxisParameters, MountParameters, axis_force,
                               elastic_force, jenkins_update)
from drymount.hbm.elements import elastic_remainder, jenkins_periodic, nonlinear_axes
from drymount.hbm.systems import sdof

ATOL_LAW = 1e-9  # N; vectorised vs scalar law: same operations, measured 0 to 2e-12
RTOL_ENERGY = 1e-12  # loop energy from samples vs 4 Fs (X - eps): exact at samples

LAWS = {
    "cubic": AxisParameters(law="cubic", k1=34770.0, kc=5.708e8),
    "piecewise": AxisParameters(law="piecewise"),
    "piecewise_asym": AxisParameters(law="piecewise_asym", delta=0.01,
                                     delta_neg=0.005),
}


def _axes(p):
    return nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 1.0))


@pytest.mark.parametrize("name", sorted(LAWS))
def test_elastic_remainder_equals_scalar_law(name):
    p = LAWS[name]
    ax = _axes(p)
    u = np.linspace(-0.03, 0.03, 2001)[:, None]
    f, kt = elastic_remainder(u, ax)
    for i in range(u.shape[0]):
        fe, ke = elastic_force(float(u[i, 0]), p)
        assert abs(p.k1 * u[i, 0] + f[i, 0] - fe) <= ATOL_LAW
        assert abs(p.k1 + kt[i, 0] - ke) <= ATOL_LAW


def test_linear_law_has_no_nonlinear_axis():
    assert _axes(AxisParameters(law="linear")).n == 0
    assert _axes(AxisParameters(law="linear", friction=True, n0=5.0)).n == 1


@pytest.mark.parametrize("amp", [1e-3, 3.2e-4, 2e-4, 1e-4])  # slipping ... stuck
def test_jenkins_periodic_equals_marching_the_law(amp):
    kf, fs = 60000.0, 20.0  # eps = 3.3e-4
    th = 2 * np.pi * np.arange(256) / 256
    u = amp * np.sin(th) + 0.3 * amp * np.cos(3 * th) + 2e-4
    f, stuck, last = jenkins_periodic(u, kf, fs)
    # reference: march the scalar law three periods, keep the last one
    w = 0.0
    out = []
    for _ in range(3):
        out = []
        for x in u:
            ff, w, _, _ = jenkins_update(float(x), w, kf, fs)
            out.append(ff)
    np.testing.assert_allclose(f, out, rtol=0, atol=1e-12)
    # at stuck samples the slider position is u[last] -+ eps
    eps = fs / kf
    for n in np.flatnonzero(stuck & (last >= 0)):
        w_n = u[n] - f[n] / kf
        assert min(abs(w_n - (u[last[n]] - eps)), abs(w_n - (u[last[n]] + eps))) < 1e-15


def test_jenkins_loop_energy_is_4fs_x_minus_eps():
    """Dissipation per cycle of the periodic loop = 4 Fs (X - eps) (PHYSICS.md s. 1).

    The slider position is ``w = u - F/kf``; the slider dissipates ``Fs |dw|``. With
    N a multiple of 4 the extrema are samples, so the sampled sum is exact.
    """
    kf, fs, X = 60000.0, 20.0, 2e-3
    N = 256
    u = X * np.sin(2 * np.pi * np.arange(N) / N)
    f, _, _ = jenkins_periodic(u, kf, fs)
    w = u - f / kf
    energy = fs * float(np.abs(np.diff(np.append(w, w[0]))).sum())
    assert energy == pytest.approx(4 * fs * (X - fs / kf), rel=RTOL_ENERGY)


def test_axis_force_decomposition():
    """k1 u + c v + remainder + Jenkins == mount_law.axis_force along a path."""
    p = AxisParameters(law="piecewise", friction=True, n0=40.0)
    ax = _axes(p)
    t = np.linspace(0, 1, 501)
    u = 0.02 * np.sin(2 * np.pi * 2 * t) * np.exp(-t)
    v = np.gradient(u, t)
    f_nl, _ = elastic_remainder(u[:, None], ax)
    w = 0.0
    for i in range(t.size):
        F, f_fr, w_new, _, _, _ = axis_force(float(u[i]), float(v[i]), w, p)
        ff, w2, _, _ = jenkins_update(float(u[i]), w, p.kf, p.fs)
        assert math.isclose(F, p.k1 * u[i] + p.c * v[i] + f_nl[i, 0] + ff,
                            rel_tol=0, abs_tol=ATOL_LAW)
        assert w2 == w_new
        w = w_new


def test_every_law_has_hbm_forms_looked_up_by_name():
    """Each law of the fmu_src registry has its HBM forms in hbm.laws; an unknown
    name fails with a message that says where to add it."""
    from drymount.fmu_src.mount_law import ELASTIC_LAWS
    from drymount.hbm.laws import HBM_LAWS, hbm_law

    assert set(HBM_LAWS) == set(ELASTIC_LAWS)
    with pytest.raises(KeyError, match="hbm.laws.HBM_LAWS"):
        hbm_law("quintic")
