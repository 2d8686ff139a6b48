"""Continuation, drivers and results: AFT vs closed forms at H = 1, input validation,
stalled continuations, CSV, plots, progress bar, multi-harmonic convergence."""

import csv

import numpy as np
import pytest

import drymount.hbm as hbm
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.continuation import Status
from drymount.hbm.systems import quarter_car, sdof

# H = 1 AFT (N = 4096 samples) vs closed forms, relative to the peak amplitude. The
# AFT's error comes from the kinks of the laws between samples, O(N^-2):
# measured 1.9e-7 (Jenkins), 1.1e-7 (piecewise + Jenkins), 6e-8 (cubic + Jenkins).
RTOL_AFT_VS_CLOSED = 1e-6
N_AFT = 4096


def sdof_preset(n0=20.0, law="linear", **kw):
    """The benchmark's single-DOF preset: m 70 kg, k 91 870 N/m, c 150 N s/m,
    kf 60 000 N/m, Fs = n0 (mu = 1), force amplitude 40 N."""
    ax = AxisParameters(law=law, k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        mu=1.0, n0=n0, **kw)
    return sdof(70.0, MountParameters(axial=ax), "force", 40.0)


def quarter_car_preset(n0=30.0):
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        mu=1.0, n0=n0)
    return quarter_car(70, 230, 30, 15000, 1000, 200000, 0.0,
                       MountParameters(axial=ax), road_amplitude=0.01)


@pytest.mark.parametrize("system", [
    sdof_preset(),
    sdof_preset(law="piecewise", delta=0.002),
    sdof_preset(law="cubic", kc=5e8),
    quarter_car_preset(),
], ids=["jenkins", "piecewise", "cubic", "quarter_car"])
def test_h1_aft_equals_closed_form(system):
    f = np.linspace(2.0, 15.0, 14) if system.name == "sdof" else np.linspace(1, 25, 13)
    rc = hbm.solve_frequencies(system, f, harmonics=1)
    ra = hbm.solve_frequencies(system, f, harmonics=1, closed_form=False,
                               n_samples=N_AFT)
    assert rc.closed_form and not ra.closed_form and rc.success and ra.success
    scale = rc.amplitude.max(axis=0)
    err = np.abs(ra.amplitude - rc.amplitude) / scale
    assert err.max() <= RTOL_AFT_VS_CLOSED
    err_c = np.abs(ra.coefficients - rc.coefficients).max(axis=(0, 2)) / scale
    assert err_c.max() <= RTOL_AFT_VS_CLOSED


def test_curve_points_solve_the_equations():
    """Points of the continuation and Newton at the same frequencies agree."""
    s = sdof_preset()
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=5)
    assert r.success and r.freq_hz[0] == 2.0 and r.freq_hz[-1] == 15.0
    assert np.all(np.diff(r.freq_hz) > 0)  # no fold for this preset
    sel = slice(None, None, 3)
    r2 = hbm.solve_frequencies(s, r.freq_hz[sel], harmonics=5, n_samples=r.n_samples)
    np.testing.assert_allclose(r2.coefficients, r.coefficients[sel], rtol=0,
                               atol=1e-9 * r.amplitude.max())
    assert r.n_newton >= r.n_points - 1 and r.n_steps >= r.n_points - 1
    assert r.stable.all() and len(r.turning_points) == 0


def test_fold_traced_with_aft_and_friction():
    """A hardening cubic with a friction element at H = 3: two folds traced."""
    ax = AxisParameters(law="cubic", k1=34770.0, kc=5.708e8, c=20.0, friction=True,
                        kf=60000.0, n0=2.0)
    s = sdof(20.0, MountParameters(axial=ax), "force", 10.0)
    r = hbm.frequency_response(s, 3.0, 15.0, harmonics=3)
    assert r.success
    assert len(r.turning_points) == 2
    i, j = r.turning_points
    assert r.turning_freq_hz[0] > r.turning_freq_hz[1]
    assert not r.stable[i:j].any()


