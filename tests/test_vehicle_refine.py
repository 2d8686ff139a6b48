"""Sweeps that find the peak (vehicle.refine, ``sweep(refine=...)``): the target
rules on closed forms, and the peak of quarter_car_halved against harmonic balance.

Runtime: about 6 s CPU (12 s wall on the shared 2-core machine)."""

from __future__ import annotations

import numpy as np
import pytest

import drymount.vehicle as vehicle
from drymount import api
from drymount.vehicle.refine import hbm_targets, refine_targets

#: The issue's bar: a 30-point sweep with refinement reads the HBM peak within 1 %.
#: Measured: +0.15 % with 8 extra points, -0.04 % with 4 guided by the HBM curve
#: (the sweep's discretisation, 256 steps per period, and HBM's 7 harmonics differ
#: at that level); the plain 30-point grid reads it 11.7 % low.
PEAK_RTOL = 0.01


def test_vertex_of_a_parabola_is_exact():
    """On y = 3 - 2 (f - 4.77)^2 the first target is the parabola's vertex."""
    f = np.linspace(0.5, 30.0, 30)
    y = 2000.0 - 2.0 * (f - 4.77) ** 2  # positive on the band
    assert refine_targets(f, y, 1, min_step=1e-3) == [pytest.approx(4.77, rel=1e-12)]
    assert len(refine_targets(f, y, 3, min_step=1e-3)) == 3


def test_targets_keep_their_distance_and_honour_first():
    f = np.array([1.0, 2.0, 3.0, 4.0])
    tr = np.array([1.0, 2.0, 1.5, 1.0])
    got = refine_targets(f, tr, 5, min_step=0.3, first=[2.1, 3.5])
    assert got[0] == 3.5  # 2.1 is within min_step of 2.0
    allf = np.sort(np.concatenate([f, got]))
    assert np.min(np.diff(allf)) >= 0.3 - 1e-12
    assert len(got) <= 5


def test_hbm_targets_peak_and_folds():
    """A folded curve in continuation order: up to 5.0 Hz, back to 4.0, up again."""
    f = np.array([3.0, 4.0, 5.0, 4.5, 4.0, 4.5, 6.0])
    tr = np.array([1.0, 2.0, 4.0, 3.0, 1.0, 0.8, 0.5])
    assert hbm_targets(f, tr, 0.5, 30.0) == [5.0, 5.0, 4.0]
    assert hbm_targets(f, tr, 4.5, 30.0) == [5.0, 5.0]
    with pytest.raises(ValueError, match="as many"):
        hbm_targets(f, tr[:3], 0.5, 30.0)


@pytest.fixture(scope="module")
def quarter_car():
    m = api.load("quarter_car_halved")
    curve = api.hbm(m, progress=False)
    return m, curve


def _peak(res):
    return float(np.max(res.transmissibility))


def test_refined_sweep_reads_the_hbm_peak(quarter_car):
    m, curve = quarter_car
    ref = float(np.max(curve.transmissibility))
    f = np.linspace(0.5, 30.0, 30)
    plain = vehicle.sweep(m.system, f, backend="inproc", progress=False, batch=True)
    refined = vehicle.sweep(m.system, f, backend="inproc", progress=False, refine=8)
    guided = vehicle.sweep(m.system, f, backend="inproc", progress=False, refine=4,
                           hbm=curve, batch=True)
    assert abs(_peak(plain) / ref - 1) > 0.05  # the grid alone misses it
    assert abs(_peak(refined) / ref - 1) <= PEAK_RTOL
    assert abs(_peak(guided) / ref - 1) <= PEAK_RTOL
    assert len(refined.freq_hz) == 38 and np.all(np.diff(refined.freq_hz) > 0)
    assert refined.notes["refined"] and refined.success
    assert guided.notes["refined"][0] == pytest.approx(
        float(curve.freq_hz[np.argmax(curve.transmissibility)]))


def test_refine_must_be_a_count():
    with pytest.raises(ValueError, match="`refine` must be an integer >= 0"):
        vehicle.sweep(api.load("quarter_car_halved").system, [3.0, 4.0],
                      backend="inproc", refine=-1, progress=False)
