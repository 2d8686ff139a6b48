"""Harmonic balance right by default (issue 17): exact folds and peaks, error
estimates against the true error, curves readable between their points, merged
zigzags of the sampled residual.

References are independent of the code under test: closed forms (linear FRF peak,
Duffing's single-harmonic relation in test_hbm_duffing.py), solves at H = 31 (the
"true" error), event-exact time integration (hbm.reference) for the folds of a
piecewise system.
"""

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.problem import build_problem
from drymount.hbm.continuation import newton
from drymount.hbm.systems import sdof

M, K, C, F = 70.0, 91870.0, 150.0, 40.0


def friction_system():
    ax = AxisParameters(law="linear", k1=K, c=C, friction=True, kf=60000.0, mu=1.0,
                        n0=20.0)
    return sdof(M, MountParameters(axial=ax), "force", F)


def piecewise_system():
    """Hardening piecewise-linear mount (knee at 2 mm), no friction: two folds."""
    ax = AxisParameters(law="piecewise", k1=45935.0, k2=256900.0, delta=0.002, c=60.0)
    return sdof(M, MountParameters(axial=ax), "force", 60.0)


def cubic_system():
    ax = AxisParameters(law="cubic", k1=34770.0, kc=5.708e8, c=20.0)
    return sdof(20.0, MountParameters(axial=ax), "force", 10.0)


# --- peaks ---------------------------------------------------------------------------
# the 1e-8 (measured 1.8e-15 Hz and 2.2e-16 relative)
PEAK_TOL = 1e-8


def test_linear_peak_is_the_exact_frf_peak():
    s = sdof(M, MountParameters(axial=AxisParameters(law="linear", k1=K, c=C)),
             "force", F)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=1)
    w2 = K / M - C**2 / (2 * M**2)  # maximum of F / |K - M w^2 + i C w|
    a = F / np.sqrt((K - M * w2) ** 2 + C**2 * w2)
    (p,) = r.peaks
    assert p.kind == "peak" and p.dof == "x" and p.converged and p.interior
    assert abs(p.freq_hz - np.sqrt(w2) / (2 * np.pi)) < PEAK_TOL
    assert abs(p.amplitude[0] / a - 1) < PEAK_TOL
    # the largest curve point is lower and elsewhere (the peak lies between points)
    assert r.amplitude.max() <= p.amplitude[0]


def test_events_csv(tmp_path):
    r = hbm.frequency_response(cubic_system(), 3.0, 15.0, harmonics=1)
    path = tmp_path / "c.csv"
    r.to_csv(path)
    side = r.events_path(path)
    r.events_to_csv(side)
    with open(side, encoding="utf-8") as fh:
        lines = [ln for ln in fh if not ln.startswith("#")]
    assert lines[0].strip() == ("kind,dof,freq_hz,after_row,converged,x_amp,x_peak,"
                                "transmissibility")
    rows = [ln.strip().split(",") for ln in lines[1:]]
    assert [row[:2] for row in rows] == [["fold", ""], ["fold", ""], ["peak", "x"],
                                         ["peak", "transmissibility"]]
    np.testing.assert_allclose([float(row[2]) for row in rows[:2]],
                               r.turning_freq_hz, atol=1e-9)
    # the fold lies between the curve rows after_row and after_row + 1
    for row in rows[:2]:
        k = int(row[3])
        lo, hi = sorted(r.freq_hz[k:k + 2])
        assert lo - 1e-9 <= float(row[2]) <= hi + 1e-9 or \
            abs(float(row[2]) - r.freq_hz[k:k + 2]).min() < 0.05


