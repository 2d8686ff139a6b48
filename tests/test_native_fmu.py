"""The native FMUs (FMI 2.0 and FMI 3.0, fmu_build/native.py) against the Python law.

* equivalence with ``fmu_src/mount_law.py`` on the same random trajectories: 4 x 1e5
  steps through the FMI 2.0 binary in a plain C host started with an empty environment
  (two instances side by side; 2 x 2e4 steps with micro-slip and non-symmetric axes),
  4 x 4000 steps through fmpy for each FMI version (2 of them micro-slip and
  non-symmetric; inclined axes where the law has that friction kind);
* ``fmpy validate`` and ``fmpy simulate``; the model description is the interface table;
* the FMI state machine (docs/fmu.md 4a): calls out of order, bad step sizes, time
  jumps, non-finite values (refused at the set), invalid parameters (the PythonFMU's
  message; outputs 0 with a warning before), state get/set/serialize (also with
  micro-slip sliders and inclined elements), reset;
* the binary needs no Python: no libpython, no Py* symbol, only libc and libm.

Runtime about 30 s on 2 cores (most of it the Python reference of 4.4e5 steps).
"""

from __future__ import annotations

import math
import re
import zipfile

from dataclasses import dataclass

import numpy as np
import pytest
from native_helpers import (
    GENERAL_LAYOUT,
    LAW_LAYOUT,
    ROOT,
    Outputs,
    build,
    host_config,
    parameter_values,
    random_general_instance,
    random_instance,
    random_trajectory,
    reference_run,
    run,
    worst_relative,
)

from drymount.fmu_src import interface, mount_law
from drymount.fmu_src.mount_law import AXES, axis_force, initial_sliders

fmpy = pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

#: C and Python agree to this, relative to the output's scale (force, stiffness,
#: energy). Measured: 0.0 (bit-identical) for every output, both FMI versions.
TOL_REL = 1e-12
HOST_STEPS = 100_000
FMPY_STEPS = 4000
H = 1e-4


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def native(request, tmp_path_factory):
    fmi = request.param
    return fmi, build(tmp_path_factory.mktemp(f"native{fmi}"), fmi)


@pytest.fixture(scope="module")
def native2(tmp_path_factory):
    return build(tmp_path_factory.mktemp("native2"), 2)


class Driver:
    """One instance of a native FMU through fmpy (FMI 2.0 or 3.0), messages kept."""

    def __init__(self, path, fmi: int, name: str = "mount"):
        from fmpy import extract, read_model_description

        self.fmi, self.messages, self.name = fmi, [], name
        md = read_model_description(str(path))
        self.md = md
        self.vars = {v.name: v for v in md.modelVariables}
        self.unzip = extract(str(path))
        kw = dict(unzipDirectory=self.unzip, instanceName=name,
                  modelIdentifier=md.coSimulation.modelIdentifier)
        if fmi == 2:
            from fmpy.fmi2 import FMU2Slave

            self.fmu = FMU2Slave(guid=md.guid, **kw)
            from drymount.vehicle.fmi_logging import callbacks

            cb = callbacks(self._log2)  # one process-wide logger (see that module)
            self._cb = cb
            self.fmu.instantiate(callbacks=cb, loggingOn=True)
        else:
            from fmpy.fmi3 import FMU3Slave

            self.fmu = FMU3Slave(guid=md.guid, **kw)
            self.fmu.instantiate(loggingOn=True, logMessage=self._log3)

    def _log2(self, env, instance, status, category, message):
        self.messages.append((status, message.decode()))

    def _log3(self, env, status, category, message):
        self.messages.append((status, message.decode()))

    def vr(self, names):
        return [self.vars[n].valueReference for n in names]

    def set(self, values: dict) -> None:
        f = self.fmu
        for name, value in values.items():
            typ = self.vars[name].type
            if typ in ("Real", "Float64"):
                (f.setReal if self.fmi == 2 else f.setFloat64)(self.vr([name]), [value])
            elif typ in ("Integer", "Int32"):
                set_int = f.setInteger if self.fmi == 2 else f.setInt32
                set_int(self.vr([name]), [value])
            else:
                f.setBoolean(self.vr([name]), [bool(value)])

    def get(self, names) -> list:
        f = self.fmu
        typ = self.vars[names[0]].type
        if typ in ("Real", "Float64"):
            return list((f.getReal if self.fmi == 2 else f.getFloat64)(self.vr(names)))
        return list(f.getBoolean(self.vr(names)))

    def init(self, start: float = 0.0) -> None:
        if self.fmi == 2:
            self.fmu.setupExperiment(startTime=start)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=start)
        self.fmu.exitInitializationMode()

    def step(self, t: float, h: float = H) -> None:
        self.fmu.doStep(t, h)

    def last(self) -> str:
        """The last message (FMI 3.0's logger has no instance argument: the FMU
        prefixes the instance name, removed here)."""
        text = self.messages[-1][1] if self.messages else ""
        return text.removeprefix(self.name + ": ") if self.fmi == 3 else text

    def close(self) -> None:
        import shutil

        self.fmu.freeInstance()
        shutil.rmtree(self.unzip, ignore_errors=True)


def _status(excinfo) -> int:
    return excinfo.value.status


