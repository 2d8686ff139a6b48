"""The hydraulic mount's fluid path in the three FMU builds (PythonFMU FMI 2.0, native
C FMI 2.0 and 3.0): against the in-process law on random trajectories (1e-12 of each
output's scale), the fluid states through a serialized FMU state (restored in a
fresh instance, the second half replays identically), and the preset
``sdof_hydraulic`` co-simulated with the backend ``fmu`` against ``inproc`` (bit for
bit: the same law, the same operations). Runtime about 10 s (two native builds, one
PythonFMU build)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_dynamic_friction import RTOL_FMU, H, _reference
from test_fmu_maxwell import _run_and_restore, _worst

from drymount.fmu_src.mount_law import HYDRAULIC_AXIS_FIELDS

STEPS = 1200

#: the fluid of the preset sdof_hydraulic, plus a decoupler on some axes
FLUID = dict(hyd_Ap=5e-3, hyd_C1=1e-10, hyd_C2=1e-9, hyd_I_i=1e6, hyd_R_i=1e8)
DECOUPLER = dict(hyd_I_d=2e4, hyd_R_d=3e6)


def _instance(rng):
    """Three axes with the fluid: beside Jenkins with a decoupler, beside a Maxwell
    branch and LuGre, alone on a linear rubber."""
    from native_helpers import random_axis

    return (replace(random_axis(rng, "piecewise", True), **FLUID, **DECOUPLER),
            replace(random_axis(rng, "cubic", True), friction_kind="lugre",
                    sigma1=100.0, stribeck_ratio=1.4, v_stribeck=0.05,
                    maxwell_k1=4e4, maxwell_c1=300.0, **FLUID),
            replace(random_axis(rng, "linear", False),
                    **{**FLUID, "hyd_R_i": 3e7}, hyd_I_d=5e3, hyd_R_d=0.0))


def _without_fluid(axes):
    return tuple(replace(p, **dict.fromkeys(HYDRAULIC_AXIS_FIELDS, 0.0)) for p in axes)


@pytest.fixture(scope="module")
def native_fmus(tmp_path_factory):
    from native_helpers import build
    folder = tmp_path_factory.mktemp("hydraulic_native")
    return {fmi: build(folder, fmi) for fmi in (2, 3)}


@pytest.fixture(scope="module")
def python_fmu(tmp_path_factory):
    from drymount.fmu_build import build_fmu
    return build_fmu(tmp_path_factory.mktemp("hydraulic_py") / "FrictionMount.fmu")


def _check(path, seed, magic, steps=STEPS):
    from native_helpers import random_trajectory

    rng = np.random.default_rng(seed)
    axes = _instance(rng)
    assert all(p.has_hydraulic for p in axes)
    traj = random_trajectory(rng, steps, h=H, amplitude=0.004, n0=300.0)
    ref = _reference(axes, traj)
    got, again, half = _run_and_restore(path, axes, traj, magic)
    assert _worst(got, ref) <= RTOL_FMU
    assert np.array_equal(again[half:], got[half:])
    # the fluid carries force: the reference without it differs
    assert _worst(_reference(_without_fluid(axes), traj), ref) > 1e-3


@pytest.mark.parametrize("fmi", [2, 3])
def test_native_fmu_with_the_fluid_equals_the_law(fmi, native_fmus):
    pytest.importorskip("fmpy")
    _check(native_fmus[fmi], 2830 + fmi, b"DMNTST07")


def test_pythonfmu_with_the_fluid_equals_the_law(python_fmu):
    pytest.importorskip("fmpy")
    _check(python_fmu, 2840, b"DMPYST01", steps=600)


@pytest.mark.parametrize("build", ["python", "native2", "native3"])
def test_sdof_hydraulic_fmu_backend_equals_inproc(build, request):
    pytest.importorskip("fmpy")
    from drymount.config import load_preset
    from drymount.vehicle.steady import steady_state

    path = request.getfixturevalue("python_fmu") if build == "python" else \
        request.getfixturevalue("native_fmus")[int(build[-1])]
    system = load_preset("sdof_hydraulic").system
    # 30 periods from the linear start (converged or not: the same periods compared)
    kw = dict(steps_per_period=64, rtol=1e-10, max_periods=30)
    for f_hz in (7.0, 16.0):
        a = steady_state(system, f_hz, backend="inproc", **kw)
        b = steady_state(system, f_hz, backend="fmu", fmu_path=path, **kw)
        assert a.n_periods == b.n_periods
        assert np.array_equal(a.phasor, b.phasor), (f_hz, a.phasor, b.phasor)


@pytest.mark.parametrize("fmi", [2, 3])
def test_model_exchange_refuses_the_fluid_naming_the_parameter(fmi, native_fmus):
    """docs/fmu.md 7a: Model Exchange does not carry the fluid states."""
    pytest.importorskip("fmpy")
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Model
    from fmpy.fmi3 import FMU3Model

    path = native_fmus[fmi]
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    model = (FMU2Model if fmi == 2 else FMU3Model)(
        guid=md.guid, unzipDirectory=extract(str(path)), instanceName="me",
        modelIdentifier=md.modelExchange.modelIdentifier)
    heard = []
    if fmi == 2:
        from test_fmu_small_items import _callbacks
        model.instantiate(loggingOn=True, callbacks=_callbacks(heard))
    else:
        model.instantiate(loggingOn=True, logMessage=lambda env, status, cat, msg:
                          heard.append(msg.decode("utf-8", "replace")))
    names = ["radial1_hyd_Ap", "radial1_hyd_C1", "radial1_hyd_C2", "radial1_hyd_I_i"]
    (model.setReal if fmi == 2 else model.setFloat64)(
        [vr[n] for n in names], [5e-3, 1e-10, 1e-9, 1e6])
    if fmi == 2:
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
    else:
        model.enterInitializationMode(startTime=0.0)
    with pytest.raises(FMICallException):
        model.exitInitializationMode()
    model.freeInstance()
    log = "\n".join(heard)
    assert "`radial1_hyd_Ap` = 0.005: the hydraulic fluid path is Co-Simulation " \
           "only" in log, log
