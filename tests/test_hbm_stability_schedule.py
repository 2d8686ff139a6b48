"""The schedule of Hill evaluations along a branch
(hbm.stability_schedule.schedule_verdicts): verdicts equal to evaluating every point for
verdict patterns with changes at sign changes of det J, away from them (a complex pair
crossing) and short islands near the stability boundary, with fewer evaluations."""

import numpy as np
import pytest

from drymount.hbm.stability_schedule import MARGIN_SLOPE, schedule_verdicts


def _run(g, det_sign, stride, slope=MARGIN_SLOPE):
    """Schedule for a branch whose point i has the deciding real part g[i] (relative
    to omega; unstable where > 0)."""
    calls = []

    def evaluate(i):
        calls.append(i)
        return bool(g[i] <= 0), float(g[i]), abs(float(g[i]))

    s = schedule_verdicts(np.asarray(det_sign, float), evaluate, stride, slope)
    assert sorted(calls) == sorted(set(calls))  # no point evaluated twice
    np.testing.assert_array_equal(s.evaluated, np.isin(np.arange(len(g)), calls))
    return s, calls


def _profile(npts):
    """A smooth margin profile with one long unstable band (complex crossing, no det
    sign change), one band bounded by det sign changes (folds) and a 3-point island
    where the real part just grazes the boundary."""
    x = np.arange(npts, dtype=float)
    g = -0.05 + 0.1 * np.exp(-((x - 80) / 40) ** 2)  # unstable about 47..113
    g[200:251] = 0.02  # folds at 200 and 251
    near = slice(270, 320)
    g[near] = np.maximum(g[near], -0.0015 - 0.0025 * np.abs(x[near] - 295))
    g[294:297] = 0.0005  # a 3-point unstable island
    det = np.ones(npts)
    det[200:251] = -1.0
    det[260:262] = -1.0  # det sign changes with no verdict change
    return g, det


@pytest.mark.parametrize("stride", [4, 16, 64])
def test_schedule_reproduces_every_point(stride):
    g, det = _profile(360)
    s, calls = _run(g, det, stride)
    np.testing.assert_array_equal(s.stable, g <= 0)
    assert np.all(np.isnan(s.max_real[~s.evaluated]))
    np.testing.assert_array_equal(s.max_real[s.evaluated], g[s.evaluated])
    if stride >= 16:
        assert len(calls) < 360 / 5  # measured: 54 (16), 49 (64) of 360; 106 (4)


def test_island_needs_the_margin_rule():
    """Without the margin rule (slope 0) a stride of 64 steps over the island."""
    g, det = _profile(360)
    s, _ = _run(g, det, 64, slope=0.0)
    assert not np.array_equal(s.stable, g <= 0)


def test_stride_one_evaluates_every_point():
    g = np.where(np.arange(20) % 3 == 0, 0.1, -0.1)
    s, calls = _run(g, np.ones(20), 1)
    np.testing.assert_array_equal(s.stable, g <= 0)
    assert sorted(calls) == list(range(20))


def test_unknown_margin_is_refined():
    """A failed evaluation (margin NaN) counts as on the boundary: its neighbours are
    evaluated."""
    g = -0.1 * np.ones(65)

    def evaluate(i):
        return True, float("nan") if i == 0 else -0.1, float("nan") if i == 0 else 0.1

    s = schedule_verdicts(np.ones(65), evaluate, 64)
    assert s.evaluated[32]
    np.testing.assert_array_equal(s.stable, g <= 0)
