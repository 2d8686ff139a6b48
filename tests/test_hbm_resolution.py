"""The ``tol`` adaptation honours its cap on H by every route that raises it (issue 23
item 1: ``drymount hbm six_dof_halved --set ...`` went to H = 14 past the cap of 13,
then a probe back down to 13 padded a (29, 6) solution into (27, 6) and crashed), and
a failure while raising the resolution keeps the last whole curve for the caller.

The single-DOF friction system stands in for the 6-DOF one: with ``MULTI_DOF``
patched to 0 it takes the probe route of the systems of more than 3 DOF, at a cost of
seconds instead of minutes.
"""

from types import SimpleNamespace

import numpy as np
import pytest

import drymount.hbm as hbm
import drymount.hbm.analysis as analysis
import drymount.hbm.resolution as resolution
from drymount import cli
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.error_estimate import _pad
from drymount.hbm.systems import sdof

CAP = 3


def friction_system():
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                        mu=1.0, n0=20.0)
    return sdof(70.0, MountParameters(axial=ax), "force", 40.0)


def test_fit_level_at_the_cap_stays_at_the_cap():
    # a curve at H = 13 = cap with a truncation above target: the floor H0 + 1 = 14
    # must not win over the cap (it did: H = 14 for six_dof_halved)
    e = lambda H: 0.014 * (5 / H) ** 3  # noqa: E731
    assert resolution._fit_level(11, e(11), 13, e(13), 1e-9, 14, 13, 1.5) == 13
    assert resolution._fit_level(11, e(11), 13, 0.0, 1e-9, 14, 13, 1.5) == 13


def test_next_resolution_never_lowers_h():
    opts = hbm.HBMOptions()
    curve = SimpleNamespace(harmonics=15, n_samples=1024, closed_form=False)
    # a curve above the cap (started there): H stays, only N may rise
    H, N, why = resolution.next_resolution(curve, 1e-2, 1e-2, 1e-4, opts, False,
                                           False, 13)
    assert (H, N, why) == (15, 2048, "")
    H, N, why = resolution.next_resolution(curve, 1e-2, 1e-6, 1e-4, opts, False,
                                           False, 13)
    assert H is None and "caps max_harmonics = 13" in why


def test_pad_refuses_to_cut_a_solution_down():
    from drymount.hbm.problem import build_problem
    s = friction_system()
    small = build_problem(s, 2.0, 15.0, 3, 64, False).hb
    large = build_problem(s, 2.0, 15.0, 4, 64, False).hb
    X = np.arange(small.size, dtype=float)
    padded = _pad(X, small, large)
    assert padded.shape == (large.size,)
    np.testing.assert_array_equal(padded[:small.size], X)
    assert not padded[small.size:].any()
    with pytest.raises(ValueError, match="H = 4 harmonics into one of H = 3"):
        _pad(padded, large, small)


def test_every_curve_and_probe_within_the_cap(monkeypatch):
    """The probe route with a tolerance the cap cannot meet: every curve and every
    probe at H <= cap, and the result says the cap stopped it (before the fix: a
    curve at H = 4 and the ValueError of ``_pad`` probing back down to 3)."""
    monkeypatch.setattr(analysis, "MULTI_DOF", 0)
    curves, probes = [], []
    real_curve, real_probe = analysis._curve, resolution.probe_errors

    def spy_curve(system, fmin, fmax, H, N, *a, **k):
        curves.append(H)
        return real_curve(system, fmin, fmax, H, N, *a, **k)

    def spy_probe(prob, ys, ts, pts, make, settings, n_peak, H, N, scale):
        probes.append((prob.hb.H, H))
        return real_probe(prob, ys, ts, pts, make, settings, n_peak, H, N, scale)

    monkeypatch.setattr(analysis, "_curve", spy_curve)
    monkeypatch.setattr(resolution, "probe_errors", spy_probe)
    r = hbm.frequency_response(friction_system(), 2.0, 15.0, options=hbm.HBMOptions(
        harmonics=CAP, tol=1e-5, max_harmonics=CAP, max_samples=256))
    assert r.success and r.tol_met is False
    assert "caps max_harmonics = 3" in r.message
    assert curves and max(curves) <= CAP, curves
    assert probes, "the probe route was not taken"
    assert all(h_curve <= h <= CAP for h_curve, h in probes), probes
    assert r.harmonics <= CAP


