"""The FMU's FMI 2.0 call-order rules (docs/fmu.md "Call-order rules", issue 11).

Each rule with a direct test through fmpy (status fmi2Error, a log message naming the
call, the state and the value, nothing changed), the slave class called from Python
(FMICallError), and a hypothesis property test: random sequences of FMI calls with
random values, run in a subprocess (tests/importers/fmi_sequence_drive.py), against
an oracle written from the rules in docs/fmu.md (not from fmu_src/fmi_state.py). It
checks: the process never dies, no call is fatal, every call is accepted or rejected
as the rules say, no output read is NaN or infinite, after every rejected call the
instance still answers, and after every sequence fmi2Reset gives a usable instance.

The property test runs on both implementations, the PythonFMU build and the native
FMI 2.0 build (fmu_src/native), with the same oracle.

Runtime: ~20 s (two FMU builds, 2 x 200 sequences of up to 34 calls, one importer
process each). Mutations of fmu_src/fmi_state.py (parameters settable after
initialization, no step-size bound, terminate in any state) make it fail.
"""

from __future__ import annotations

import gc
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("fmpy", reason="pip install fmpy (the test extra)")
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_fmu import FMI_ERROR, FMI_OK, Mount  # noqa: E402

DRIVER = Path(__file__).parent / "importers" / "fmi_sequence_drive.py"
REPO = Path(__file__).resolve().parents[1]
#: Sequences the property test runs (each up to MAX_CALLS calls).
N_SEQUENCES = 200
MAX_CALLS = 30

PARAMS = {"axial_friction": True, "axial_n0": 50.0, "axial_kf": 60000.0}


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    """(model description, unzip directory, value references by name) of a fresh
    build (as tests/test_fmu.py's fixture)."""
    from fmpy import extract, read_model_description

    from drymount.fmu_build import build_fmu

    path = build_fmu(tmp_path_factory.mktemp("fmu") / "FrictionMount.fmu")
    md = read_model_description(str(path))
    unzipdir = extract(str(path), unzipdir=str(tmp_path_factory.mktemp("unzip")))
    return md, unzipdir, {v.name: v.valueReference for v in md.modelVariables}


def _messages(mount) -> str:
    return "\n".join(text for _, text in mount.messages)


# ======================================================================================
# The rules, one by one (fmpy)
# ======================================================================================


def test_fixed_parameter_after_initialization_is_rejected(fmu):
    mount = Mount(fmu, params=PARAMS).start()
    try:
        f0 = mount.real(["F_axial"])
        with pytest.raises(Exception) as info:
            mount.set("axial_k1", 1.0)
        assert info.value.status == FMI_ERROR
        assert ("fmi2SetReal: `axial_k1` is a fixed parameter and cannot be set after "
                "fmi2ExitInitializationMode (state stepComplete, value 1.0)"
                in _messages(mount))
        assert mount.real(["axial_k1"]) == [91870.0]  # unchanged: the physics too
        mount.set("u_axial", 0.001)
        assert mount.real(["F_axial"]) != f0  # still usable
        mount.slave.doStep(0.0, 1e-4)
    finally:
        mount.free()
    gc.collect()


@pytest.mark.parametrize("t, h, needle", [
    (0.0, 0.0, "the step size must be finite and > 0, got communicationStepSize = 0.0"),
    (0.0, -1e-4, "finite and > 0, got communicationStepSize = -0.0001"),
    (0.0, math.nan, "finite and > 0, got communicationStepSize = nan"),
    (0.0, 1e300,
     "the step size must be <= 1e+06 s, got communicationStepSize = 1e+300"),
    (-1.0, 1e-4, "currentCommunicationPoint = -1.0 does not continue from the end of "
                 "the previous step, 0.0"),
    (math.inf, 1e-4, "the time must be finite, got currentCommunicationPoint = inf"),
])
def test_bad_step_is_rejected_and_the_next_good_one_works(fmu, t, h, needle):
    mount = Mount(fmu, params=PARAMS).start()
    try:
        mount.set("u_axial", 0.002)
        before = mount.real(["E_fr", "w_axial", "F_axial"])
        with pytest.raises(Exception) as info:
            mount.slave.doStep(t, h)
        assert info.value.status == FMI_ERROR
        assert needle in _messages(mount), _messages(mount)
        assert before[1] == 0.0
        assert mount.real(["E_fr", "w_axial", "F_axial"]) == before  # nothing committed
        mount.slave.doStep(0.0, 1e-4)
        mount.set("u_axial", -0.002)
        mount.slave.doStep(1e-4, 1e-4)
        assert mount.real(["E_fr"])[0] > 0.0
    finally:
        mount.free()
    gc.collect()