def _drive_fmpy(path, fmi, axes, traj) -> Outputs:
    d = Driver(path, fmi)
    try:
        d.set(parameter_values(axes))
        d.init()
        ins = [f"{q}_{a}" for a in AXES for q in ("u", "v", "n")]
        reals = [f"{q}_{a}" for q in ("F", "Ffr", "kt", "E_fr") for a in AXES]
        reals.append("E_fr")
        slips = [f"slip_{a}" for a in AXES]
        f = d.fmu
        set_real = f.setReal if fmi == 2 else f.setFloat64
        get_real = f.getReal if fmi == 2 else f.getFloat64
        vin, vout, vslip = d.vr(ins), d.vr(reals), d.vr(slips)
        vw = d.vr([f"w_{a}" for a in AXES])
        steps = traj.u.shape[0]
        rows = np.zeros((steps, 13))
        slip, w = np.zeros((steps, 3)), np.zeros((steps, 3))
        x = np.stack([traj.u, traj.v, traj.n], axis=2).reshape(steps, 9)
        for k in range(steps):
            set_real(vin, x[k].tolist())
            rows[k] = get_real(vout)
            slip[k] = f.getBoolean(vslip)
            f.doStep(k * H, H)
            w[k] = get_real(vw)
    finally:
        d.close()
    return Outputs(F=rows[:, 0:3], Ffr=rows[:, 3:6], kt=rows[:, 6:9], slip=slip,
                   E_fr=rows[:, 9:12], E_total=rows[:, 12], w=w)


@pytest.mark.parametrize("layout", [0, 1])
def test_fmpy_equals_python_law(native, layout):
    fmi, path = native
    rng = np.random.default_rng(100 + layout)
    axes = random_instance(rng, LAW_LAYOUT[layout])
    traj = random_trajectory(rng, FMPY_STEPS)
    ref = reference_run(axes, traj)
    got = _drive_fmpy(path, fmi, axes, traj)
    errors = worst_relative(ref, got)
    assert max(errors.values()) <= TOL_REL, errors
    assert 0 < ref.slip.mean() < 1 and (traj.n < 0).any()  # both regimes visited
    assert np.abs(got.w - ref.w).max() <= TOL_REL * np.abs(ref.w).max()


@pytest.mark.parametrize("layout", [0, 1])
def test_fmpy_micro_slip_and_fs_ratio_equal_python_law(native, layout):
    """Micro-slip (3 to 64 sliders, with spread and fs_ratio) and non-symmetric
    macro-slip axes, 4000 steps with reversals inside steps and contact loss: every
    output and the mean slider position w_<axis> equal the Python law (measured 0)."""
    fmi, path = native
    rng = np.random.default_rng(300 + layout)
    axes = random_general_instance(rng, GENERAL_LAYOUT[layout])
    traj = random_trajectory(rng, FMPY_STEPS)
    ref = reference_run(axes, traj)
    got = _drive_fmpy(path, fmi, axes, traj)
    errors = worst_relative(ref, got)
    assert max(errors.values()) <= TOL_REL, errors
    assert np.abs(got.w - ref.w).max() <= TOL_REL * np.abs(ref.w).max()
    assert 0 < ref.slip.mean() < 1 and (traj.n < 0).any()
    assert ref.E_total[-1] > 0


# ---------------------------------------------------------------------- C host


@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    exe = tmp_path_factory.mktemp("host") / "native_host"
    proc = run(["gcc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-Wall", "-Wextra",
                "-Werror", "-O2", "-o", exe,
                ROOT / "tests" / "c_host" / "native_host.c", "-ldl"])
    assert proc.returncode == 0, proc.stderr
    return exe


@pytest.mark.parametrize("pair", [(0, 1), (2, 3)], ids=["layouts01", "layouts23"])
def test_c_host_empty_environment_two_instances(native2, c_host, tmp_path, pair):
    """1e5 steps per instance and law (every law with and without friction over the
    two pairs), two instances of one binary stepped side by side, host run with
    ``env -i``: outputs equal the Python law to TOL_REL."""
    rng = np.random.default_rng(200 + pair[0])
    instances = [(random_instance(rng, LAW_LAYOUT[i]),
                  random_trajectory(rng, HOST_STEPS)) for i in pair]
    _run_host(native2, c_host, tmp_path, instances)


#: Steps per instance of the C host with micro-slip axes (the Python reference of
#: 64 sliders costs about 50 us a step).
HOST_GENERAL_STEPS = 20_000


def test_c_host_micro_slip_and_fs_ratio(native2, c_host, tmp_path):
    """The two micro-slip / non-symmetric layouts side by side in the plain C host
    under ``env -i``, 2e4 steps each: outputs equal the Python law to TOL_REL."""
    rng = np.random.default_rng(250)
    instances = [(random_general_instance(rng, layout),
                  random_trajectory(rng, HOST_GENERAL_STEPS))
                 for layout in GENERAL_LAYOUT]
    _run_host(native2, c_host, tmp_path, instances)


def _run_host(native2, c_host, tmp_path, instances) -> None:
    """Run ``instances`` ((axes, trajectory) pairs) in the C host; compare."""
    from fmpy import extract, read_model_description

    md = read_model_description(str(native2))
    unzip = extract(str(native2), str(tmp_path / "fmu"))
    steps = instances[0][1].u.shape[0]
    cfg = tmp_path / "host.cfg"
    cfg.write_text(host_config(tmp_path, md, instances, H))
    lib = f"{unzip}/binaries/linux64/{md.coSimulation.modelIdentifier}.so"
    proc = run(["env", "-i", c_host, lib, md.guid, cfg])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert f"DONE {steps} steps, {len(instances)} instances" in proc.stdout
    for i, (axes, traj) in enumerate(instances):
        rows = np.fromfile(tmp_path / f"out{i}.bin", "<f8").reshape(steps, 16)
        got = Outputs(F=rows[:, 0:3], Ffr=rows[:, 3:6], kt=rows[:, 6:9],
                      E_fr=rows[:, 9:12], E_total=rows[:, 12], slip=rows[:, 13:16])
        ref = reference_run(axes, traj)
        errors = worst_relative(ref, got)
        assert max(errors.values()) <= TOL_REL, (i, errors)
        assert ref.E_total[-1] > 0  # friction dissipated energy


# ---------------------------------------------------------------------- validity


