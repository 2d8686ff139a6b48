"""The schedule of Hill evaluations along a branch (hbm.stability_schedule._stability):
verdicts equal to evaluating every point for a verdict pattern with changes both at
sign changes of det J and away from them (a complex pair crossing), with fewer
evaluations."""

from types import SimpleNamespace

import numpy as np
import pytest

import hbm.stability_schedule as an


def _run(monkeypatch, unstable, det_sign, stride):
    """_stability on a fake branch whose point i has the given verdict and det sign."""
    npts = len(unstable)
    calls = []

    def fake_is_stable(hb, J, w):
        i = int(round(J[1, 1]))
        calls.append(i)
        return (not unstable[i]), (1.0 if unstable[i] else -1.0)

    monkeypatch.setattr(an, "is_stable", fake_is_stable)
    # J = diag(sign, i): det sign as given, the point's index readable from J[1, 1]
    jac = [np.array([[det_sign[i], 0.0, 0.0], [0.0, i + 0.0, 0.0]])
           for i in range(npts)]
    prob = SimpleNamespace(hb=None, rs=np.ones(2), xs=np.ones(2),
                           x_of=lambda y: (None, 1.0))
    br = SimpleNamespace(jacobian=jac)
    stable, fmr = an._stability(prob, [None] * npts, br, stride)
    return stable, calls


@pytest.mark.parametrize("stride", [4, 16, 32])
def test_schedule_reproduces_every_point(monkeypatch, stride):
    npts = 300
    unstable = np.zeros(npts, bool)
    unstable[37:121] = True  # changes away from det sign changes (bisection)
    unstable[200:251] = True  # changes at det sign changes
    det_sign = np.ones(npts)
    det_sign[200:251] = -1.0
    det_sign[260:262] = -1.0  # sign changes with no verdict change
    stable, calls = _run(monkeypatch, unstable, det_sign, stride)
    np.testing.assert_array_equal(stable, ~unstable)
    assert len(set(calls)) == len(calls)  # no point evaluated twice
    if stride >= 16:
        assert len(calls) < npts / 4  # measured: 56 (16), 46 (32) of 300; 107 (4)


def test_stride_one_evaluates_every_point(monkeypatch):
    unstable = np.arange(20) % 3 == 0
    stable, calls = _run(monkeypatch, unstable, np.ones(20), 1)
    np.testing.assert_array_equal(stable, ~unstable)
    assert sorted(calls) == list(range(20))