# --- error estimates -----------------------------------------------------------------
def _true_error(r, system, fmin, fmax, H_ref=31, N_ref=2048):
    """Distance of each point of ``r`` to the H = 31 curve, measured like the
    estimate: Newton on the plane normal to the curve (tangent by central
    differences of the points), each DOF's amplitude and max |q| relative to its
    largest value, with the frequency shift relative to fmax - fmin (hypot)."""
    ref = build_problem(system, fmin, fmax, H_ref, N_ref, False)
    st = hbm.HBMOptions(max_newton=30).continuation_settings()
    n, m, mr = len(r.dof_names), 2 * r.harmonics + 1, ref.hb.m
    q0 = np.hstack([r.amplitude, r.peak])
    scale = q0.max(axis=0)
    out = np.full(r.n_points, np.nan)
    for i in range(r.n_points):
        w = 2 * np.pi * r.freq_hz[i]
        Xp = np.zeros((mr, n))
        Xp[:m] = r.coefficients[i].T
        y0 = ref.y_of(Xp.ravel(), w)
        j0, j1 = max(i - 1, 0), min(i + 1, r.n_points - 1)
        dX = np.zeros((mr, n))
        dX[:m] = r.coefficients[j1].T - r.coefficients[j0].T
        t = np.append(dX.ravel() / ref.xs,
                      2 * np.pi * (r.freq_hz[j1] - r.freq_hz[j0]) / ref.ws)
        y, ok, _, _ = newton(ref, y0, st, tangent=t / np.linalg.norm(t), y_pred=y0)
        if ok:
            X, wr = ref.x_of(y)
            Xr = X.reshape(mr, n)
            q = np.hstack([np.hypot(Xr[1], Xr[2]), ref.hb.peak_abs(X, 256)])
            out[i] = np.max(np.hypot((q - q0[i]) / scale,
                                     (wr - w) / (2 * np.pi * (fmax - fmin))))
    return out


# The factor 3, checked two ways against the true error (the distance to the
# H = 31, N = 2048 curve, measured like the estimate), both on the estimate
# truncation + sampling (the CSV's two columns):
# 1. curve maximum: the largest estimate (what `drymount hbm` reports and --tol uses)
#    against the largest true error. Measured est/true: friction 2.45, piecewise 1.35,
#    cubic 1.51.
# 2. per point, at the re-solved points where the true error is above the noise
#    floor (a tenth of its largest value). Measured est/true: friction 1.52..2.50 at
#    all 7 points, cubic 1.51..1.53 at all 9, piecewise 1.07..3.12 with 19 of 20
#    within 3x (3.12 at 8.943 Hz, on the stretch near the upper fold re-traced past
#    kinks of the sampled residual), so the piecewise case is held to the factor 3
#    at PER_POINT_FRACTION of its points, the others at every point. (Before the
#    re-solves started cold, hbm.error_estimate.estimate_errors, the friction case
#    was 1.91..9.55 per point.)
ESTIMATE_FACTOR = 3.0
PER_POINT_FRACTION = 0.9
NOISE_FLOOR = 0.1