def test_time_going_backwards_is_rejected(fmu):
    mount = Mount(fmu, params=PARAMS).start()
    try:
        for k in range(3):
            mount.slave.doStep(k * 1e-4, 1e-4)
        with pytest.raises(Exception):
            mount.slave.doStep(1e-4, 1e-4)
        assert "currentCommunicationPoint = 0.0001 does not continue from the end of " \
            "the previous step, 0.0003" in _messages(mount)
        mount.slave.doStep(3e-4, 2e-4)  # a different step size is fine
    finally:
        mount.free()
    gc.collect()


@pytest.mark.parametrize("call, state", [
    ("doStep", "initializationMode"), ("exitInitializationMode", "stepComplete"),
    ("enterInitializationMode", "stepComplete"), ("setupExperiment", "stepComplete"),
    ("terminate", "initializationMode"),
])
def test_calls_out_of_order_name_call_and_state(fmu, call, state):
    mount = Mount(fmu, params=PARAMS)
    try:
        if state == "stepComplete":
            mount.start()
        fn = {"doStep": lambda: mount.slave.doStep(0.0, 1e-4),
              "exitInitializationMode": mount.slave.exitInitializationMode,
              "enterInitializationMode": mount.slave.enterInitializationMode,
              "setupExperiment": lambda: mount.slave.setupExperiment(startTime=0.0),
              "terminate": mount.slave.terminate}[call]
        with pytest.raises(Exception) as info:
            fn()
        assert info.value.status == FMI_ERROR
        assert f"fmi2{call[0].upper()}{call[1:]} is not allowed in state {state}" \
            in _messages(mount), _messages(mount)
        if state == "initializationMode":
            mount.start()
        mount.slave.doStep(0.0, 1e-4)  # usable in the state it was in
    finally:
        mount.free()
    gc.collect()


def test_set_real_on_an_output_is_an_error_not_fatal(fmu):
    mount = Mount(fmu, params=PARAMS).start()
    try:
        for name in ("F_axial", "E_fr"):
            with pytest.raises(Exception) as info:
                mount.slave.setReal([mount.vr[name]], [1.0])
            assert info.value.status == FMI_ERROR
            assert f"`{name}` is an output and cannot be set" in _messages(mount)
        with pytest.raises(Exception) as info:
            mount.slave.setReal([mount.vr["axial_law"]], [1.0])
        assert "`axial_law` (value reference" in _messages(mount)
        assert "is a Integer; use fmi2SetInteger" in _messages(mount)
        mount.slave.doStep(0.0, 1e-4)
    finally:
        mount.free()
    gc.collect()


def test_bad_parameter_error_at_exit_and_outputs_zero_before(fmu):
    """Reading outputs in initialization mode with a bad parameter never fails (0,
    a warning); fmi2ExitInitializationMode returns fmi2Error naming it; fixing the
    parameter and exiting again works."""
    mount = Mount(fmu, params={**PARAMS, "axial_kf": -5.0})
    try:
        assert mount.real(["F_axial", "E_fr"]) == [0.0, 0.0]
        assert "outputs are 0 until the parameters are valid" in _messages(mount)
        with pytest.raises(Exception) as info:
            mount.start()
        assert info.value.status == FMI_ERROR
        assert "`axial_kf` must be finite and > 0 when friction is on, got -5.0" \
            in _messages(mount)
        mount.set("axial_kf", 60000.0)
        mount.start()
        mount.set("u_axial", 0.001)
        assert mount.real(["F_axial"])[0] > 0.0
    finally:
        mount.free()
    gc.collect()


