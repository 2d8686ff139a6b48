"""The AFT Jacobians in harmonic form (issue 27 item 3) against the dense products
they replace, and the vectorised retrace distance against the loop it replaces.

References written here: ``P diag(kt) E`` as the dense product, the Jenkins Jacobian
``P Z`` with ``Z[n] = kt_n E[n] - kt_n [last_n >= 0] E[last_n]`` (the formula of
:func:`hbm.friction_march.jenkins_jacobian`), and a curve traced with both dense
products patched in.
"""

import math

import numpy as np
import pytest

import drymount.hbm as hbm
import drymount.hbm.aft as aft
from drymount.config.loading import load_preset
from drymount.hbm.aft import FourierBasis, aft_forces
from drymount.hbm.continuation import _distance_to_polyline, _polyline
from drymount.hbm.elements import elastic_remainder
from drymount.hbm.friction_march import jenkins_march
from drymount.hbm.problem import build_problem

REL = 1e-12  # relative to the largest entry of the reference


def _dense_gram(basis, kt):
    """``P diag(kt[:, c]) E`` for kt (..., N, C) by the dense product."""
    return (basis.P * np.swapaxes(kt, -1, -2)[..., None, :]) @ basis.E


@pytest.mark.parametrize("H, N", [(1, 3), (2, 5), (3, 7), (5, 16), (7, 64),
                                  (7, 1024), (13, 1024), (13, 27), (4, 100)])
def test_gram_equals_dense_product(H, N):
    b = FourierBasis(H, N)
    rng = np.random.default_rng(H * 1000 + N)
    for kt in (rng.standard_normal((N, 3)), rng.standard_normal((4, 2, N, 5)),
               1e5 * (rng.random((N, 9)) > 0.5)):  # the piecewise tangent's shape
        ref = _dense_gram(b, kt)
        got = b.gram(kt)
        assert got.shape == ref.shape
        assert np.abs(got - ref).max() <= REL * np.abs(ref).max()


def _dense_aft_jacobian(U, ax, basis):
    """The Jacobian of :func:`aft_forces` (elastic remainder plus Jenkins) by dense
    products, with the scan march (NumPy, bit for bit the scalar march)."""
    u = basis.E @ U
    _, kt = elastic_remainder(u, ax)
    dF = _dense_gram(basis, kt)
    fr = ax.friction
    m = jenkins_march(u[..., fr], ax.kf[fr], ax.fs[fr], ax.w_start[fr], backend="scan")
    stuck = np.swapaxes(m.stuck, -1, -2)
    last = np.swapaxes(m.last_slip, -1, -2)
    kj = stuck * ax.kf[fr][:, None]
    back = kj * (last >= 0)
    Z = kj[..., None] * basis.E - back[..., None] * basis.E[np.maximum(last, 0)]
    dF[..., fr, :, :] += basis.P @ Z
    return dF


@pytest.mark.parametrize("name", ["six_dof_halved", "sdof_halved",
                                  "quarter_car_halved"])
@pytest.mark.parametrize("H, N", [(7, 1024), (13, 1024), (5, 64), (3, 7)])
def test_aft_jacobian_equals_dense(name, H, N):
    prob = build_problem(load_preset(name).system, 2.0, 25.0, H, N)
    hb = prob.hb
    X, _ = prob.x_of(prob.linear_guess(9.0, stuck=False))
    U = hb.axis_coefficients(X)
    rng = np.random.default_rng(H + N)
    # a batch of motions from mostly stuck to mostly slipping, with higher harmonics
    Ub = (U[None] * rng.uniform(0.2, 3.0, (4, 1, 1))
          + 1e-3 * rng.standard_normal((4, *U.shape)))
    for UU in (U, Ub):
        ref = _dense_aft_jacobian(UU, hb.axes, hb.basis)
        F, got = aft._aft_harmonic(UU, hb.axes, hb.basis)  # at every N
        assert np.abs(got - ref).max() <= REL * np.abs(ref).max()
        F_dense, dF_dense = aft._aft_dense(UU, hb.axes, hb.basis, True)
        assert np.array_equal(F, F_dense)
        assert np.abs(dF_dense - ref).max() <= REL * np.abs(ref).max()
        _, used = aft_forces(UU, hb.axes, hb.basis)
        assert np.array_equal(used, got if N >= aft.HARMONIC_FROM else dF_dense)