def test_fmpy_validate_clean(native):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(native[1])) == []


def test_fmpy_simulate_default_experiment(native):
    fmi, path = native
    result = fmpy.simulate_fmu(str(path))
    exp = interface.DEFAULT_EXPERIMENT
    assert result["time"][0] == exp["startTime"]
    assert math.isclose(result["time"][-1], exp["stopTime"])
    assert np.all(result["F_axial"] == 0.0)  # at rest, no input: no force
    assert np.all(result["kt_axial"] == interface.variable("axial_k1").start)


def test_model_description_is_the_interface_table(native):
    from fmpy import read_model_description

    fmi, path = native
    md = read_model_description(str(path))
    fmi3_type = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}
    by_name = {v.name: v for v in md.modelVariables}
    for vr, var in enumerate(interface.VARIABLES):
        got = by_name[var.name]
        assert got.valueReference == vr
        assert got.type == (var.type if fmi == 2 else fmi3_type[var.type])
        assert (got.causality, got.variability) == (var.causality, var.variability)
        assert got.description == var.description
        assert (got.unit or None) == (var.unit if var.type == "Real" else None)
        if var.start is not None:
            assert got.start == (str(var.start).lower() if var.type == "Boolean"
                                 else repr(float(var.start)) if var.type == "Real"
                                 else str(var.start))
    extra = set(by_name) - {v.name for v in interface.VARIABLES}
    # beyond the table: FMI 3.0's time, the Model Exchange states, derivatives and
    # event indicators (fmu_build/native_me.py; tests/test_native_me.py)
    from drymount.fmu_build.native_me import me_variables
    assert extra == ({v.name for v in me_variables()} | ({"time"} if fmi == 3
                                                          else set()))
    exp = md.defaultExperiment
    assert float(exp.stopTime) == interface.DEFAULT_EXPERIMENT["stopTime"]
    assert float(exp.stepSize) == interface.DEFAULT_EXPERIMENT["stepSize"]
    assert md.coSimulation.modelIdentifier == (
        "FrictionMountNative" if fmi == 2 else "FrictionMountNative3")
    assert md.coSimulation.canGetAndSetFMUstate
    assert md.coSimulation.canSerializeFMUstate


def test_archive_layout_sources_and_binaries(native):
    fmi, path = native
    names = set(zipfile.ZipFile(path).namelist())
    ident = "FrictionMountNative" if fmi == 2 else "FrictionMountNative3"
    linux, win = (("linux64", "win64") if fmi == 2
                  else ("x86_64-linux", "x86_64-windows"))
    assert f"binaries/{linux}/{ident}.so" in names
    glue = f"fmi{fmi}_glue.c"
    for src in ("mount_law.c", "mount_law.h", "model.c", "model.h",
                "model_variables.h", glue):
        assert f"sources/{src}" in names
    assert ("sources/buildDescription.xml" in names) == (fmi == 3)
    assert "documentation/index.html" in names
    import shutil
    if shutil.which("x86_64-w64-mingw32-gcc"):
        dll = zipfile.ZipFile(path).read(f"binaries/{win}/{ident}.dll")
        assert dll[:2] == b"MZ"


def test_build_is_reproducible_and_tokens_distinct(tmp_path):
    from drymount.fmu_build.native import build_native_fmu

    a = build_native_fmu(tmp_path / "a.fmu", fmi=2)
    b = build_native_fmu(tmp_path / "b.fmu", fmi=2)
    c = build_native_fmu(tmp_path / "c.fmu", fmi=3)
    n = build_native_fmu(tmp_path / "n.fmu", fmi=2, null=True)
    assert a.path.read_bytes() == b.path.read_bytes()
    assert len({a.token, c.token, n.token}) == 3
    assert n.target.model_identifier == "NullMountNative"


