"""The FMU backend's stepping loop in C (vehicle.c_loop) against the Python loop it
replaces (vehicle.backends.FMUBackend.run, the reference): the same runs through
both paths must agree bit for bit (the C loop makes the same FMI calls and the same
BLAS product), errors and interrupts must leave the same state, and the C loop is
chosen only where valid."""

from __future__ import annotations

import numpy as np
import pytest

from drymount.fmu_build.native import build_native_fmu
from drymount.fmu_src.mount_law import AxisParameters, MountParameters
from drymount.hbm.systems import rigid_engine, sdof
from drymount.vehicle import c_loop
from drymount.vehicle.backends import FMUError
from drymount.vehicle.master import Master

FIELDS = ("q", "qd", "forces", "friction_forces", "deflections", "friction_energy")

pytestmark = pytest.mark.skipif(c_loop.library()[0] is None,
                                reason=f"C loop not built: {c_loop.library()[1]}")


def _systems():
    ax = AxisParameters(law="piecewise", friction=True, n0=10.0)
    s1 = sdof(70.0, MountParameters.from_axial(ax), "unbalance", 0.01)
    mounts = [MountParameters.from_axial(ax, 1.0, friction_axes=f)
              for f in (("radial1",), ("radial2",), ("axial",))]
    s6 = rigid_engine(140.8, [8.63, 10.02, 10.22],
                      [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)],
                      mounts)
    return {"sdof": s1, "six_dof": s6}


SYSTEMS = _systems()


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def native(request, tmp_path_factory):
    name = "FrictionMountNative.fmu" if request.param == 2 else \
        "FrictionMountNative3.fmu"
    return build_native_fmu(tmp_path_factory.mktemp("cl") / name,
                            fmi=request.param).path


def _history(system, fmu, monkeypatch, enabled: bool, duration=0.5):
    monkeypatch.setenv("DRYMOUNT_C_LOOP", "1" if enabled else "0")
    with Master(system, "fmu", fmu_path=fmu) as m:
        th = m.simulate(duration, freq_hz=6.0)
        used = m.backend._c_loop is not None
        return th, used, m.backend.steps, m.sliders()


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_c_loop_equals_python_loop_bit_for_bit(native, name, monkeypatch):
    a, used_c, steps_c, w_c = _history(SYSTEMS[name], native, monkeypatch, True)
    b, used_py, steps_py, w_py = _history(SYSTEMS[name], native, monkeypatch, False)
    assert used_c and not used_py
    assert steps_c == steps_py == a.q.shape[0]
    for f in FIELDS:
        assert np.array_equal(getattr(a, f), getattr(b, f)), f
    assert np.array_equal(w_c, w_py)
    assert np.ptp(a.forces) > 0  # a run that moves the mounts


def test_periods_through_both_loops_agree(native, monkeypatch):
    from drymount.vehicle.inputs import HarmonicInput

    out = []
    for enabled in (True, False):
        monkeypatch.setenv("DRYMOUNT_C_LOOP", "1" if enabled else "0")
        with Master(SYSTEMS["six_dof"], "fmu", fmu_path=native) as m:
            m.begin_periodic(HarmonicInput(m.system, 6.0), 256, 1.0 / (6 * 256))
            recs = [m.run_period() for _ in range(3)]
            out.append((recs, m.time))
    (ra, ta), (rb, tb) = out
    assert ta == tb
    for x, y in zip(ra, rb, strict=True):
        for f in ("q", "qd", "forces", "friction_forces", "energy", "q_end"):
            assert np.array_equal(getattr(x, f), getattr(y, f)), f


def test_a_failing_call_raises_the_same_fmu_error(native, monkeypatch):
    """Time going backwards (a doStep at an earlier time) is refused by the FMU:
    both loops raise the same FMUError after the same number of steps."""
    errs = []
    for enabled in (True, False):
        monkeypatch.setenv("DRYMOUNT_C_LOOP", "1" if enabled else "0")
        with Master(SYSTEMS["sdof"], "fmu", fmu_path=native) as m:
            m.simulate(0.01, freq_hz=6.0)
            be = m.backend
            steps = be.steps
            with pytest.raises(FMUError) as info:
                be.run(0, 5, [0.0] * 5)
            errs.append((info.value.function, info.value.status, info.value.mount,
                         be.steps - steps))
    assert errs[0] == errs[1]
    assert errs[0][0] is not None and errs[0][1] >= 2


def test_interrupt_between_chunks_keeps_the_rows_done(native, monkeypatch):
    """A KeyboardInterrupt seen between two C chunks stops the run like one between
    two Python steps: the partial history holds the blocks completed, equal to the
    uninterrupted run's rows."""
    full, *_ = _history(SYSTEMS["sdof"], native, monkeypatch, True, duration=2.0)
    monkeypatch.setattr(c_loop, "CHUNK", 1024)
    calls = []
    real = c_loop.CLoop.__init__

    def init(self, *args):
        real(self, *args)
        lib = self.lib

        class Lib:
            def dm_run(self, *a):
                calls.append(1)
                if len(calls) == 3:  # the first chunk of the second block
                    raise KeyboardInterrupt
                return lib.dm_run(*a)

        self.lib = Lib()

    monkeypatch.setattr(c_loop.CLoop, "__init__", init)
    monkeypatch.setenv("DRYMOUNT_C_LOOP", "1")
    with Master(SYSTEMS["sdof"], "fmu", fmu_path=native) as m:
        with pytest.raises(KeyboardInterrupt) as info:
            m.simulate(2.0, freq_hz=6.0)
        assert m.backend.steps == 2048
    part = info.value.partial_result
    assert part.q.shape[0] == 2048
    for f in FIELDS:
        assert np.array_equal(getattr(part, f), getattr(full, f)[:2048]), f


def test_not_used_for_the_pythonfmu_build(tmp_path, monkeypatch, caplog):
    from drymount.fmu_build import build_fmu

    fmu = build_fmu(tmp_path / "FrictionMount.fmu")
    monkeypatch.setenv("DRYMOUNT_C_LOOP", "1")
    with caplog.at_level("DEBUG", logger="drymount.vehicle.c_loop"):
        with Master(SYSTEMS["sdof"], "fmu", fmu_path=fmu) as m:
            m.simulate(0.05, freq_hz=6.0)
            assert m.backend._c_loop is None
    assert "not a native C FMU" in caplog.text


def test_control_runs_the_python_loop(native, monkeypatch):
    """Semi-active control (Python controllers every step) keeps the Python loop,
    whose results are those of the C-free run."""
    from drymount.vehicle.control import ScheduledControl

    ctl = {("mount", "axial"): ScheduledControl((1.0, 10.0), (25.0, 25.0),
                                                signal=lambda t: 6.0)}
    out = []
    for enabled in (True, False):
        monkeypatch.setenv("DRYMOUNT_C_LOOP", "1" if enabled else "0")
        with Master(SYSTEMS["sdof"], "fmu", fmu_path=native, control=ctl) as m:
            if enabled:
                monkeypatch.setattr(c_loop.CLoop, "run", _never)
            out.append(m.simulate(0.05, freq_hz=6.0))
    for f in FIELDS:
        assert np.array_equal(getattr(out[0], f), getattr(out[1], f)), f


def _never(*_a):
    raise AssertionError("the C loop ran under control")