def test_slave_called_from_python_raises_fmi_call_error():
    from drymount.fmu_src.friction_mount import FMICallError, FrictionMount

    s = FrictionMount(instance_name="py")
    vr = {v.name: k for k, v in s.vars.items()}
    with pytest.raises(FMICallError, match="fmi2DoStep is not allowed in state "
                                           "instantiated"):
        s.do_step(0.0, 1e-4)
    s.setup_experiment(0.0)
    s.enter_initialization_mode()
    s.exit_initialization_mode()
    with pytest.raises(FMICallError, match="`axial_c` is a fixed parameter"):
        s.set_real([vr["axial_c"]], [1.0])
    assert s.do_step(0.0, 1e-4)


# ======================================================================================
# Property test: random call sequences through fmpy, in a subprocess
# ======================================================================================

REALS = st.one_of(st.floats(-1e3, 1e3, allow_nan=False),
                  st.sampled_from([0.0, -0.0, math.nan, math.inf, -math.inf, 1e-300]))
STEPS = st.sampled_from([1e-4, 2.5e-4, 0.0, -1e-4, math.nan, math.inf, 1e300, 1e-3])
REAL_VARS = ("axial_k1", "axial_c", "axial_kf", "u_axial", "v_axial", "n_axial",
             "w_axial", "F_axial", "E_fr")

CALL = st.one_of(
    st.tuples(st.just("setup"), st.sampled_from([0.0, 1.5, math.nan, math.inf])),
    st.tuples(st.just("enter")), st.tuples(st.just("exit")),
    st.tuples(st.just("terminate")), st.tuples(st.just("reset")),
    st.tuples(st.just("setReal"), st.sampled_from(REAL_VARS), REALS),
    st.tuples(st.just("setInteger"), st.just("axial_law"), st.integers(-2, 5)),
    st.tuples(st.just("setBoolean"), st.just("axial_friction"), st.booleans()),
    st.tuples(st.just("getReal"), st.sampled_from(("F_axial", "E_fr", "axial_k1",
                                                   "u_axial", "n_axial"))),
    # doStep (twice as likely): continue from the end of the last step, or jump
    st.tuples(st.just("doStep"), st.sampled_from([0.0, 0.0, 0.0, -1e-2, 5e-3]), STEPS),
    st.tuples(st.just("doStep"), st.just(0.0), STEPS),
    st.tuples(st.just("doStep"), st.sampled_from([-1e-2, 5e-3, -1e-4]), st.just(1e-4)),
    st.tuples(st.just("getState")), st.tuples(st.just("setState"), st.integers(0, 2)),
)


class Oracle:
    """The call-order rules of docs/fmu.md, for predicting each call's status."""

    PARAM_OK = {"axial_k1": lambda v: v >= 0, "axial_c": lambda v: v >= 0}

    def __init__(self):
        self.reset()
        self.saved = []

    def reset(self):
        self.mode, self.t_next, self.friction = "instantiated", None, False
        self.values = {"axial_k1": 91870.0, "axial_c": 150.0, "axial_kf": 60000.0,
                       "axial_law": 2}

    def params_ok(self) -> bool:
        v = self.values
        kf_ok = v["axial_kf"] > 0 if self.friction else v["axial_kf"] >= 0
        return (v["axial_k1"] >= 0 and v["axial_c"] >= 0 and kf_ok
                and 0 <= v["axial_law"] <= 3)

    def apply(self, call) -> tuple[bool, list]:
        """``(accepted, concrete call)``; updates the state when accepted."""
        name, *args = call
        m = self.mode
        if name == "setup":
            ok = m == "instantiated" and math.isfinite(args[0])
            if ok:
                self.t_next = args[0]
            return ok, list(call)
        if name == "enter":
            ok = m == "instantiated"
            self.mode = "initializationMode" if ok else m
            return ok, list(call)
        if name == "exit":
            ok = m == "initializationMode" and self.params_ok()
            self.mode = "stepComplete" if ok else m
            return ok, list(call)
        if name == "terminate":
            ok = m == "stepComplete"
            self.mode = "terminated" if ok else m
            return ok, list(call)
        if name == "reset":
            self.reset()
            return True, list(call)
        if name == "getReal":
            return True, list(call)
        if name == "getState":
            self.saved.append((self.mode, self.t_next, self.friction,
                               dict(self.values)))
            return True, list(call)
        if name == "setState":
            k = args[0]
            if k >= len(self.saved):
                return None, None  # not sent
            self.mode, self.t_next, self.friction, values = self.saved[k]
            self.values = dict(values)
            return True, list(call)
        if name == "doStep":
            offset, h = args
            t = (self.t_next if self.t_next is not None else 0.0) + offset
            ok = (m == "stepComplete" and math.isfinite(h) and 0 < h <= 1e6
                  and (self.t_next is None or offset == 0.0))
            if ok:
                self.t_next = t + h
            return ok, ["doStep", t, h]
        var, value = args
        if var in ("F_axial", "E_fr"):
            return False, list(call)
        causality = "input" if var in ("u_axial", "v_axial", "n_axial") else \
            "local" if var == "w_axial" else "parameter"
        allowed = {"parameter": ("instantiated", "initializationMode"),
                   "local": ("instantiated", "initializationMode", "stepComplete"),
                   "input": ("instantiated", "initializationMode", "stepComplete")}
        ok = m in allowed[causality] and (name != "setReal" or math.isfinite(value))
        if ok and var == "axial_friction":
            self.friction = bool(value)
        elif ok and var in self.values:
            self.values[var] = value
        return ok, list(call)


