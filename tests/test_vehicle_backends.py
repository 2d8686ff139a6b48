"""Vehicle harness, FMU backend mechanics: FMI call counts, errors naming the mount
and the time, instances always freed; native backend bookkeeping."""

from __future__ import annotations

import functools
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.vehicle import FMUError
from drymount.vehicle.master import Master
from drymount.hbm.systems import rigid_engine, sdof
from drymount.vehicle.steady import run_steady

ROOT = Path(__file__).resolve().parents[1]
POSITIONS = [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)]


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory):
    from drymount.fmu_build import build_fmu

    return build_fmu(tmp_path_factory.mktemp("fmu") / "FrictionMount.fmu")


@pytest.fixture(scope="module")
def null_fmu(tmp_path_factory):
    """bench/null_mount.py built in a subprocess (keeps this process clean)."""
    dest = tmp_path_factory.mktemp("null") / "NullMount.fmu"
    code = ("from pythonfmu.builder import FmuBuilder; FmuBuilder.build_FMU("
            f"{str(ROOT / 'bench' / 'null_mount.py')!r}, dest={str(dest)!r})")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=dest.parent)
    return dest


def six_dof():
    ax = AxisParameters(law="piecewise", friction=True, n0=20.0)
    mounts = [MountParameters.from_axial(ax, 1.0, friction_axes=f)
              for f in (("radial1",), ("radial2",), ("axial",))]
    return rigid_engine(140.8, [8.63, 10.02, 10.22], POSITIONS, mounts)


def sdof_axial():
    return sdof(70.0, MountParameters.from_axial(AxisParameters(law="linear")),
                "force", 50.0)


@pytest.fixture
def fmi_counter(monkeypatch):
    """Count the raw FMI calls and the instance lifecycle calls of FMU2Slave."""
    from fmpy.fmi2 import FMU2Slave

    counts = dict.fromkeys(["fmi2SetReal", "fmi2GetReal", "fmi2DoStep", "instantiate",
                            "terminate", "freeInstance"], 0)
    for name in counts:
        orig = getattr(FMU2Slave, name)

        # wraps: fmpy derives the ctypes argtypes from the method's signature
        @functools.wraps(orig)
        def wrapper(self, *a, _orig=orig, _name=name, **kw):
            counts[_name] += 1
            return _orig(self, *a, **kw)
        monkeypatch.setattr(FMU2Slave, name, wrapper)
    # the stepping loop calls the FMU's functions directly (backends.raw_fmi_calls),
    # not through FMU2Slave's methods: count those calls under the same names
    import drymount.vehicle.backends as backends

    orig_raw = backends.raw_fmi_calls

    def counted_raw(fmu, h, t_arg):
        r = orig_raw(fmu, h, t_arg)
        for attr, name in (("set_real", "fmi2SetReal"), ("get_real", "fmi2GetReal"),
                           ("do_step", "fmi2DoStep")):
            fn = getattr(r, attr)

            def call(*a, _f=fn, _name=name):
                counts[_name] += 1
                return _f(*a)
            setattr(r, attr, call)
        return r
    monkeypatch.setattr(backends, "raw_fmi_calls", counted_raw)
    return counts


def test_one_set_get_dostep_per_mount_and_step(fmu_path, fmi_counter):
    system = six_dof()
    nm = len(system.elements)
    with Master(system, "fmu", fmu_path=fmu_path) as m:
        setup_set = fmi_counter["fmi2SetReal"]
        setup_get = fmi_counter["fmi2GetReal"]
        assert fmi_counter["instantiate"] == nm
        ss = run_steady(m, 6.0, min_periods=2, max_periods=2)
        n = ss.n_steps
        assert n == 2 * ss.steps_per_period
        assert fmi_counter["fmi2DoStep"] == nm * n
        assert fmi_counter["fmi2SetReal"] - setup_set == nm * n
        # plus one read of E_fr before the run and of the sliders after it
        assert fmi_counter["fmi2GetReal"] - setup_get == nm * n + 2 * nm
    assert fmi_counter["terminate"] == nm
    assert fmi_counter["freeInstance"] == nm


def test_only_active_axes_are_exchanged(fmu_path):
    """SDOF: only the axial axis is active, so 2 inputs (u, v) and 3 outputs (F, Ffr,
    E_fr) are exchanged per step; radial inputs stay at their start values."""
    system = sdof_axial()
    assert system.elements[0].active_axes == (0,)
    with Master(system, "fmu", fmu_path=fmu_path) as m:
        assert m.backend._nin == [2] and m.backend._nout == [3]
        run_steady(m, 5.0, min_periods=1, max_periods=1)
        fmu = m.backend._fmus[0]
        vr = {v: m.backend._vars[v].valueReference
              for v in ("u_radial1", "v_radial2", "u_axial")}
        vals = fmu.getReal(list(vr.values()))
        assert vals[0] == 0.0 and vals[1] == 0.0 and vals[2] != 0.0


def test_error_in_do_step_names_mount_and_time_and_frees(null_fmu, fmi_counter):
    system = six_dof()
    fail_at = 0.01
    with pytest.raises(FMUError) as info:
        with Master(system, "fmu", fmu_path=null_fmu,
                    fmu_start_values={"mount2": {"fail_at": fail_at}}) as m:
            run_steady(m, 6.0, start="rest")
    err = info.value
    h = 1.0 / (6.0 * 256)
    assert err.mount == "mount2"
    assert fail_at <= err.time < fail_at + h + 1e-12
    assert err.function == "fmi2DoStep"
    assert "mount2" in str(err) and f"{err.time:.9g}" in str(err)
    assert any("requested failure" in line for line in err.log)
    assert fmi_counter["instantiate"] == 3
    assert fmi_counter["freeInstance"] == 3


def test_error_at_initialisation_names_mount_and_frees(fmu_path, fmi_counter):
    """An invalid parameter reaches the FMU (bypassing AxisParameters' checks): its
    exitInitializationMode fails; the error names the mount, t = 0 and quotes the
    FMU's log; the instances made so far are freed."""
    system = six_dof()
    with pytest.raises(FMUError) as info:
        Master(system, "fmu", fmu_path=fmu_path,
               fmu_start_values={"mount2": {"axial_k1": -1.0}})
    err = info.value
    assert err.mount == "mount2"
    assert err.time == 0.0
    assert any("axial_k1" in line for line in err.log), err.log
    assert fmi_counter["instantiate"] == 2
    assert fmi_counter["freeInstance"] == 2


def test_unknown_start_value_is_rejected(fmu_path):
    with pytest.raises(ValueError, match="unknown FMU variables"):
        Master(sdof_axial(), "fmu", fmu_path=fmu_path,
               fmu_start_values={"no_such_variable": 1.0})


def test_unknown_backend_is_rejected():
    with pytest.raises(ValueError, match="`backend` must be one of"):
        Master(sdof_axial(), "ode45")


def test_sliders_round_trip_between_backends(fmu_path):
    """A steady state's end (state and sliders) restarts a fresh FMU master exactly
    where the native one stopped."""
    system = six_dof()
    with Master(system, "inproc") as m:
        a = run_steady(m, 6.0, start="linear")
        b = run_steady(m, 6.5)
    assert np.any(a.sliders != 0.0)
    with Master(system, "fmu", fmu_path=fmu_path) as m:
        c = run_steady(m, 6.5, start=a)
    np.testing.assert_allclose(c.amplitude, b.amplitude, rtol=1e-12)
    np.testing.assert_allclose(c.sliders, b.sliders, rtol=1e-12, atol=1e-15)