def _resolved_points(r):
    """Indices the estimate re-solved (hbm.analysis._estimate's schedule)."""
    from drymount.hbm.analysis import ESTIMATE_STRIDE, MAX_ESTIMATED
    n = r.n_points
    stride = max(ESTIMATE_STRIDE, -(-n // MAX_ESTIMATED))
    return np.array(sorted(set(range(0, n, stride)) | {n - 1}
                           | {j for i in r.turning_points for j in (i - 1, i)}))


@pytest.mark.parametrize("case", [
    ("friction", friction_system, 2.0, 15.0, 7, 256),
    ("piecewise", piecewise_system, 2.0, 12.0, 7, 256),
    ("cubic", cubic_system, 3.0, 15.0, 3, 64),
], ids=lambda c: c[0])
def test_error_estimate_vs_true_error(case):
    name, make, fmin, fmax, H, N = case
    system = make()
    r = hbm.frequency_response(system, fmin, fmax, harmonics=H, n_samples=N,
                               options=hbm.HBMOptions(tol=None))
    assert r.success
    true = _true_error(r, system, fmin, fmax)
    assert np.all(np.isfinite(true))
    # 1. the curve's largest estimate
    ratio = np.nanmax(r.error_truncation + r.error_sampling) / true.max()
    assert 1 / ESTIMATE_FACTOR <= ratio <= ESTIMATE_FACTOR, ratio
    # 2. per point, above the noise floor
    est = r.error_truncation + r.error_sampling
    sel = _resolved_points(r)
    big = sel[true[sel] > NOISE_FLOOR * true.max()]
    per = est[big] / true[big]
    assert np.all(np.isfinite(per)) and len(per) >= 5
    inside = np.mean((per >= 1 / ESTIMATE_FACTOR) & (per <= ESTIMATE_FACTOR))
    if name == "piecewise":
        assert inside >= PER_POINT_FRACTION, per
    else:
        assert inside == 1.0, per


# --- curves you can read -------------------------------------------------------------
# With the defaults (tol 1e-3) the single-DOF friction curve, read by linear
# interpolation between CSV rows, stays within 0.1 % of the peak of the converged
# curve (H = 15, N = 512) at 300 frequencies (the criterion; measured
# 6.7e-4 amplitude, 6.4e-4 max |q|: tol/2 for H and N, tol/2 for the chords).
READ_TOL = 1e-3


def test_default_friction_curve_readable_between_rows():
    s = friction_system()
    r = hbm.frequency_response(s, 2.0, 15.0)
    assert r.success and r.tol_met and np.all(np.diff(r.freq_hz) > 0)
    f = np.linspace(2.0, 15.0, 300)
    conv = hbm.solve_frequencies(s, f, harmonics=15, n_samples=512,
                                 options=hbm.HBMOptions(stability=False,
                                                        error_estimate=False))
    assert conv.success
    for quantity in ("amplitude", "peak"):
        ref = getattr(conv, quantity)[:, 0]
        got = np.interp(f, r.freq_hz, getattr(r, quantity)[:, 0])
        err = np.abs(got - ref).max() / ref.max()
        assert err < READ_TOL, (quantity, err)


def test_tol_raises_resolution_and_says_when_it_cannot():
    s = friction_system()
    r = hbm.frequency_response(s, 2.0, 15.0, options=hbm.HBMOptions(tol=1e-3))
    assert r.tol_met and r.n_samples > 64 and "raised" in r.message
    # H fixed by the caller at 1: the estimate exceeds the tolerance and says why
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=1,
                               options=hbm.HBMOptions(tol=1e-4))
    assert r.success and r.tol_met is False
    assert "fixed by the caller" in r.message and "exceeds tol/2" in r.message
    # a cap: max_harmonics = the starting H
    r = hbm.frequency_response(s, 2.0, 15.0, options=hbm.HBMOptions(
        tol=2e-4, harmonics=3, max_harmonics=3, max_samples=64))
    assert r.tol_met is False and "caps" in r.message


# --- turning points that are real ----------------------------------------------------
def test_zigzags_of_the_sampled_residual_are_merged():
    """The piecewise system at H = 7 and 64 samples zigzags near its upper fold
    (32 turning points without merging, measured); merging leaves the two folds
    of the finely sampled curve (H = 7, N = 1024: 9.05476 and 5.23779 Hz)."""
    s = piecewise_system()
    raw = hbm.frequency_response(s, 2.0, 12.0, harmonics=7, n_samples=256,
                                 options=hbm.HBMOptions(tol=None, zigzag_refine=1,
                                                        error_estimate=False))
    assert len(raw.turning_points) > 10
    r = hbm.frequency_response(s, 2.0, 12.0, harmonics=7, n_samples=256,
                               options=hbm.HBMOptions(tol=None, error_estimate=False))
    assert len(r.turning_points) == 2 and r.turning_points_merged > 10
    np.testing.assert_allclose(r.turning_freq_hz, [9.05476, 5.23779], atol=5e-4)
    i, j = r.turning_points
    assert np.all(np.diff(r.freq_hz[:i]) > 0) and np.all(np.diff(r.freq_hz[j:]) > 0)


# --- folds against long-time integration ---------------------------------------------
# The march is exact per linear segment: its end state does not depend on the step
# (16 vs 128 steps per period: measured 2.8e-14 m/s) and agrees with DOP853 at rtol
# 1e-12 (which steps across the knees) to 2.1e-9 m/s after 20 periods.
MARCH_STEP_TOL = 1e-12
MARCH_DOP853_TOL = 1e-7


def test_piecewise_march_is_exact():
    from scipy.integrate import solve_ivp
    from piecewise_march import PiecewiseOscillator, march
    osc = PiecewiseOscillator(M, 60.0, 45935.0, 256900.0, 0.002, 60.0)
    # amplitudes of several delta, as in the fold test (a motion turning within a
    # step of a knee is the march's documented blind spot: 3 Hz from (1 mm,
    # -0.1 m/s), peaks 2.2-3.7 mm, differs by 2e-4 at 16 steps, 2e-15 at 32)
    f = np.array([7.0, 9.0, 9.05])
    z0 = np.array([[0.003, 0.0], [0.0, 0.5], [0.0, 1.0]])
    coarse, fine = march(osc, f, z0, 20, 16), march(osc, f, z0, 20, 128)
    assert coarse.crossings > 100
    np.testing.assert_allclose(coarse.state, fine.state, rtol=0, atol=MARCH_STEP_TOL)

    def rhs(t, z, w):
        x, v = z
        el = osc.k1 * x + (osc.k2 - osc.k1) * (max(x - osc.delta, 0.0)
                                               + min(x + osc.delta, 0.0))
        return [v, (osc.force * np.sin(w * t) - osc.c * v - el) / osc.m]

    for j in range(f.size):
        sol = solve_ivp(rhs, (0.0, 20 / f[j]), z0[j], args=(2 * np.pi * f[j],),
                        rtol=1e-12, atol=1e-14, method="DOP853")
        np.testing.assert_allclose(coarse.state[j], sol.y[:, -1], rtol=0,
                                   atol=MARCH_DOP853_TOL)


def _initial_state(r, i):
    """``(q(0), dq/dt(0))`` of curve point i."""
    X = r.coefficients[i].T  # (2H+1, n)
    w = 2 * np.pi * r.freq_hz[i]
    k = np.arange(1, r.harmonics + 1)[:, None]
    return X[0] + X[1::2].sum(axis=0), w * (k * X[2::2]).sum(axis=0)


# The 1e-4 Hz: the upper fold (jump down) of the piecewise system by
# long-time integrations, exact per linear segment (tests/piecewise_march.py, written
# from the law's formula, not hbm's code), bracketed to FOLD_BRACKET_HZ by refining a
# grid of frequencies integrated at once; every integration starts from the HBM
# upper-branch point below the fold and is classified stayed (converged on the upper
# branch: change per period < 1e-10) or fell (to the lower branch); see
# piecewise_march.fold_by_integration for why that decides the fold. Measured: HBM
# fold (H = 25, N = 2048) 9.0550137 Hz, integration bracket [9.0549357, 9.0550357] Hz
# (3 stages, 400 + 400 + 4400 periods; refined to 1.6e-5 Hz spacing it is
# [9.0550097, 9.0550417]: the HBM fold lies 4e-6..2.8e-5 Hz below the integration's;
# the H = 15 fold is 1.0e-4 Hz lower still). About 50 s on a loaded 2-core machine
# (load 7), HBM 3 s of it.
FOLD_TIME_TOL_HZ = 1e-4
FOLD_BRACKET_HZ = 1e-4


def test_piecewise_fold_vs_long_time_integration():
    from piecewise_march import PiecewiseOscillator, fold_by_integration
    s = piecewise_system()
    ax = s.elements[0].params.axial
    assert s.M.tolist() == [[M]] and not s.K.any() and not s.C.any()
    assert s.excitation.kind == "force"  # F sin(omega t), as the march integrates
    osc = PiecewiseOscillator(M, ax.c, ax.k1, ax.k2, ax.delta,
                              float(s.excitation.amplitude[0]))
    r = hbm.frequency_response(s, 4.0, 10.0, harmonics=25, n_samples=2048,
                               options=hbm.HBMOptions(tol=None, stability=False,
                                                      error_estimate=False))
    assert len(r.folds) == 2  # the upper fold (jump down) first, then the lower
    fold = r.folds[0]
    assert fold.converged and r.freq_hz[fold.index - 1] < fold.freq_hz
    state = _initial_state(r, fold.index - 1)  # upper branch, below the fold
    # the search spans +-0.1 Hz around the HBM point (the integrations decide)
    f0 = r.freq_hz[fold.index - 1]
    br = fold_by_integration(osc, np.ravel(state), f0 - 0.1, f0 + 0.1,
                             FOLD_BRACKET_HZ)
    assert br.hi - br.lo <= FOLD_BRACKET_HZ
    assert br.lo - FOLD_TIME_TOL_HZ < fold.freq_hz < br.hi + FOLD_TIME_TOL_HZ, \
        (fold.freq_hz, br.lo, br.hi)


def test_failed_start_retried_with_more_samples_and_a_smaller_step():
    """The issue's nearly rigid slider (kf = 1e8) at H = 7, N = 64 has no start
    solution at fmin; the start is retried with 128 samples and a 4x smaller first
    step, and the message says why."""
    ax = AxisParameters(law="linear", k1=K, c=C, friction=True, kf=1e8, mu=1.0,
                        n0=20.0)
    s = sdof(M, MountParameters(axial=ax), "force", F)
    opts = hbm.HBMOptions(tol=None, error_estimate=False)
    r = hbm.frequency_response(s, 2.0, 3.0, options=opts)
    assert r.success and r.n_samples == 128
    # the first attempt (64 samples) failed, and the message says so
    assert "with 64 AFT samples no solution at fmin" in r.message
    assert "first step 0.005" in r.message


# --- adaptive defaults that stay affordable ------------------------------------------
def test_harmonics_cap_by_dof_count():
    from drymount.config import MAX_HARMONICS as CONFIG_MAX
    from drymount.hbm.options import (ADAPTIVE_MAX_HARMONICS, MAX_HARMONICS,
                                      MULTI_DOF_MAX_HARMONICS)
    o = hbm.HBMOptions()
    assert o.harmonics_cap(1) == o.harmonics_cap(3) == ADAPTIVE_MAX_HARMONICS == 25
    assert MAX_HARMONICS == CONFIG_MAX == 50   # one bound, hbm's
    assert o.harmonics_cap(6) == MULTI_DOF_MAX_HARMONICS == 13
    assert hbm.HBMOptions(max_harmonics=31).harmonics_cap(6) == 31


# errors falling like H^-3 from 0.014 at H = 5: 0.014 (5/H)^3 <= 2.5e-4 needs H >= 19.1
def test_resolution_predicted_from_two_levels():
    from drymount.hbm.resolution import _fit_level, _rate
    e = lambda H: 0.014 * (5 / H) ** 3  # noqa: E731
    assert abs(_rate(5, e(5), 11, e(11), 1.5) - 3.0) < 1e-12
    assert _fit_level(5, e(5), 11, e(11), 2.5e-4, 6, 25, 1.5) == 20
    assert _fit_level(5, e(5), 11, e(11), 2.5e-4, 6, 13, 1.5) == 13  # the cap
    # no decay between the two: the default rate
    assert _rate(5, 1e-3, 11, 2e-3, 1.5) == 1.5


# A probe at the curve's own resolution re-solves its points (on the plane normal to
# the curve: they hardly move) and estimates them again: the same estimates as the
# curve's at those points (measured max relative difference 4e-9).
PROBE_SELF_RTOL = 1e-5


def test_probe_at_the_curves_resolution_reproduces_its_estimates():
    from drymount.hbm.analysis import _estimate
    from drymount.hbm.resolution import _probe_points
    from drymount.hbm.error_estimate import curve_scale, probe_errors
    s = friction_system()
    opts = hbm.HBMOptions(tol=None)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=5, n_samples=128, options=opts)
    prob = build_problem(s, 2.0, 15.0, 5, 128, False)
    from drymount.hbm.analysis import _trace
    r, br = _trace(prob, 2.0, 15.0, opts, False)
    _estimate(s, 2.0, 15.0, prob, br, opts, r)
    pts = [i for i in _probe_points(r) if i % 4 == 0]  # re-solved points
    assert len(pts) >= 4
    est = probe_errors(prob, br.y, br.tangent, pts,
                       lambda H, N, cf: build_problem(s, 2.0, 15.0, H, N, cf),
                       opts.continuation_settings(), opts.n_peak, 5, 128,
                       curve_scale(prob, br.y, opts.n_peak))
    # atol: estimates of round-off size (2.7e-17 measured) differ at random
    np.testing.assert_allclose(est.truncation, r.error_truncation[pts],
                               rtol=PROBE_SELF_RTOL, atol=1e-12)
    np.testing.assert_allclose(est.sampling, r.error_sampling[pts],
                               rtol=PROBE_SELF_RTOL, atol=1e-12)