@pytest.fixture(scope="module", params=["pythonfmu", "native"])
def driver(request, fmu, tmp_path_factory):
    """The sequence driver on the PythonFMU build or the native FMI 2.0 build: both
    are held to the same oracle."""
    unzipdir = fmu[1]
    if request.param == "native":
        from fmpy import extract

        from drymount.fmu_build.native import build_native_fmu

        path = build_native_fmu(tmp_path_factory.mktemp("native") / "native.fmu").path
        unzipdir = extract(str(path), unzipdir=str(tmp_path_factory.mktemp("unzip")))
    proc = subprocess.Popen([sys.executable, str(DRIVER), str(unzipdir)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(REPO)})
    yield proc
    proc.stdin.close()
    proc.wait(timeout=30)
    proc.stdout.close()
    proc.stderr.close()


#: Starts of a sequence, so that every state is reached often (a uniformly random
#: sequence seldom gets past initialization).
PREFIXES = st.sampled_from([
    [], [("enter",)], [("setup", 0.0), ("enter",), ("exit",)],
    [("setup", 0.0), ("enter",), ("exit",), ("doStep", 0.0, 1e-4)],
    [("enter",), ("exit",), ("terminate",)],
])


@settings(max_examples=N_SEQUENCES, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture,
                                 HealthCheck.too_slow])
@given(PREFIXES, st.lists(CALL, min_size=1, max_size=MAX_CALLS))
def test_random_call_sequences(driver, prefix, calls):
    calls = list(prefix) + calls
    oracle = Oracle()
    expected, sent = [], []
    for call in calls:
        ok, concrete = oracle.apply(call)
        if concrete is None:
            continue
        expected.append(ok)
        sent.append(concrete)
    driver.stdin.write(json.dumps(sent) + "\n")
    driver.stdin.flush()
    line = driver.stdout.readline()
    assert line, f"the importer process died: {driver.stderr.read()[-3000:]}\n{sent}"
    res = json.loads(line)
    statuses = [a[0] for a in res["answers"]]
    assert 4 not in statuses, (sent, statuses)  # never fatal
    assert len(statuses) == len(sent)
    for call, ok, (status, values) in zip(sent, expected, res["answers"], strict=True):
        assert status == (FMI_OK if ok else FMI_ERROR), (call, status, sent)
        if values is not None:
            assert all(math.isfinite(x) for x in values), (call, values, sent)
    # every rejected call logged one message of status error
    assert res["errors_logged"] == expected.count(False), (res, sent)
    for status, values in res["probes"]:  # after every rejection: still answers
        assert status == FMI_OK and all(math.isfinite(x) for x in values), res
    assert res["usable"], sent