def _fail_second_curve(monkeypatch) -> None:
    """The second curve of the ``tol`` adaptation (the first raise) fails."""
    real = analysis._curve
    calls = []

    def failing_second(*a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise ValueError("injected failure at the raised resolution")
        return real(*a, **k)

    monkeypatch.setattr(analysis, "_curve", failing_second)


def test_failure_while_raising_keeps_the_last_whole_curve(monkeypatch):
    _fail_second_curve(monkeypatch)
    with pytest.raises(ValueError, match="injected") as info:
        hbm.frequency_response(friction_system(), 2.0, 15.0,
                               options=hbm.HBMOptions(harmonics=3, tol=1e-4))
    part = info.value.partial_result
    assert part.harmonics == 3 and part.n_points > 20
    assert part.freq_hz[0] == 2.0 and part.freq_hz[-1] == 15.0
    assert "stopped while raising H and N" in part.message
    assert part.peaks, "the partial curve is finished (peaks located)"


def test_cli_exit_1_writes_the_partial_curve(monkeypatch, tmp_path, capsys):
    _fail_second_curve(monkeypatch)
    out = tmp_path / "c.csv"
    code = cli.main(["hbm", "sdof_halved", "--fmin", "2", "--fmax", "15", "--tol",
                     "1e-4", "-q", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1, err
    lines = out.read_text().splitlines()
    assert lines[0].startswith("# partial: ValueError: injected failure"), lines[0]
    assert lines[2].startswith("freq_hz,") and len(lines) > 20


def test_cli_max_harmonics_bounded_by_the_config_cap(capsys):
    from drymount.config import MAX_HARMONICS
    code = cli.main(["hbm", "sdof_halved", "--max-harmonics",
                     str(MAX_HARMONICS + 1)])
    err = capsys.readouterr().err
    assert code == 2
    assert f"1..{MAX_HARMONICS}" in err and str(MAX_HARMONICS + 1) in err, err


def test_first_samples_of_the_adaptation():
    """More than 3 DOF: the first curve of the ``tol`` adaptation at ``max(64, 16H)``
    samples (a power of 2); smaller systems keep the default (None)."""
    assert [resolution.first_samples(6, H) for H in (1, 3, 5, 7, 13)] == \
        [64, 64, 128, 128, 256]
    assert resolution.first_samples(3, 5) is None
    assert resolution.first_samples(1, 7) is None


def test_the_first_curve_takes_first_samples(monkeypatch):
    """The adaptation's first curve is traced at ``first_samples`` unless the caller
    fixed N (then at that N), and the samples stay free to rise."""
    seen = []
    trace = analysis._trace

    def spy(prob, *args, **kwargs):
        seen.append(prob.hb.n_samples)
        return trace(prob, *args, **kwargs)
    monkeypatch.setattr(analysis, "_trace", spy)
    monkeypatch.setattr(resolution, "MULTI_DOF", 0)  # the 1-DOF system as a big one
    opts = hbm.HBMOptions(harmonics=5, max_harmonics=5, max_samples=128)
    hbm.frequency_response(friction_system(), 2.0, 12.0, options=opts)
    assert seen[0] == 128
    seen.clear()
    hbm.frequency_response(friction_system(), 2.0, 12.0, n_samples=64, options=opts)
    assert set(seen) == {64}
    seen.clear()
    monkeypatch.setattr(resolution, "MULTI_DOF", 3)
    hbm.frequency_response(friction_system(), 2.0, 12.0, options=opts)
    assert seen[0] == 64