def test_documented_compile_command_builds_the_sources(native, tmp_path):
    """The one-line linux command of documentation/index.html compiles sources/."""
    from drymount.fmu_build.native import COMPILE

    fmi, path = native
    zipfile.ZipFile(path).extractall(tmp_path)
    ident = "FrictionMountNative" if fmi == 2 else "FrictionMountNative3"
    cmd = COMPILE["linux"].format(id=ident)
    assert cmd in (tmp_path / "documentation" / "index.html").read_text()
    proc = run(["sh", "-c", cmd], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    nm = run(["nm", "-D", "--defined-only", tmp_path / f"{ident}.so"]).stdout
    assert f" T fmi{fmi}DoStep" in nm


def test_binary_needs_no_python(native):
    """Only libc and libm in the dynamic section, no undefined Py* symbol, every
    exported symbol an FMI function."""
    fmi, path = native
    linux = "linux64" if fmi == 2 else "x86_64-linux"
    ident = "FrictionMountNative" if fmi == 2 else "FrictionMountNative3"
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        lib = zipfile.ZipFile(path).extract(f"binaries/{linux}/{ident}.so", tmp)
        dynamic = run(["readelf", "-d", lib]).stdout
        undefined = run(["nm", "-D", "--undefined-only", lib]).stdout.split()
        defined = run(["nm", "-D", "--defined-only", lib]).stdout.splitlines()
    needed = {line.split("[")[1].rstrip("]") for line in dynamic.splitlines()
              if "(NEEDED)" in line}
    assert needed <= {"libc.so.6", "libm.so.6"}, needed
    assert "python" not in dynamic.lower()
    names = [w.split("@")[0] for w in undefined if w not in ("U", "w")]
    assert names and not [n for n in names if n.lstrip("_").startswith("Py")]
    exported = [line.split()[-1] for line in defined if " T " in line]
    assert exported and all(n.startswith(f"fmi{fmi}") for n in exported), exported


# ---------------------------------------------------------------------- state machine


@pytest.fixture
def driver(native):
    fmi, path = native
    d = Driver(path, fmi)
    yield d
    d.close()


def _call(d, fn, *args):
    with pytest.raises(fmpy.fmi1.FMICallException) as exc:
        fn(*args)
    return _status(exc), d.last()


def test_calls_out_of_order_are_refused_with_a_message(driver):
    d, p = driver, f"fmi{driver.fmi}"
    status, msg = _call(d, d.step, 0.0)
    assert status == 3 and f"{p}DoStep is not allowed in state Instantiated" in msg
    assert d.get(["F_axial"]) == [0.0]  # getters: every state (docs/fmu.md 4a)
    status, msg = _call(d, d.fmu.exitInitializationMode)
    assert status == 3 and "not allowed in state Instantiated" in msg
    d.init()
    set_name = "SetReal" if d.fmi == 2 else "SetFloat64"
    status, msg = _call(d, d.set, {"axial_k1": 1.0})
    assert status == 3
    assert f"{p}{set_name} of axial_k1 is not allowed in state StepMode" in msg
    status, msg = _call(d, d.set, {"F_axial": 1.0})
    assert status == 3 and "F_axial is an output and cannot be set" in msg
    status, msg = _call(d, d.fmu.enterInitializationMode)
    assert status == 3 and "not allowed in state StepMode" in msg
    # refused calls change nothing: the instance steps on
    d.set({"u_axial": 0.001})
    d.step(0.0)
    assert d.get(["F_axial"])[0] == pytest.approx(91.87)
    d.fmu.terminate()
    status, msg = _call(d, d.step, H)
    assert status == 3 and "not allowed in state Terminated" in msg


@pytest.mark.parametrize("t, h, needle", [
    (0.0, 0.0, "communicationStepSize must be finite and > 0, got 0.0"),
    (0.0, -1e-4, "communicationStepSize must be finite and > 0, got -0.0001"),
    (0.0, math.nan, "communicationStepSize must be finite and > 0, got nan"),
    (0.0, math.inf, "communicationStepSize must be finite and > 0, got inf"),
    (0.0, 1.5e6, "communicationStepSize must be <= 1e+06 s, got 1500000.0"),
    (math.nan, 1e-4, "currentCommunicationPoint must be finite, got nan"),
    (1e300, 1e-4, "communicationStepSize = 0.0001 does not advance "
                  "currentCommunicationPoint = 1e+300"),
])
def test_bad_step_is_refused_and_the_next_good_one_works(driver, t, h, needle):
    """docs/fmu.md 4a: 0 < h <= 1e6 s, t finite, t + h > t."""
    d = driver
    d.init()
    status, msg = _call(d, d.step, t, h)
    assert status == 3 and needle in msg, msg
    d.step(0.0, 1e6)  # still usable; 1e6 s is allowed


def test_without_setup_experiment_the_first_step_starts_anywhere(native2):
    """FMI 2.0 without fmi2SetupExperiment (docs/fmu.md 4a): no start time, the first
    step may start at any t; then time continues from it."""
    d = Driver(native2, 2)
    try:
        d.fmu.enterInitializationMode()
        d.fmu.exitInitializationMode()
        d.step(-7.25)
        d.step(-7.25 + H)
        status, msg = _call(d, d.step, 0.0)
        assert status == 3 and f"the last step, {(-7.25 + H) + H!r}, got 0.0" in msg
    finally:
        d.close()


def test_step_size_limit_is_fmi_state_s():
    """The native limits are the PythonFMU's (fmu_src/fmi_state.py)."""
    from drymount.fmu_src import fmi_state

    source = (ROOT / "fmu_src" / "native" / "model.c").read_text()
    defines = dict(re.findall(r"^#define (MD_\w+) (\S+)$", source, re.M))
    assert float(defines["MD_MAX_STEP_SIZE"]) == fmi_state.MAX_STEP_SIZE
    assert float(defines["MD_TIME_RTOL"]) == fmi_state.TIME_RTOL


def test_time_continues_from_the_last_step(driver):
    driver.init(start=0.5)
    status, msg = _call(driver, driver.step, 0.0)
    assert status == 3 and "must continue from the end of the last step, 0.5" in msg
    driver.step(0.5)
    status, msg = _call(driver, driver.step, 0.5)  # the same step again
    assert status == 3 and "the last step, 0.5001, got 0.5" in msg
    driver.step(0.5 + H)
    status, msg = _call(driver, driver.step, 0.5 + 3 * H)  # a step skipped
    assert status == 3
    # tolerance 1e-9 max(1, |t_end|, h) (docs/fmu.md 4a): at t_end = 0.5002 it is
    # 1e-9, not 1e-9 (|t| + h) = 5e-13
    t_end = 0.5 + 2 * H
    driver.step(t_end + 0.9e-9)
    status, msg = _call(driver, driver.step, t_end + H + 0.9e-9 + 1.1e-9)
    assert status == 3 and "must continue from the end of the last step" in msg


def test_unknown_value_reference_and_wrong_type(driver):
    driver.init()
    f = driver.fmu
    get = f.getReal if driver.fmi == 2 else f.getFloat64
    n = len(driver.vars)
    status, msg = _call(driver, get, [n + 5])
    assert status == 3 and f"unknown value reference {n + 5}" in msg
    status, msg = _call(driver, get, driver.vr(["axial_law"]))
    assert status == 3 and "(axial_law) is a Integer variable, not Real" in msg


def test_non_finite_value_is_refused_at_the_set_and_changes_nothing(driver):
    """docs/fmu.md 4a: a Real value must be finite; every value of a set call is
    checked before any is set."""
    d = driver
    d.set({"axial_friction": True, "axial_n0": 100.0})
    status, msg = _call(d, d.set, {"axial_k1": math.inf})  # a parameter, too
    assert status == 3 and "`axial_k1` must be finite, got inf" in msg
    d.init()
    d.set({"u_axial": 0.01})
    d.step(0.0)
    w, f = d.get(["w_axial"])[0], d.get(["F_axial"])[0]
    set_real = d.fmu.setReal if d.fmi == 2 else d.fmu.setFloat64
    status, msg = _call(d, set_real, d.vr(["u_axial", "v_axial"]), [0.02, math.nan])
    assert status == 3 and "`v_axial` must be finite, got nan" in msg
    assert d.get(["u_axial", "F_axial"]) == [0.01, f]  # u_axial was not set either
    d.step(H)
    assert d.get(["w_axial"]) == [w]  # u unchanged: the slider stays


def test_outputs_read_zero_with_a_warning_until_parameters_are_valid(driver):
    """docs/fmu.md 4a: before the end of initialization an output read with an invalid
    parameter is 0 and logs a warning once; fmi2ExitInitializationMode refuses."""
    d = driver
    d.set({"axial_friction": True, "axial_kf": -5.0})
    assert d.get(["F_axial", "E_fr"]) == [0.0, 0.0]
    warnings = [m for s, m in d.messages if s == 1]
    assert len(warnings) == 1 and "outputs are 0 until the parameters are valid " \
        "(invalid parameters: `axial_kf` must be finite and > 0 when friction is on, " \
        "got -5.0)" in warnings[0]
    if d.fmi == 2:
        d.fmu.setupExperiment(startTime=0.0)
        d.fmu.enterInitializationMode()
    else:
        d.fmu.enterInitializationMode(startTime=0.0)
    assert d.get(["F_axial"]) == [0.0]
    status, msg = _call(d, d.fmu.exitInitializationMode)
    assert status == 3 and "`axial_kf` must be finite and > 0" in msg
    d.set({"axial_kf": 60000.0, "u_axial": 0.001})
    assert d.get(["F_axial"])[0] > 0.0
    d.fmu.exitInitializationMode()


def test_invalid_parameters_give_the_pythonfmu_message(driver):
    from drymount.fmu_src.friction_mount import FrictionMount

    bad = {"axial_k1": -1.0, "radial2_delta": 0.0, "radial1_friction": True,
           "radial1_kf": 0.0, "axial_law": 9}
    slave = FrictionMount(instance_name="reference")
    for name, value in bad.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0)  # the call-order rules (docs/fmu.md, 4a)
    slave.enter_initialization_mode()
    with pytest.raises(ValueError) as ref:
        slave.exit_initialization_mode()
    d = driver
    d.set(bad)
    if d.fmi == 2:
        d.fmu.setupExperiment(startTime=0.0)
        d.fmu.enterInitializationMode()
    else:
        d.fmu.enterInitializationMode(startTime=0.0)
    status, msg = _call(d, d.fmu.exitInitializationMode)
    assert status == 3
    assert msg == f"{ref.value} (in fmi{d.fmi}ExitInitializationMode)"
    d.set({"axial_k1": 1.0, "radial2_delta": 0.01, "radial1_kf": 1.0, "axial_law": 0})
    d.fmu.exitInitializationMode()  # fixed in initialization mode: accepted


