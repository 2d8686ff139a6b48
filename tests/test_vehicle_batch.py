"""Batched native time stepping (vehicle.batch): the vectorised law against the scalar
law of fmu_src, batched steady states against one steady state per frequency.

Runtime: about 4 s CPU (7-17 s wall on the shared 2-core machine)."""

from __future__ import annotations

import numpy as np
import pytest

import drymount.vehicle as vehicle
from drymount import api
from drymount.fmu_src.mount_law import AxisParameters, MountParameters, axis_force
from drymount.hbm.systems import sdof
from drymount.vehicle.batch import VectorLaw, steady_states
from drymount.vehicle.steady import steady_state

#: The vectorised law performs the scalar law's floating-point operations in the same
#: order: measured difference 0 (bit for bit); the bar set for a second implementation.
LAW_RTOL = 1e-12
#: Batched and per-frequency steady states run the same periods from the same start;
#: the batched matrix-vector product may sum in another order than np.dot (round-off
#: only). Measured 0 on quarter_car_halved and on the three-mount 6-DOF model.
STEADY_RTOL = 1e-12


def _axes():
    """One axis of every law, with and without friction, stuck and slipping."""
    return [
        AxisParameters(law="linear", k1=9e4, c=120.0),
        AxisParameters(law="cubic", k1=3.5e4, kc=5.7e8, c=150.0, friction=True,
                       kf=6e4, n0=20.0),
        AxisParameters(law="piecewise", friction=True, kf=6e4, n0=15.0),
        AxisParameters(law="piecewise_asym", k1=8e4, k2=4e5, delta=0.004,
                       delta_neg=0.002, c=90.0),
        AxisParameters(law="piecewise", k1=5e4, k2=2e5, delta=0.003, friction=True,
                       kf=1e5, n0=0.0),  # friction on, slip force 0: always slips
    ]


def _scalar_run(axes, u, v, w0):
    """The scalar law column by column over the trajectory (steps, B, m)."""
    T, B, m = u.shape
    out = {k: np.empty((T, B, m)) for k in ("force", "ffr", "w", "diss")}
    for b in range(B):
        for i, p in enumerate(axes):
            w = w0[b, i]
            for t in range(T):
                r = axis_force(float(u[t, b, i]), float(v[t, b, i]), w, p)
                w = r.w_new if p.friction else w
                out["force"][t, b, i] = r.force
                out["ffr"][t, b, i] = r.friction_force
                out["w"][t, b, i] = w
                out["diss"][t, b, i] = r.dissipated
    return out


def test_vector_law_equals_scalar_law_on_random_trajectories():
    rng = np.random.default_rng(15)
    axes = _axes()
    T, B, m = 400, 7, len(axes)
    # random walks across the knees (+-5 mm) with many reversals, and random rates
    u = np.cumsum(rng.normal(0.0, 8e-4, (T, B, m)), axis=0)
    v = rng.normal(0.0, 0.05, (T, B, m))
    w0 = rng.normal(0.0, 1e-4, (B, m))
    ref = _scalar_run(axes, u, v, w0)
    law = VectorLaw(axes)
    w = w0.copy()
    worst = 0.0
    for t in range(T):
        s = law.step(u[t], v[t], w)
        w = s.w_new
        for got, key in ((s.force, "force"), (s.friction_force, "ffr"),
                         (s.w_new, "w"), (s.dissipated, "diss")):
            r = ref[key][t]
            err = np.abs(got - r) / np.maximum(np.abs(r), 1e-300)
            worst = max(worst, float(np.max(np.where(r == 0, np.abs(got), err))))
    assert worst <= LAW_RTOL
    # the trajectories exercise what they should: slips, sticks, both knees
    assert np.any(ref["diss"][:, :, 1] > 0) and np.any(ref["diss"][:, :, 1] == 0)
    assert np.any(u[:, :, 2] > 0.01225) and np.any(u[:, :, 3] < -0.002)


def test_vector_law_rejects_unknown_input():
    with pytest.raises(TypeError, match="AxisParameters"):
        VectorLaw([AxisParameters(), "linear"])


def _compare(system, freqs):
    ref = [steady_state(system, f, backend="inproc") for f in freqs]
    got = steady_states(system, freqs, batch_size=3)
    worst = 0.0
    for a, b in zip(ref, got, strict=True):
        assert b.freq_hz == a.freq_hz and b.n_periods == a.n_periods
        assert b.converged == a.converged and b.n_steps == a.n_steps
        for x, y in ((a.amplitude, b.amplitude), (a.peak, b.peak),
                     (np.array([a.transmissibility]), np.array([b.transmissibility])),
                     (np.array([a.friction_energy]), np.array([b.friction_energy])),
                     (a.sliders, b.sliders)):
            scale = np.maximum(np.abs(x), 1e-300)
            worst = max(worst, float(np.max(np.where(x == 0, np.abs(y),
                                                     np.abs(y - x) / scale))))
    return worst