@pytest.mark.parametrize("kwargs,match", [
    (dict(fmin_hz=5.0, fmax_hz=2.0), "fmax_hz"),
    (dict(fmin_hz=-1.0, fmax_hz=2.0), "fmin_hz"),
    (dict(fmin_hz=1.0, fmax_hz=float("nan")), "fmax_hz"),
    (dict(harmonics=0), "harmonics"),
    (dict(harmonics=2.5), "harmonics"),
    (dict(harmonics=3, n_samples=6), "n_samples"),
    (dict(harmonics=3, closed_form=True), "closed_form"),
    (dict(options="fast"), "options"),
])
def test_invalid_input_raises_before_work(kwargs, match):
    args = dict(fmin_hz=2.0, fmax_hz=15.0)
    args.update(kwargs)
    with pytest.raises((ValueError, TypeError), match=match):
        hbm.frequency_response(sdof_preset(), args.pop("fmin_hz"), args.pop("fmax_hz"),
                               **args)


def test_closed_form_unavailable_for_asymmetric_law():
    s = sdof_preset(law="piecewise_asym", delta=0.002, delta_neg=0.001)
    with pytest.raises(ValueError, match="piecewise_asym"):
        hbm.frequency_response(s, 2.0, 15.0, harmonics=1, closed_form=True)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=1)  # falls back to AFT
    assert r.success and not r.closed_form
    assert np.abs(r.coefficients[:, 0, 0]).max() > 0  # asymmetric: static offset


@pytest.mark.parametrize("field,value", [("ds_min", -1.0), ("harmonics", 0),
                                         ("stability", 1), ("n_samples", 2.0),
                                         ("max_newton", True),
                                         ("refine_samples", -1),
                                         ("max_restarts", 1.5),
                                         ("restart_factor", 1.0)])
def test_options_validation(field, value):
    with pytest.raises(ValueError, match=field):
        hbm.HBMOptions(**{field: value})


def test_stalled_continuation_returns_branch():
    s = sdof_preset()
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=3,
                               options=hbm.HBMOptions(max_steps=5))
    assert not r.success and r.status is Status.TOO_MANY_STEPS
    assert "max_steps" in r.message
    assert r.n_points == 6 and r.freq_hz[-1] < 15.0
    # Newton cannot converge in one iteration on the nonlinear branch: the step
    # shrinks below ds_min and the continuation stops with what it has
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=3,
                               options=hbm.HBMOptions(max_newton=1, ds_min=1e-3,
                                                      refine_samples=0))
    assert not r.success and r.status is Status.STEP_TOO_SMALL
    assert "ds_min" in r.message
    assert r.n_points >= 1 and r.freq_hz[0] == 2.0


def test_dead_end_of_the_sampled_problem_is_refined(six_dof_halved_issue4):
    """six_dof_halved (the engine of issue 4) at H = 5 and 64 samples: the branch turns
    back onto itself at a kink near 9.65 Hz (measured). Without refinement the curve
    so far comes back with status RETRACED; by default the samples are doubled, the
    curve
    reaches fmax and the message says what happened."""
    s = six_dof_halved_issue4
    # tol=None: the steps of the old default (the chord control would step past it)
    off = hbm.HBMOptions(stability=False, refine_samples=0, tol=None)
    r = hbm.frequency_response(s, 2.0, 25.0, harmonics=5, options=off)
    assert not r.success and r.status is Status.RETRACED and r.n_samples == 64
    assert r.n_points > 10 and 9.0 < r.freq_hz.max() < 10.0
    r = hbm.frequency_response(s, 2.0, 25.0, harmonics=5,
                               options=hbm.HBMOptions(stability=False, tol=None))
    assert r.success and r.n_samples == 128 and r.freq_hz[-1] == 25.0
    assert "raised to 128" in r.message and "64 AFT samples" in r.message