def test_invalid_micro_slip_parameters_give_the_pythonfmu_message(driver):
    """Bad sliders / spread / fs_ratio: the PythonFMU build's message; once fixed,
    micro-slip and non-symmetric axes initialize."""
    from drymount.fmu_src.friction_mount import FrictionMount

    bad = {"radial1_friction": True, "radial1_sliders": 65, "axial_friction": True,
           "axial_fs_ratio": -0.5, "radial2_sliders": 0, "radial2_spread": 1.0}
    slave = FrictionMount(instance_name="reference")
    for name, value in bad.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    with pytest.raises(ValueError) as ref:
        slave.exit_initialization_mode()
    d = driver
    d.set(bad)
    if d.fmi == 2:
        d.fmu.setupExperiment(startTime=0.0)
        d.fmu.enterInitializationMode()
    else:
        d.fmu.enterInitializationMode(startTime=0.0)
    status, msg = _call(d, d.fmu.exitInitializationMode)
    assert status == 3
    assert msg == f"{ref.value} (in fmi{d.fmi}ExitInitializationMode)"
    assert "`radial1_sliders` must be an integer from 1 to 64" in msg
    d.set({"radial1_sliders": 64, "axial_fs_ratio": 0.5, "radial2_sliders": 2,
           "radial2_spread": 0.5})
    d.fmu.exitInitializationMode()


def test_normal_force_follows_n0_until_set(driver):
    d = driver
    d.set({"axial_friction": True, "axial_n0": 150.0, "axial_mu": 0.5})
    d.init()
    d.set({"u_axial": 1.0})  # far beyond slip: |Ffr| = mu n0
    assert d.get(["Ffr_axial", "n_axial"]) == [75.0, 150.0]
    d.set({"n_axial": -10.0})  # contact lost
    assert d.get(["Ffr_axial"]) == [0.0]
    d.set({"n_axial": 300.0})
    assert d.get(["Ffr_axial"]) == [150.0]


def _run_steps(d, k0, k1, traj):
    out = []
    for k in range(k0, k1):
        d.set({"u_axial": float(traj.u[k, 0]), "v_axial": float(traj.v[k, 0]),
               "n_axial": float(traj.n[k, 0])})
        out.append(d.get(["F_axial", "Ffr_axial", "E_fr", "w_axial"]))
        d.step(k * H)
    return out


