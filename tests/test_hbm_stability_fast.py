"""Hill stability without a dense eigenvalue problem at every point, against the dense
problem at every point (the reference, ``hbm.stability.is_stable``) on real branches:
the Floquet exponents by shift-invert Arnoldi (``hbm.hill_arnoldi``) and the schedule
of evaluations along a curve (``hbm.stability_schedule``)."""

import numpy as np
import pytest

import drymount.hbm as hbm
import drymount.hbm.postprocess as pp
from drymount.config import resolve_config
from drymount.validation import CASES
from drymount.hbm.analysis import _trace
from drymount.hbm.continuation import _tangent
from drymount.hbm.hill_arnoldi import MIN_SIZE, TOL, TOL_TIGHT, central_eigenvalues
from drymount.hbm.problem import build_problem
from drymount.hbm.stability import Method, hill_eigenvalues, hill_verdict, stability_of
from drymount.hbm.stability_schedule import _det_sign, _stability

#: Found eigenvalues against the nearest dense one, relative to their modulus: the
#: selected (the Floquet exponents, smallest imaginary parts; measured 7e-11 over this
#: file's branches) and all found (ARPACK at hbm.hill_arnoldi.TOL = 1e-6 bounds the
#: Ritz residual, the outermost converge least; measured 4e-6).
EIG_RTOL = 1e-8
EIG_RTOL_ALL = 1e-4
#: Largest real part of the exponents, Arnoldi against dense, relative to omega
#: (measured 7e-14 over the 6-DOF presets at H = 7).
MAX_REAL_RTOL = 1e-9


def _jacobian(prob, br, i):
    return br.jacobian[i][:, :-1] * (prob.rs / prob.xs), prob.x_of(br.y[i])[1]


def _solved(preset, freqs, H, monkeypatch):
    """(prob, branch) of Newton solutions at ``freqs`` (hbm.solve_frequencies)."""
    got = {}
    orig = pp._stability

    def keep(prob, ys, br, stride):
        br.y = list(ys)
        got["pb"] = prob, br
        return orig(prob, ys, br, stride)

    monkeypatch.setattr(pp, "_stability", keep)
    hbm.solve_frequencies(resolve_config(preset).system, freqs, harmonics=H,
                          options=hbm.HBMOptions(tol=None))
    return got["pb"]


def _traced(preset, f0, f1, H, N=None):
    """(prob, branch) of the continuation from f0 to f1 Hz, without stability."""
    prob = build_problem(resolve_config(preset).system, f0, f1, H, N, None)
    _, br = _trace(prob, f0, f1, hbm.HBMOptions(tol=None, stability=False), False)
    return prob, br


def _check_arnoldi(prob, br, every=1):
    """Arnoldi's eigenvalues are dense ones, include every dense eigenvalue of smaller
    modulus than the largest found, and give the dense verdict at every ``every``-th
    point. Returns the number of unstable points checked."""
    n_unstable = 0
    for i in range(0, len(br.y), every):
        J, w = _jacobian(prob, br, i)
        dense = hill_eigenvalues(prob.hb, J, w)
        lam = central_eigenvalues(prob.hb, J, w)
        assert lam is not None  # measured: no fallback on the 6-DOF presets
        near = np.min(np.abs(lam[:, None] - dense[None, :]), axis=1) / np.abs(lam)
        sel = np.argsort(np.abs(lam.imag), kind="stable")[:2 * prob.hb.n]
        assert np.all(near[sel] <= EIG_RTOL)
        assert np.all(near <= EIG_RTOL_ALL)
        inside = dense[np.abs(dense) < np.max(np.abs(lam)) * (1 - 1e-6)]
        assert len(inside) <= len(lam)
        ref, got = stability_of(dense, prob.hb.n, w), hill_verdict(prob.hb, J, w)
        assert got.method is Method.ARNOLDI
        assert got.stable == ref.stable
        assert abs(got.max_real - ref.max_real) <= MAX_REAL_RTOL * w
        n_unstable += not ref.stable
    return n_unstable


def test_arnoldi_equals_dense_six_dof_h7(monkeypatch):
    """six_dof_halved, H = 7 (Hill's matrix 180 x 180), Newton solutions at 3-12 Hz
    (stable but one)."""
    prob, br = _solved("six_dof_halved", np.linspace(3.0, 12.0, 10), 7, monkeypatch)
    assert 2 * prob.hb.m * prob.hb.n >= MIN_SIZE
    _check_arnoldi(prob, br)


def test_arnoldi_equals_dense_six_dof_branch():
    """six_dof_halved, H = 5 (132 x 132), every 4th point of the branch over 5-10.5 Hz:
    a complex pair crossing and a fold, about 60 % of the points unstable."""
    prob, br = _traced("six_dof_halved", 5.0, 10.5, 5)
    assert _check_arnoldi(prob, br, every=4) > 40  # measured 72 of 123