def test_csv_and_plot(tmp_path):
    r = hbm.frequency_response(quarter_car_preset(), 1.0, 25.0, harmonics=3)
    path = tmp_path / "curve.csv"
    r.to_csv(path)
    lines = path.read_text().splitlines()
    assert lines[0].startswith("# ")
    rows = list(csv.reader(lines[1:]))
    assert rows[0] == ["freq_hz", "engine_amp", "engine_peak", "sprung_amp",
                       "sprung_peak", "unsprung_amp", "unsprung_peak",
                       "transmissibility", "stable", "err_truncation",
                       "err_sampling"]
    data = np.array(rows[1:], dtype=float)
    assert data.shape == (r.n_points, 11)
    np.testing.assert_allclose(data[:, 0], r.freq_hz, rtol=1e-9)
    np.testing.assert_allclose(data[:, 1], r.amplitude[:, 0], rtol=1e-9)
    np.testing.assert_allclose(data[:, 7], r.amplitude[:, 0] / r.amplitude[:, 1],
                               rtol=1e-9)  # thesis eq. 4.3
    assert set(data[:, 8]) <= {0.0, 1.0}
    np.testing.assert_allclose(data[:, 9], r.error_truncation, rtol=1e-2)
    png = tmp_path / "curve.png"
    ax = r.plot(png)
    assert png.stat().st_size > 1000
    # one panel per DOF beside the transmissibility, titled with system and H/N
    fig = ax.figure
    assert len(fig.axes) == 4
    assert "H = 3" in fig._suptitle.get_text()
    label = fig.axes[0].get_ylabel()
    assert "|sprung|" in label or "eq. 4.3" in label
    assert [a.get_title() for a in fig.axes[1:]] == [
        "DOF engine", "DOF sprung", "DOF unsprung"]
    assert all("[m]" in a.get_ylabel() for a in fig.axes[1:])


def test_force_transmissibility_equals_linear_formula():
    """Thesis eq. 4.1 for a linear mount: |k + i omega c| |X| / F."""
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0)
    s = sdof(70.0, MountParameters(axial=ax), "unbalance", 0.01)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=1)
    w = 2 * np.pi * r.freq_hz
    ref = np.abs(91870.0 + 1j * w * 150.0) * r.amplitude[:, 0] / (w**2 * 0.01)
    np.testing.assert_allclose(r.transmissibility, ref, rtol=1e-12)


def test_progress_bar_on_stderr(capsys):
    hbm.frequency_response(sdof_preset(), 2.0, 15.0, harmonics=1, progress=True)
    err = capsys.readouterr().err
    assert "Hz" in err and "13.00/13.00" in err


# multi-harmonic convergence at the resonance peak (sdof preset): fundamental
# amplitude at the peak vs H = 15. Measured: H=1 4.1e-3, H=3 1.8e-3, H=5 1.2e-3,
# H=9 3.8e-6.
RTOL_H9_VS_H15 = 2e-5


def test_multiharmonic_convergence_at_peak():
    s = sdof_preset()
    f = np.linspace(5.80, 5.92, 41)
    peaks = {}
    for H in (1, 3, 5, 9, 15):
        r = hbm.solve_frequencies(s, f, harmonics=H)
        assert r.success
        peaks[H] = r.amplitude[:, 0].max()
    err = {H: abs(peaks[H] / peaks[15] - 1) for H in (1, 3, 5, 9)}
    assert err[1] > err[3] > err[5] > err[9]
    assert err[9] <= RTOL_H9_VS_H15


def _max_relative_residual(system, r, n_samples):
    """The largest residual of the curve's points, each with the AFT samples it
    was solved with (``n_samples``, or more where a stretch was re-traced)."""
    from drymount.hbm.residual import HarmonicBalance
    balances = {}
    worst = 0.0
    for i in range(r.n_points):
        n = r.samples_of(i)
        assert n == n_samples or i in _retraced_points(r), (i, n)
        hb = balances.setdefault(n, HarmonicBalance(system, r.harmonics, n))
        w = 2 * np.pi * r.freq_hz[i]
        R, _, _ = hb.residual(r.coefficients[i].T.ravel(), w, jacobian=False)
        worst = max(worst, np.linalg.norm(R) / np.linalg.norm(hb.excitation(w)))
    return worst


def _retraced_points(r) -> set:
    """Indices of the points with more samples than the curve's (re-traced)."""
    return {i for i in range(len(r.samples_per_point))
            if r.samples_per_point[i] > r.n_samples}


# Newton tolerance 1e-10 on the scaled residual; measured 4.4e-11 and 5e-12
RTOL_POINT_RESIDUAL = 1e-9