def test_batched_steady_states_equal_per_frequency_runs():
    """Quarter car (one friction mount, piecewise law): 5 frequencies in batches of
    at most 3 (frequencies leave a batch as they converge)."""
    s = api.load("quarter_car_halved").system
    assert _compare(s, [1.5, 4.5, 4.8, 9.0, 20.0]) <= STEADY_RTOL


def test_batched_steady_states_several_mounts():
    """Three mounts, several axes each (the 6-DOF model): two frequencies."""
    s = api.load("six_dof_halved").system
    assert _compare(s, [7.0, 12.0]) <= STEADY_RTOL


def test_batched_sweep_matches_serial_sweep_outside_bistable_bands():
    """A linear SDOF has one steady state: the batched sweep (linearised start at
    every frequency) and the serial sweep (previous steady state) agree to what the
    steady-state tolerance leaves (measured 1.5e-5 here)."""
    ax = AxisParameters(law="linear", k1=91870.0, c=150.0)
    s = sdof(70.0, MountParameters.from_axial(ax), "unbalance", 0.01)
    f = np.linspace(3.0, 9.0, 7)
    serial = vehicle.sweep(s, f, backend="inproc", progress=False)
    batch = vehicle.sweep(s, f, backend="inproc", progress=False, batch=True)
    assert batch.notes["batch"] and batch.success
    np.testing.assert_allclose(batch.amplitude, serial.amplitude, rtol=1e-4)


def test_batched_sweep_needs_the_inproc_backend_in_one_process():
    s = api.load("quarter_car_halved").system
    with pytest.raises(ValueError, match="backend 'inproc' and workers 1"):
        vehicle.sweep(s, [3.0, 4.0], backend="inproc", workers=2, batch=True,
                      progress=False)
    with pytest.raises(ValueError, match="backend 'inproc' and workers 1"):
        vehicle.sweep(s, [3.0, 4.0], backend="fmu", batch=True, progress=False)


def test_batched_steady_states_group_by_steps_per_period():
    """Below 1 / (256 dt_limit) a period needs more than 256 steps: frequencies with
    different steps per period run in separate lock-step groups (here 512, 366 and
    256 steps) and come back in the order given."""
    from drymount.vehicle.master import Master

    s = api.load("sdof_halved").system
    f_256 = 1.0 / (256 * Master(s, "inproc").dt_limit())
    freqs = [0.5 * f_256, 1.5 * f_256, 0.7 * f_256]
    assert _compare(s, freqs) <= STEADY_RTOL
    got = steady_states(s, freqs)
    assert [g.freq_hz for g in got] == freqs
    assert len({g.steps_per_period for g in got}) == 3


def test_stopped_batched_sweep_keeps_the_converged_frequencies(monkeypatch):
    """A stop (here an error after the second converged frequency) hands the caller
    the frequencies that converged, on the exception."""
    import drymount.vehicle.batch as vb

    real = vb._analyse
    calls = []

    def analyse(*args):
        if len(calls) == 2:
            raise KeyboardInterrupt
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(vb, "_analyse", analyse)
    s = api.load("quarter_car_halved").system
    with pytest.raises(KeyboardInterrupt) as info:
        vehicle.sweep(s, [2.0, 3.0, 9.0, 10.0], backend="inproc", batch=True,
                      progress=False)
    part = info.value.partial_result
    assert len(part.freq_hz) == 2 and "stopped" in part.notes


def _friction_system(kind: str):
    """The SDOF of sdof_microslip's mount with the friction element ``kind``."""
    from dataclasses import replace

    base = api.load("sdof_microslip").system.elements[0].params.axial
    axis = {"non-symmetric": replace(base, sliders=1),
            "micro-slip": base,
            "micro-slip symmetric": replace(base, fs_ratio=1.0),
            "inclined": api.load("sdof_inclined").system.elements[0].params.axial,
            }[kind]
    return sdof(70.0, MountParameters.from_axial(axis), "unbalance", 0.030478)


@pytest.mark.parametrize("kind", ["non-symmetric", "micro-slip",
                                  "micro-slip symmetric", "inclined"])
def test_batched_steady_states_equal_per_frequency_for_every_element(kind):
    """Every friction element runs batched (its own scalar step where VectorLaw has
    no vector port) and equals the per-frequency run (was: +5.2 % at 6 Hz for
    non-symmetric friction, a reshape error for micro-slip, a refusal for the
    inclined element)."""
    s = _friction_system(kind)
    assert _compare(s, [3.0, 6.0, 11.0]) <= STEADY_RTOL
    p = s.elements[0].params.axial
    assert VectorLaw([p]).generic == [0]
