"""Maxwell branches in the three FMU builds (PythonFMU FMI 2.0, native C FMI 2.0 and
3.0) against the in-process law on random trajectories (1e-12 of each output's
scale), and their strokes through a serialized FMU state: restored in a fresh
instance, the second half replays identically. Runtime about 5 s (two native builds
shared with the module, one PythonFMU build)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_dynamic_friction import RTOL_FMU, H, _Fmu, _reference

STEPS = 1200


def _instance(rng):
    """Three axes with branches: beside LuGre, beside Jenkins, alone."""
    from native_helpers import random_axis

    def mx(p, k, c):
        kw = {}
        for i, (ki, ci) in enumerate(zip(k, c), start=1):
            kw[f"maxwell_k{i}"], kw[f"maxwell_c{i}"] = ki, ci
        return replace(p, **kw)

    return (mx(replace(random_axis(rng, "piecewise", True), friction_kind="lugre",
                       sigma1=100.0, stribeck_ratio=1.4, v_stribeck=0.05),
               (4e4, 1.5e4), (300.0, 20.0)),
            mx(random_axis(rng, "cubic", True), (6e4, 0.0, 2e4), (50.0, 10.0, 900.0)),
            mx(random_axis(rng, "linear", False), (3e4,), (120.0,)))


@pytest.fixture(scope="module")
def native_fmus(tmp_path_factory):
    from native_helpers import build
    folder = tmp_path_factory.mktemp("maxwell_native")
    return {fmi: build(folder, fmi) for fmi in (2, 3)}


def _run_and_restore(path, axes, traj, magic):
    a, b = _Fmu(path), _Fmu(path)
    ref_shape = (traj.u.shape[0], 4, 3)
    got, again = np.zeros(ref_shape), np.zeros(ref_shape)
    half = traj.u.shape[0] // 2
    try:
        a.start(axes)
        a.run(traj, 0, half, got)
        two = a.fmi == 2
        blob = (a.fmu.serializeFMUstate if two else a.fmu.serializeFMUState)(
            (a.fmu.getFMUstate if two else a.fmu.getFMUState)())
        assert bytes(blob[:8]) == magic
        a.run(traj, half, traj.u.shape[0], got)
        b.start(axes)
        state = (b.fmu.deSerializeFMUstate if two else b.fmu.deserializeFMUState)(blob)
        (b.fmu.setFMUstate if two else b.fmu.setFMUState)(state)
        b.run(traj, half, traj.u.shape[0], again)
    finally:
        a.close()
        b.close()
    return got, again, half


def _worst(got, ref):
    scale = np.maximum(np.abs(ref).max(axis=(0, 2)), 1.0)
    return float(np.max(np.abs(got - ref).max(axis=(0, 2)) / scale))


@pytest.mark.parametrize("fmi", [2, 3])
def test_native_fmu_with_maxwell_equals_the_law(fmi, native_fmus):
    pytest.importorskip("fmpy")
    from native_helpers import random_trajectory

    rng = np.random.default_rng(2800 + fmi)
    axes = _instance(rng)
    traj = random_trajectory(rng, STEPS, h=H, amplitude=0.004, n0=300.0)
    ref = _reference(axes, traj)
    got, again, half = _run_and_restore(native_fmus[fmi], axes, traj, b"DMNTST07")
    assert _worst(got, ref) <= RTOL_FMU
    assert np.array_equal(again[half:], got[half:])
    # the branches carry force: the reference without them differs
    bare = _reference(tuple(replace(p, **{f"maxwell_{q}{i}": 0.0 for i in (1, 2, 3)
                                          for q in "kc"}) for p in axes), traj)
    assert _worst(bare, ref) > 1e-3


def test_pythonfmu_with_maxwell_equals_the_law(tmp_path):
    pytest.importorskip("fmpy")
    from native_helpers import random_trajectory

    from drymount.fmu_build import build_fmu

    rng = np.random.default_rng(2810)
    axes = _instance(rng)
    traj = random_trajectory(rng, 600, h=H, amplitude=0.004, n0=300.0)
    ref = _reference(axes, traj)
    got, again, half = _run_and_restore(build_fmu(tmp_path / "FrictionMount.fmu"),
                                        axes, traj, b"DMPYST01")
    assert _worst(got, ref) <= RTOL_FMU
    assert np.array_equal(again[half:], got[half:])