def test_state_get_set_serialize_replays_identically(driver):
    d = driver
    d.set({"axial_friction": True, "axial_n0": 300.0})
    d.init()
    traj = random_trajectory(np.random.default_rng(7), 200)
    _run_steps(d, 0, 100, traj)
    f = d.fmu
    state = f.getFMUstate() if d.fmi == 2 else f.getFMUState()
    blob = (f.serializeFMUstate(state) if d.fmi == 2 else f.serializeFMUState(state))
    first = _run_steps(d, 100, 200, traj)
    f.setFMUstate(state) if d.fmi == 2 else f.setFMUState(state)
    assert _run_steps(d, 100, 200, traj) == first
    restored = (f.deSerializeFMUstate(blob) if d.fmi == 2
                else f.deserializeFMUState(blob))
    f.setFMUstate(restored) if d.fmi == 2 else f.setFMUState(restored)
    assert _run_steps(d, 100, 200, traj) == first
    assert first[-1][2] > 0
    for s in (state, restored):
        f.freeFMUstate(s) if d.fmi == 2 else f.freeFMUState(s)


@dataclass
class _MidRun:
    """An instance's FMU state at step 200 of 400, serialized, and the rows of
    the second half run from it."""

    state: object
    blob: bytes
    second: np.ndarray


def _save_mid_run(d, fmi: int, traj, expect: np.ndarray) -> _MidRun:
    """Steps 0..399 of ``d`` with the state saved at 200; the rows equal ``expect``."""
    f = d.fmu
    first = _run_all_axes(d, 0, 200, traj)
    state = f.getFMUstate() if fmi == 2 else f.getFMUState()
    blob = f.serializeFMUstate(state) if fmi == 2 else f.serializeFMUState(state)
    second = _run_all_axes(d, 200, 400, traj)
    got = np.vstack([first, second])
    assert np.abs(got - expect).max() <= TOL_REL * np.abs(expect).max()
    return _MidRun(state, blob, second)


def _replay_serialized(other, fmi: int, run: _MidRun, traj):
    """``run``'s serialized state set into ``other``: the second half replays
    identically. Returns the deserialized state (to free)."""
    g = other.fmu
    restored = (g.deSerializeFMUstate(run.blob) if fmi == 2
                else g.deserializeFMUState(run.blob))
    g.setFMUstate(restored) if fmi == 2 else g.setFMUState(restored)
    assert np.array_equal(_run_all_axes(other, 200, 400, traj), run.second)
    return restored


def _free_states(d, other, fmi: int, state, restored) -> None:
    for inst, st in ((d.fmu, state), (other.fmu, restored)):
        inst.freeFMUstate(st) if fmi == 2 else inst.freeFMUState(st)


def _run_all_axes(d, k0, k1, traj) -> np.ndarray:
    """Steps k0..k1-1 on every axis: rows of F, Ffr, kt, E_fr per axis, E_fr and the
    committed w per axis after the step."""
    outs = [f"{q}_{a}" for q in ("F", "Ffr", "kt", "E_fr") for a in AXES] + ["E_fr"]
    rows = []
    for k in range(k0, k1):
        d.set({f"{q}_{a}": float(x[k, j]) for j, a in enumerate(AXES)
               for q, x in (("u", traj.u), ("v", traj.v), ("n", traj.n))})
        row = d.get(outs)
        d.step(k * H)
        rows.append(row + d.get([f"w_{a}" for a in AXES]))
    return np.array(rows)


def _sliders_at(p, traj, steps, j) -> tuple:
    """Slider positions of axis ``j`` (parameters ``p``) after ``steps`` steps."""
    w = initial_sliders(p)
    for k in range(steps):
        n = float(traj.n[k, j])
        w = axis_force(float(traj.u[k, j]), 0.0, w, p, n)[2]
    return w


def test_state_with_sliders_restores_mid_trajectory(native):
    """Micro-slip (8 and 64 sliders) and non-symmetric axes: the FMU state taken at
    step 200 of 400 holds every slider. Restored in the same instance, and
    serialized into a fresh instance that never saw the parameters, the second half
    replays identically and equals the Python law."""
    fmi, path = native
    rng = np.random.default_rng(400)
    axes = random_general_instance(rng, GENERAL_LAYOUT[0])
    traj = random_trajectory(rng, 400)
    ref = reference_run(axes, traj)
    expect = np.column_stack([ref.F, ref.Ffr, ref.kt, ref.E_fr, ref.E_total, ref.w])
    d = Driver(path, fmi)
    other = Driver(path, fmi, name="other")
    try:
        d.set(parameter_values(axes))
        d.init()
        f = d.fmu
        run = _save_mid_run(d, fmi, traj, expect)
        assert len(set(_sliders_at(axes[2], traj, 200, 2))) > 10  # apart at 200
        f.setFMUstate(run.state) if fmi == 2 else f.setFMUState(run.state)
        assert np.array_equal(_run_all_axes(d, 200, 400, traj), run.second)
        restored = _replay_serialized(other, fmi, run, traj)
        _free_states(d, other, fmi, run.state, restored)
    finally:
        d.close()
        other.close()


# ---------------------------------------------------------------------- inclined


_KINDS = getattr(mount_law, "FRICTION_KINDS", ())
needs_inclined = pytest.mark.skipif(
    "inclined" not in _KINDS, reason="fmu_src/mount_law.py has no inclined friction "
    "kind yet (issue 14): nothing to wire")


def _inclined_instance(rng):
    """Axial: the inclined element at 60 degrees; radial1: micro-slip with fs_ratio;
    radial2: the inclined element at 45 degrees. (Steep angles lift the flat surface
    off on this motion, and a bonded surface, mu = inf, cannot be set through FMI,
    whose setters refuse non-finite values: the ctypes test of inclined.c covers both.)
    """
    from dataclasses import replace

    from native_helpers import random_axis

    return (replace(random_axis(rng, "piecewise", True), friction_kind="inclined",
                    theta_deg=60.0, k=2e4, kf2=5e4, mu1=0.3, mu2=0.25, preload=300.0),
            replace(random_axis(rng, "cubic", True), sliders=8, spread=0.5,
                    fs_ratio=0.7),
            replace(random_axis(rng, "linear", True), friction_kind="inclined",
                    theta_deg=45.0, mu1=0.2, mu2=0.3, preload=400.0, k=3e4))