def test_transmissibility_peak_located_like_the_dof_peaks(tmp_path):
    """Linear single DOF, force excitation: T(w) = |k + i c w| / |k - m w^2 + i c w|,
    its maximum from the closed form's derivative (a dense grid, then the golden
    section on it, written here) against the located peak (issue 23 item 4)."""
    s = sdof(M, MountParameters(axial=AxisParameters(law="linear", k1=K, c=C)),
             "force", F)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=1)

    def T(f):
        w = 2 * np.pi * f
        return abs(K + 1j * C * w) / abs(K - M * w**2 + 1j * C * w)

    lo, hi = 2.0, 15.0
    f = np.linspace(lo, hi, 20001)
    i = int(np.argmax(T(f)))
    lo, hi = f[i - 1], f[i + 1]
    g = (np.sqrt(5) - 1) / 2
    while hi - lo > 1e-10:
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        lo, hi = (a, hi) if T(a) < T(b) else (lo, b)
    f_ref = 0.5 * (lo + hi)
    p = r.transmissibility_peak
    assert p.kind == "peak" and p.dof is None and p.converged and p.interior
    assert abs(p.freq_hz - f_ref) < 1e-6  # FREQ_TOL_HZ
    assert abs(p.transmissibility / T(f_ref) - 1) < 1e-9
    assert p.transmissibility >= r.transmissibility.max()
    assert r.transmissibility_max() == (p.freq_hz, p.transmissibility)
    side = tmp_path / "e.csv"
    r.events_to_csv(side)
    rows = side.read_text().splitlines()
    assert any(row.startswith("peak,transmissibility,") for row in rows), rows