def test_curve_unchanged_by_harmonic_form(monkeypatch):
    """A preset's curve with the harmonic-form Jacobians (N = 1024) equals the one
    with the dense products to 1e-9."""
    system = load_preset("sdof_halved").system
    opts = hbm.HBMOptions(tol=None, stability=False)

    def curve():
        r = hbm.frequency_response(system, 2.0, 15.0, harmonics=7, n_samples=1024,
                                   options=opts)
        assert r.success
        return r

    new = curve()

    def dense_jenkins(U, ax, basis, jacobian):
        u = basis.E @ U
        f, _ = elastic_remainder(u, ax)
        fr = ax.friction
        m = jenkins_march(u[..., fr], ax.kf[fr], ax.fs[fr], ax.w_start[fr])
        f[..., fr] += m.force
        F = basis.P @ f
        return F, (_dense_aft_jacobian(U, ax, basis) if jacobian else None)

    monkeypatch.setattr(aft, "_aft_jenkins", dense_jenkins)
    ref = curve()
    assert len(new.freq_hz) == len(ref.freq_hz)
    for a, b in ((new.freq_hz, ref.freq_hz), (new.coefficients, ref.coefficients)):
        a, b = np.asarray(a), np.asarray(b)
        assert np.abs(a - b).max() <= 1e-9 * np.abs(b).max()


def _loop_distance(p, pts):
    """The retrace distance by a loop over the segments (the former code)."""
    best = math.sqrt(float(np.dot(p - pts[-1], p - pts[-1])))
    seg = 0.0
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        d = b - a
        dd = float(np.dot(d, d))
        s = 0.0 if dd == 0.0 else min(1.0, max(0.0, float(np.dot(p - a, d)) / dd))
        r = p - a - s * d
        dist = math.sqrt(float(np.dot(r, r)))
        if dist < best:
            best, seg = dist, math.sqrt(dd)
    return best, seg


def test_distance_to_polyline_equals_loop():
    rng = np.random.default_rng(7)
    for trial in range(600):
        n, k = int(rng.integers(1, 40)), int(rng.integers(1, 25))
        pts = list(np.cumsum(rng.standard_normal((k, n)), axis=0))
        if trial % 7 == 0 and k > 2:
            pts[1] = pts[0].copy()  # a zero-length segment
        p = rng.standard_normal(n) * 2
        if trial % 3 == 0:  # near a vertex: two segments tie
            p = pts[int(rng.integers(0, k))] + 1e-3 * rng.standard_normal(n)
        elif trial % 5 == 0 and k > 1:  # all but on a segment, far from the origin
            # (the screen's expanded squares cancel to 1e-12 of |p|^2 here)
            shift = 1e3 * rng.standard_normal(n)
            pts = [q + shift for q in pts]
            i = int(rng.integers(0, k - 1))
            p = pts[i] + 0.37 * (pts[i + 1] - pts[i]) + 1e-9 * rng.standard_normal(n)
        assert _distance_to_polyline(p, pts, with_segment=True) == \
            _loop_distance(p, pts)
        assert _distance_to_polyline(p, pts) == _loop_distance(p, pts)[0]
        if k >= 2:   # with the polyline built once (hbm.continuation._retraced)
            assert _distance_to_polyline(p, pts, True, _polyline(pts)) == \
                _loop_distance(p, pts)


def test_retrace_check_rebuilds_its_polyline_when_the_points_change():
    from drymount.hbm.continuation import Branch, _retraced

    # up to the fold at lam = 1 on one curve, back on another 0.5 away
    up = [np.array([np.sin(3 * x), x]) for x in np.linspace(0, 1, 31)]
    back = [np.array([np.sin(3 * x) + 0.5, x]) for x in np.linspace(1, 0.4, 13)[1:]]
    br = Branch(y=up + back[:6], tangent=[None] * 37, jacobian=[None] * 37,
                det_sign=[0.0] * 37, n_iter=[0] * 37, turning_points=[30])
    for _ in range(2):   # the second time with the polyline kept
        assert not _retraced(br)
    # the old part changes (new point objects onto the way back): seen at once
    br.y[:28] = [y + [0.5, 0.0] for y in br.y[:28]]
    assert _retraced(br) and br.status.value == "retraced"