def _compressed_trajectory(rng, steps):
    """random_trajectory with 1 cm amplitude around 4 mm of compression (the wedge
    stays in contact)."""
    from native_helpers import Trajectory

    t = random_trajectory(rng, steps, amplitude=0.01)
    return Trajectory(t.u - 0.004, t.v, t.n)


def _reference_normal_forces(axes, traj) -> np.ndarray:
    """(N, N2) per step and axis of the trial state (mount_law.normal_forces), as
    the PythonFMU build's N_/N2_<axis>: shape (steps, 6)."""
    out = np.zeros((traj.u.shape[0], 6))
    for j, p in enumerate(axes):
        w = initial_sliders(p)
        for k in range(traj.u.shape[0]):
            u, v, n = (float(x[k, j]) for x in (traj.u, traj.v, traj.n))
            r = axis_force(u, v, w, p, n)
            out[k, 2 * j:2 * j + 2] = mount_law.normal_forces(p, r.w_new, n)
            w = r.w_new
    return out


@needs_inclined
def test_fmpy_inclined_axes_equal_python_law(native):
    """Two inclined axes (60 and 45 degrees) and a micro-slip one, 4000 steps with
    reversals inside steps: every output, w_<axis> (uc of the inclined element) and
    the normal forces N_/N2_<axis> equal the Python law (measured 0)."""
    fmi, path = native
    rng = np.random.default_rng(500)
    axes = _inclined_instance(rng)
    traj = _compressed_trajectory(rng, FMPY_STEPS)
    ref = reference_run(axes, traj)
    got = _drive_fmpy(path, fmi, axes, traj)
    errors = worst_relative(ref, got)
    assert max(errors.values()) <= TOL_REL, errors
    assert np.abs(got.w - ref.w).max() <= TOL_REL * np.abs(ref.w).max()
    assert (ref.slip.mean(axis=0) > 0.1).all() and ref.E_total[-1] > 0
    normal = _reference_normal_forces(axes, traj)
    d = Driver(path, fmi)
    try:
        d.set(parameter_values(axes))
        d.init()
        names = [f"{q}_{a}" for a in AXES for q in ("N", "N2")]
        rows = []
        for k in range(FMPY_STEPS):
            d.set({f"{q}_{a}": float(x[k, j]) for j, a in enumerate(AXES)
                   for q, x in (("u", traj.u), ("v", traj.v), ("n", traj.n))})
            rows.append(d.get(names))
            d.step(k * H)
    finally:
        d.close()
    scale = np.abs(normal).max()
    assert np.abs(np.array(rows) - normal).max() <= TOL_REL * scale
    assert normal[:, 0].min() > 0 and np.ptp(normal[:, 0]) > 0.1 * scale  # N varies


def _contact_lost_message(axes, u_out: float) -> str:
    """The PythonFMU build's message for the axial wedge pulled out to ``u_out``
    (the law's ContactLost, which it must raise there)."""
    from drymount.fmu_src.inclined import ContactLost

    try:
        axis_force(u_out, 0.0, initial_sliders(axes[0]), axes[0])
    except ContactLost as exc:
        return f"FrictionMount: axis axial at u_axial={u_out!r}: {exc}"
    raise AssertionError("the wedge should lose contact")


@needs_inclined
def test_inclined_contact_lost_is_an_error_with_the_python_message(native):
    """Pulling the wedge out, with the PythonFMU build's message each time (fmi2Error
    / fmi3Error): a start input out of contact is refused by ExitInitializationMode,
    which leaves the instance in initialization mode (as a bad parameter does); in
    step mode reading an output and the step are refused and nothing is committed;
    each time the instance goes on once the motion is corrected."""
    fmi, path = native
    axes = _inclined_instance(np.random.default_rng(501))
    u_out = 0.05
    why = _contact_lost_message(axes, u_out)
    d = Driver(path, fmi)
    try:
        d.set(parameter_values(axes))
        d.set({"u_axial": u_out})
        if fmi == 2:
            d.fmu.setupExperiment(startTime=0.0)
            d.fmu.enterInitializationMode()
        else:
            d.fmu.enterInitializationMode(startTime=0.0)
        status, msg = _call(d, d.fmu.exitInitializationMode)
        assert (status, msg) == (3, f"{why} (in fmi{fmi}ExitInitializationMode)")
        status, msg = _call(d, d.step, 0.0)
        assert status == 3 and "not allowed in state InitializationMode" in msg
        d.set({"u_axial": 0.0})
        d.fmu.exitInitializationMode()
        d.set({"u_axial": u_out})
        get = "GetReal" if fmi == 2 else "GetFloat64"
        status, msg = _call(d, d.get, ["F_axial"])
        assert (status, msg) == (3, f"{why} (in fmi{fmi}{get})")
        status, msg = _call(d, d.step, 0.0)
        assert (status, msg) == (3, f"{why} (in fmi{fmi}DoStep)")
        d.set({"u_axial": -0.001})
        d.step(0.0)
        assert d.get(["w_axial"]) == [-0.001]
    finally:
        d.close()