def test_small_matrices_stay_dense(monkeypatch):
    prob, br = _solved("sdof_halved", [5.0, 8.0], 7, monkeypatch)
    J, w = _jacobian(prob, br, 0)
    assert central_eigenvalues(prob.hb, J, w) is None
    assert hill_verdict(prob.hb, J, w).method is Method.DENSE


def _schedule_equals_every_point(prob, br):
    ref, fmr_ref = _stability(prob, br.y, br, 1, dense=True)
    got, fmr = _stability(prob, br.y, br, hbm.HBMOptions().stability_stride)
    np.testing.assert_array_equal(got, ref)
    done = np.isfinite(fmr)
    np.testing.assert_allclose(fmr[done], fmr_ref[done], rtol=0, atol=1e-9 * np.max(
        np.abs(fmr_ref[done])))
    return int(np.sum(~ref)), int(np.sum(done))


_SMALL = [c for c in CASES if c.preset in ("sdof_halved", "quarter_car_halved",
                                           "sdof_cubic", "sdof_microslip")]


@pytest.mark.parametrize("case", _SMALL, ids=[c.name for c in _SMALL])
def test_schedule_equals_every_point_validation_cases(case):
    """The `drymount validate` cases with one or two DOFs over their band at their H:
    the default schedule gives the verdict of the dense problem at every point."""
    prob, br = _traced(case.preset, case.fmin_hz, case.fmax_hz, case.harmonics,
                       case.n_samples)
    _schedule_equals_every_point(prob, br)


@pytest.mark.slow
def test_schedule_equals_every_point_six_dof_case():
    """six_dof_friction (3-18 Hz, H = 7, N = 256) and six_dof_halved at H = 5 over
    5-10.5 Hz (its two changes of verdict): the default schedule and Arnoldi at every
    point give the dense verdicts."""
    (case,) = [c for c in CASES if c.name == "six_dof_friction"]
    for args in ((case.preset, case.fmin_hz, case.fmax_hz, case.harmonics,
                  case.n_samples), ("six_dof_halved", 5.0, 10.5, 5)):
        prob, br = _traced(*args)
        n_unstable, _ = _schedule_equals_every_point(prob, br)
        assert _check_arnoldi(prob, br) == n_unstable
    assert n_unstable > 100  # measured 289 of 492 (H = 5, 5-10.5 Hz)


def test_tangent_gives_the_sign_of_det_jx():
    """The continuation's tangent solve of ``[J; previous]`` gives sign det J_x by
    Cramer's rule: against numpy's slogdet on random bordered systems."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        J = rng.standard_normal((7, 8))
        tg = _tangent(J, rng.standard_normal(8))
        assert tg is not None
        assert tg.det_sign == np.linalg.slogdet(J[:, :-1])[0]
        np.testing.assert_allclose(J @ tg.t, 0.0, atol=1e-12)


def test_branch_records_det_sign_at_every_point():
    """Every point of a traced branch with folds (six_dof_halved, H = 5, 5-10.5 Hz;
    its fold pieces re-traced and spliced) carries the sign of det dR/dx of its stored
    Jacobian, equal to the LU's; the schedule takes it instead of factorizing."""
    prob, br = _traced("six_dof_halved", 5.0, 10.5, 5)
    lu = [_det_sign(J[:, :-1]) for J in br.jacobian]
    assert len(br.det_sign) == len(br.y) == len(lu)
    np.testing.assert_array_equal(br.det_sign, lu)
    assert len(set(lu)) == 2  # measured: the sign changes at both folds


def test_verdict_near_the_threshold_is_solved_again_tightly(monkeypatch):
    """Within GUARD times ARPACK's loose bound of the threshold, hill_verdict solves
    again at TOL_TIGHT; its verdict is the dense one on either side of the threshold."""
    import drymount.hbm.stability as stab
    prob, br = _solved("six_dof_halved", [6.0], 7, monkeypatch)
    J, w = _jacobian(prob, br, 0)
    ref = stability_of(hill_eigenvalues(prob.hb, J, w), prob.hb.n, w)
    tols = []
    orig = stab.central_eigenvalues

    def recorded(*a, tol=TOL, **k):
        tols.append(tol)
        return orig(*a, tol=tol, **k)

    monkeypatch.setattr(stab, "central_eigenvalues", recorded)
    assert hill_verdict(prob.hb, J, w).stable == ref.stable
    assert tols == [TOL]
    for shift in (-1e-9, 1e-9):  # threshold just below / above the largest real part
        rtol = ref.max_real / w + shift
        tols.clear()
        got = hill_verdict(prob.hb, J, w, rtol=rtol)
        assert tols == [TOL, TOL_TIGHT]
        assert got.stable == stability_of(hill_eigenvalues(prob.hb, J, w), prob.hb.n,
                                          w, rtol).stable == (shift > 0)