def test_corner_folds_of_the_sampled_piecewise_law():
    """A strongly hardening piecewise spring sampled at N points gives a residual with
    kinks; the branch turns sharply at some of them (corner folds, where the
    pseudo-arclength plane has no solution). The continuation must get past them to
    fmax, and every point must solve the equations."""
    ax = AxisParameters(law="piecewise", k1=91870.0, k2=513800.0, delta=0.002, c=150.0)
    s = sdof(70.0, MountParameters(axial=ax), "force", 100.0)
    r = hbm.frequency_response(s, 2.0, 30.0, harmonics=7, n_samples=64,
                               options=hbm.HBMOptions(stability=False))
    assert r.success and r.freq_hz[-1] == 30.0
    assert len(r.turning_points) % 2 == 0 and len(r.turning_points) >= 2
    assert _max_relative_residual(s, r, 64) <= RTOL_POINT_RESIDUAL
    # the jump-down region is where the hardening branch ends: near 11.6-12 Hz
    assert 11.0 < r.turning_freq_hz.max() < 12.5


def test_start_by_load_stepping():
    """At fmin the linear guess is too far from the solution for Newton; the start
    raises the excitation in steps."""
    ax = AxisParameters(law="piecewise", k1=91870.0, k2=513800.0, delta=0.002, c=150.0)
    s = sdof(70.0, MountParameters(axial=ax), "force", 400.0)
    # zigzag_refine=1: every point at N = 32 (a merged zigzag is re-traced with more)
    r = hbm.frequency_response(s, 2.0, 5.0, harmonics=5, n_samples=32,
                               options=hbm.HBMOptions(stability=False,
                                                      zigzag_refine=1))
    assert r.n_points > 1 and r.freq_hz[0] == 2.0
    assert _max_relative_residual(s, r, 32) <= RTOL_POINT_RESIDUAL


# Continuation points vs Newton at the same frequencies: both converge to 1e-10 of
# the residual; measured 1.3e-15.
RTOL_RESTART = 1e-9


def test_restarts_continue_past_a_stall_in_segments():
    """A continuation that stops early (here: max_steps per segment) is restarted
    ``restart_factor`` above the highest frequency reached; the segments are joined
    with one gap row each and every point is a solution: Newton at the same
    frequencies (hbm.solve_frequencies, independent of the continuation) gives the
    same amplitudes."""
    s = sdof_preset()
    opts = hbm.HBMOptions(max_steps=15, max_restarts=20, stability=False)
    r = hbm.frequency_response(s, 2.0, 15.0, harmonics=3, options=opts)
    assert r.success and r.status is Status.DONE and len(r.restarts) >= 2
    segs = r.segments
    assert len(segs) == len(r.restarts) + 1
    for k, (seg, restart) in enumerate(zip(segs[1:], r.restarts)):
        gap = seg.start - 1
        assert np.isnan(r.amplitude[gap]).all() and r.freq_hz[gap] == restart.freq_hz
        assert r.freq_hz[seg.start] == pytest.approx(restart.freq_hz, rel=1e-12)
        top = r.freq_hz[segs[k]].max()
        assert restart.freq_hz == pytest.approx(top * opts.restart_factor, rel=1e-12)
        assert "max_steps" in restart.reason
    assert r.freq_hz[segs[-1]].max() == 15.0
    pts = np.concatenate([r.freq_hz[seg] for seg in segs])
    ok = np.concatenate([r.amplitude[seg][:, 0] for seg in segs])
    ref = hbm.solve_frequencies(s, pts[::7], harmonics=3, n_samples=r.n_samples,
                                options=hbm.HBMOptions(stability=False))
    assert ref.success
    assert np.allclose(ok[::7], ref.amplitude[:, 0], rtol=RTOL_RESTART, atol=0)
    # without restarts the same options stop at the first stall
    once = hbm.frequency_response(s, 2.0, 15.0, harmonics=3,
                                  options=hbm.HBMOptions(max_steps=15,
                                                         stability=False))
    assert not once.success and once.restarts == () and len(once.segments) == 1