@needs_inclined
def test_state_with_inclined_axes_restores_mid_trajectory(native):
    """The FMU state at step 200 of 400 holds the inclined elements' (w1, w2, uc):
    restored in a fresh instance, the second half equals the first run's."""
    fmi, path = native
    rng = np.random.default_rng(502)
    axes = _inclined_instance(rng)
    traj = _compressed_trajectory(rng, 400)
    ref = reference_run(axes, traj)
    expect = np.column_stack([ref.F, ref.Ffr, ref.kt, ref.E_fr, ref.E_total, ref.w])
    d, other = Driver(path, fmi), Driver(path, fmi, name="other")
    try:
        d.set(parameter_values(axes))
        d.init()
        run = _save_mid_run(d, fmi, traj, expect)
        restored = _replay_serialized(other, fmi, run, traj)
        _free_states(d, other, fmi, run.state, restored)
    finally:
        d.close()
        other.close()


def test_reset_starts_over(driver):
    d = driver
    d.set({"axial_friction": True, "axial_n0": 300.0, "axial_k1": 5e4})
    d.init()
    traj = random_trajectory(np.random.default_rng(8), 50)
    first = _run_steps(d, 0, 50, traj)
    d.fmu.reset()
    assert d.fmu is not None
    d.set({"axial_friction": True, "axial_n0": 300.0, "axial_k1": 5e4})
    d.init()
    assert _run_steps(d, 0, 50, traj) == first


def test_wrong_guid_is_refused(native, tmp_path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    fmi, path = native
    md = read_model_description(str(path))
    kw = dict(unzipDirectory=extract(str(path), str(tmp_path / "x")),
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
    fmu = (FMU2Slave(guid="{00000000-0000-0000-0000-000000000000}", **kw) if fmi == 2
           else FMU3Slave(guid="{wrong}", **kw))
    with pytest.raises(Exception, match="instantiat|Failed"):
        fmu.instantiate()
    fmu.freeLibrary()


# ---------------------------------------------------------------------- PythonFMU


@pytest.fixture(scope="module")
def python_fmu(tmp_path_factory):
    from drymount.fmu_build import build_fmu

    return build_fmu(tmp_path_factory.mktemp("pythonfmu") / "FrictionMount.fmu")


def _start(var):
    if var.start is None:
        return None
    if var.type in ("Real", "Float64"):
        return float(var.start)
    if var.type in ("Integer", "Int32"):
        return int(var.start)
    return str(var.start).lower() in ("true", "1")


def test_same_interface_as_the_pythonfmu_build(native, python_fmu):
    """Names, value references, causality, variability, initial, units, descriptions,
    start values, ranges, unit definitions and default experiment equal the PythonFMU
    build's (both are generated from fmu_src/interface.py)."""
    from fmpy import read_model_description

    fmi, path = native
    ours, theirs = (read_model_description(str(p)) for p in (path, python_fmu))
    mine = {v.name: v for v in ours.modelVariables}
    assert len(theirs.modelVariables) == len(interface.VARIABLES)
    for var in theirs.modelVariables:
        got = mine[var.name]
        for attr in ("valueReference", "causality", "variability", "initial",
                     "description", "unit", "min", "max"):
            assert getattr(got, attr) == getattr(var, attr), (var.name, attr)
        assert _start(got) == _start(var), var.name
    def exps(unit):
        return tuple(getattr(unit.baseUnit, k, None)
                     for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"))

    units = {u.name: exps(u) for u in theirs.unitDefinitions}
    assert units == {u.name: exps(u) for u in ours.unitDefinitions
                     if u.name in units}
    assert len(units) == len(interface.BASE_UNITS)
    for attr in ("startTime", "stopTime", "stepSize"):
        a, b = (getattr(md.defaultExperiment, attr) for md in (ours, theirs))
        assert float(a) == float(b)
    # the PythonFMU build writes no tolerance (pythonfmu's DefaultExperiment); the
    # native builds write the table's
    tol = ours.defaultExperiment.tolerance
    assert float(tol) == interface.DEFAULT_EXPERIMENT["tolerance"]


def test_fmi3_build_description_is_schema_valid(tmp_path):
    """sources/buildDescription.xml against the FMI 3.0 schema fmpy ships; it lists
    the one translation unit, which #includes every other C file of sources/."""
    import os

    from lxml import etree

    path = build(tmp_path, 3)
    schema_dir = os.path.join(os.path.dirname(fmpy.__file__), "schema", "fmi3")
    schema = etree.XMLSchema(etree.parse(os.path.join(schema_dir,
                                                      "fmi3BuildDescription.xsd")))
    zf = zipfile.ZipFile(path)
    doc = etree.fromstring(zf.read("sources/buildDescription.xml"))
    assert schema.validate(doc), schema.error_log
    listed = {e.get("name") for e in doc.iter("SourceFile")}
    present = {n.removeprefix("sources/") for n in zf.namelist()
               if n.startswith("sources/") and n.endswith(".c")}
    assert listed == {"drymount_fmu.c"}
    unity = zf.read("sources/drymount_fmu.c").decode()
    included = set(re.findall(r'#include "(\w+\.c)"', unity))
    assert included == present - listed


def test_windows_dll_needs_only_the_c_runtime(native, tmp_path):
    """The cross-compiled DLL imports only KERNEL32 and the C runtime and exports the
    FMI functions (skipped without the MinGW cross tools)."""
    import shutil

    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump is None or shutil.which("x86_64-w64-mingw32-gcc") is None:
        pytest.skip("apt-get install gcc-mingw-w64-x86-64 cross-compiles the DLL")
    fmi, path = native
    win = "win64" if fmi == 2 else "x86_64-windows"
    ident = "FrictionMountNative" if fmi == 2 else "FrictionMountNative3"
    dll = zipfile.ZipFile(path).extract(f"binaries/{win}/{ident}.dll", tmp_path)
    text = run([objdump, "-p", dll]).stdout
    imports = {line.split(":")[1].strip().lower() for line in text.splitlines()
               if "DLL Name:" in line}
    assert imports <= {"kernel32.dll", "msvcrt.dll"}, imports
    assert f"] fmi{fmi}DoStep" in text and "python" not in text.lower()
