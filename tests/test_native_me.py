"""Model Exchange of the native FMUs (FMI 2.0 and 3.0): fmpy's ME solver equals the
Co-Simulation result, and the stick/slip events sit at the analytic times of the input.

Input: a sine sweep u = A sin(phi(t)), phi = 2 pi (f0 t + (f1 - f0) t^2 / (2 T)), on
every axis, v = du/dt in closed form. The reference is the same FMU in Co-Simulation
stepped on a grid that holds the analytic velocity reversals (so each step's motion is
monotonic and the rate-independent return map is exact). Analytic events of a Jenkins
slider with slip displacement eps = Fs / k from w = 0: first slip where u = eps, the
reversals where phi = pi/2 + k pi, and the re-slip after each where u has come back by
2 eps (|u| = A - 2 eps); phi(t) = c is a quadratic in t.

fmpy's ME loop applies table inputs only in the event-indicator callback, not in the
derivative one, so the runs with continuous states drive u and v from the sine through
a small subclass of fmpy's FMU model whose setTime sets them (the sine at every
evaluation); the rate-independent elements also run from fmpy's own ``input=`` table.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from native_helpers import build

fmpy = pytest.importorskip("fmpy", reason="pip install -e .[fmu] installs fmpy")

from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Model, FMU2Slave  # noqa: E402
from fmpy.fmi3 import FMU3Model, FMU3Slave  # noqa: E402

AXES = ("axial", "radial1", "radial2")
T, F0, F1, A = 0.4, 4.0, 12.0, 3e-3
C = (F1 - F0) / T
#: ME vs CS, relative to the friction force scale Fs of the axis (the task's 1e-6).
TOL_FORCE = 1e-6
#: event times against the analytic ones [s]
TOL_EVENT = 1e-9
GRID = 1e-3  # output interval of the ME run = CS grid (plus the reversals)

#: Jenkins on the axial axis (eps = 1 mm), an 8-slider micro-slip bank on radial1
#: (eps_i = 1.25 mm * r_i, r_i = 1 + 0.6 ((2 i + 1) / 8 - 1)), radial2 varies.
BASE = {"axial_friction": True, "axial_kf": 6e4, "axial_mu": 1.0, "axial_n0": 60.0,
        "axial_law": 0,
        "radial1_friction": True, "radial1_kf": 8e4, "radial1_n0": 100.0,
        "radial1_sliders": 8, "radial1_spread": 0.6, "radial1_law": 0,
        "radial2_law": 0, "radial2_kf": 5e4, "radial2_n0": 50.0}
KINDS = {"jenkins": 0, "inclined": 1, "dahl": 2, "lugre": 3, "berg": 4}
FS = {"axial": 60.0, "radial1": 100.0, "radial2": 50.0}


def phase(t):
    return 2 * np.pi * (F0 * t + C * t * t / 2)


def sine(t):
    ph, dph = phase(t), 2 * np.pi * (F0 + C * t)
    return A * np.sin(ph), A * dph * np.cos(ph)


def t_of_phase(ph):
    """The root t >= 0 of phase(t) = ph."""
    return (-2 * np.pi * F0 + np.sqrt(4 * np.pi ** 2 * F0 ** 2 + 4 * np.pi * C * ph)) \
        / (2 * np.pi * C)


def reversal_times():
    t = t_of_phase(np.pi / 2 + np.pi * np.arange(40))
    return t[t < T]


def slider_events(eps):
    """Analytic stick/slip events of a slider with slip displacement eps < A/2."""
    out = [t_of_phase(math.asin(eps / A))]
    for k in range(40):
        ph = np.pi / 2 + k * np.pi
        out += [t_of_phase(ph), t_of_phase(ph + math.acos(1 - 2 * eps / A))]
    return {float(t) for t in out if t < T}


def bank_events():
    r = [1 + 0.6 * ((2 * i + 1) / 8 - 1) for i in range(8)]
    return slider_events(1e-3) | {t for ri in r for t in slider_events(1.25e-3 * ri)}


@pytest.fixture(scope="module", params=[2, 3], ids=["fmi2", "fmi3"])
def native(request, tmp_path_factory):
    fmi = request.param
    path = build(tmp_path_factory.mktemp(f"me{fmi}"), fmi)
    return fmi, str(path), read_model_description(str(path)), extract(str(path))


def _inputs(md):
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return [vr[f"{p}_{a}"] for a in AXES for p in ("u", "v")]


def _set_inputs(fmu, fmi, vrs, t):
    u, v = sine(t)
    (fmu.setReal if fmi == 2 else fmu.setFloat64)(vrs, [u, v] * 3)


def _model_class(fmi):
    """fmpy's ME model whose setTime also sets u, v of every axis to the sine (fmpy
    binds the FMI functions by the class name's prefix, hence FMU2... / FMU3...)."""
    base = FMU2Model if fmi == 2 else FMU3Model

    class Driven(base):
        def setTime(self, time):
            super().setTime(time)
            self.now = time
            _set_inputs(self, fmi, self.input_vrs, time)

        def exitInitializationMode(self):
            _set_inputs(self, fmi, self.input_vrs, 0.0)
            return super().exitInitializationMode()

        def enterEventMode(self):
            self.events.append(self.now)
            return super().enterEventMode()

    return type(f"FMU{fmi}Driven", (Driven,), {})


OUTPUTS = [f"{p}_{a}" for a in AXES for p in ("F", "Ffr", "E_fr")]


def run_me(native, params, driven=True):
    """fmpy's ME solver (CVode, rtol 1e-10): (result, event times)."""
    fmi, path, md, unzipped = native
    if not driven:
        t = np.union1d(np.arange(0.0, T + 1e-12, 2e-6), reversal_times())
        u, v = sine(t)
        signal = np.zeros(len(t), dtype=[("time", float)] + [
            (f"{p}_{a}", float) for a in AXES for p in ("u", "v", "n")])
        signal["time"] = t
        for a in AXES:
            signal[f"u_{a}"], signal[f"v_{a}"] = u, v
            signal[f"n_{a}"] = params[f"{a}_n0"]  # as without the input
        result = fmpy.simulate_fmu(path, fmi_type="ModelExchange", stop_time=T,
                                   output_interval=GRID, relative_tolerance=1e-10,
                                   start_values=params, input=signal, output=OUTPUTS,
                                   record_events=False, model_description=md)
        return result, None
    fmu = _model_class(fmi)(guid=md.guid, unzipDirectory=unzipped,
                            modelIdentifier=md.modelExchange.modelIdentifier,
                            instanceName="me")
    fmu.input_vrs, fmu.events, fmu.now = _inputs(md), [], 0.0
    fmu.instantiate()
    try:
        result = fmpy.simulate_fmu(path, fmu_instance=fmu, fmi_type="ModelExchange",
                                   stop_time=T, output_interval=GRID,
                                   relative_tolerance=1e-10, start_values=params,
                                   output=OUTPUTS, record_events=False,
                                   model_description=md)
    finally:
        fmu.freeInstance()
    return result, np.array(fmu.events)


def run_cs(native, params, times):
    """The Co-Simulation FMU: inputs of the sine at each grid time, outputs read
    there (before the step), steps to the next time. {time: outputs}."""
    fmi, path, md, unzipped = native
    slave = (FMU2Slave if fmi == 2 else FMU3Slave)(
        guid=md.guid, unzipDirectory=unzipped,
        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="cs")
    slave.instantiate()
    by_name = {v.name: v for v in md.modelVariables}
    if fmi == 2:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
    else:
        slave.enterInitializationMode(startTime=0.0)
    for name, value in params.items():
        var = by_name[name]
        if var.type == "Boolean":
            slave.setBoolean([var.valueReference], [value])
        elif var.type in ("Integer", "Int32"):
            (slave.setInteger if fmi == 2 else slave.setInt32)([var.valueReference],
                                                               [value])
        else:
            (slave.setReal if fmi == 2 else slave.setFloat64)([var.valueReference],
                                                              [value])
    vrs = _inputs(md)
    _set_inputs(slave, fmi, vrs, 0.0)
    slave.exitInitializationMode()
    get = slave.getReal if fmi == 2 else slave.getFloat64
    out_vrs = [by_name[o].valueReference for o in OUTPUTS]
    got = {}
    for i, t in enumerate(times):
        _set_inputs(slave, fmi, vrs, t)
        got[round(float(t), 9)] = np.array(get(out_vrs))
        if i + 1 < len(times):
            slave.doStep(t, times[i + 1] - t)
    slave.terminate()
    slave.freeInstance()
    return got


def compare(native, params, me):
    """Worst |ME - CS| per output over the output grid, relative to the axis's Fs
    (forces) and to its largest CS energy (energies)."""
    cs = run_cs(native, params, np.union1d(np.arange(0, round(T / GRID) + 1) * GRID,
                                           reversal_times()))
    ref = np.array([cs[round(float(t), 9)] for t in me["time"]])
    got = np.array([[row[o] for o in OUTPUTS] for row in me])
    assert len(me) == round(T / GRID) + 1
    err = {}
    for i, name in enumerate(OUTPUTS):
        axis = name.rpartition("_")[2]
        scale = FS[axis] if not name.startswith("E_fr") else \
            max(np.abs(ref[:, i]).max(), 1e-12)
        err[name] = float(np.abs(got[:, i] - ref[:, i]).max()) / scale
    return err, ref


def match_events(events, analytic):
    """Worst distance of an analytic event to the nearest FMU event and back."""
    analytic = np.array(sorted(analytic))
    miss = max(float(np.abs(events - t).min()) for t in analytic)
    extra = max(float(np.abs(analytic - t).min()) for t in events)
    return miss, extra


def test_sweep_me_equals_cs_and_locates_the_events(native):
    """Jenkins (axial), micro-slip bank (radial1), Dahl (radial2): forces and
    energies equal CS to 1e-6, every stick/slip event within 1e-9 s of the analytic
    one and no other event (radial2's reversals are the bank's)."""
    params = dict(BASE, radial2_friction=True, radial2_friction_kind=KINDS["dahl"])
    me, events = run_me(native, params)
    err, ref = compare(native, params, me)
    # friction forces were exercised: every axis slipped at its full slip force
    for a in AXES:
        assert np.abs(ref[:, OUTPUTS.index(f"Ffr_{a}")]).max() > 0.95 * FS[a]
    assert max(err.values()) < TOL_FORCE, err
    analytic = bank_events()
    assert len(events) == len(analytic) > 60
    miss, extra = match_events(events, analytic)
    assert miss < TOL_EVENT and extra < TOL_EVENT, (miss, extra)



def test_maxwell_branch_leaves_the_bank_events(native):
    """A Maxwell branch beside the micro-slip bank (radial1) puts uc and its strokes
    after the 8 sliders in the axis's state; the bank's modes and event indicators
    read the sliders only, so the events are the bank's analytic ones as without the
    branch (me.c took uc and the strokes for more sliders, and with 64 sliders wrote
    their modes past the bank's row of ML_MAX_SLIDERS)."""
    params = dict(BASE, radial2_friction=True, radial2_friction_kind=KINDS["dahl"],
                  radial1_maxwell_k1=2e4, radial1_maxwell_c1=50.0)
    _, events = run_me(native, params)
    analytic = bank_events()
    assert len(events) == len(analytic)
    miss, extra = match_events(events, analytic)
    assert miss < TOL_EVENT and extra < TOL_EVENT, (miss, extra)


@pytest.mark.parametrize("kind", ["inclined", "berg", "lugre"])
def test_other_elements_me_equals_cs(native, kind):
    """The inclined element, Berg's and LuGre (sigma1 = sigma2 = 0, no Stribeck: the
    CS increment is then exact too) on radial2: forces equal CS to 1e-6 of Fs (the
    inclined one: of its preload). Berg's energy is compared loosely: its CS
    bookkeeping clamps a negative increment to 0, so it depends on the steps (ME
    gives their limit: test_native_me_state)."""
    params = dict(BASE, radial2_friction=True, radial2_friction_kind=KINDS[kind])
    me, events = run_me(native, params)
    err, _ = compare(native, params, me)
    forces = {k: v for k, v in err.items() if not k.startswith("E_fr")}
    assert max(forces.values()) < TOL_FORCE * (FS["radial2"] / 200.0
                                               if kind == "inclined" else 1.0), err
    energies = {k: v for k, v in err.items() if k.startswith("E_fr")}
    assert max(v for k, v in energies.items() if k != "E_fr_radial2") < TOL_FORCE
    if kind != "berg":
        assert energies["E_fr_radial2"] < TOL_FORCE, err
    # the Jenkins and bank events are all there (the inclined adds its own)
    miss, _ = match_events(events, bank_events())
    assert miss < TOL_EVENT


def test_me_with_fmpy_input_table(native):
    """fmpy's own input= path (linear interpolation of a 2 us table that holds the
    reversal times) with the discrete elements only: forces equal CS to 1e-6."""
    params = dict(BASE, radial2_friction=True, radial2_friction_kind=KINDS["jenkins"],
                  radial2_sliders=3, radial2_spread=0.3, radial2_fs_ratio=0.7)
    me, _ = run_me(native, params, driven=False)
    err, _ = compare(native, params, me)
    assert max(err.values()) < TOL_FORCE, err


def lugre_reference(kf, fc, fs_static, vs, s1, s2, times):
    """The LuGre element under the sine, integrated here: dz/dt = v - kf |v| z /
    g(v), g = Fc + (Fs - Fc) exp(-(v/vs)^2), F = kf z + s1 dz/dt + s2 v (scipy's
    DOP853 at rtol 1e-12, restarted at every reversal)."""
    from scipy.integrate import solve_ivp

    def g(v):
        return fc + (fs_static - fc) * math.exp(-(v / vs) ** 2)

    def rhs(t, y):
        _, v = sine(t)
        return [v - kf * abs(v) * y[0] / g(v)]

    bounds = [0.0, *reversal_times(), T]
    z_at, z = {}, 0.0
    for t0, t1 in zip(bounds[:-1], bounds[1:], strict=True):
        inside = [t for t in times if t0 <= t <= t1]
        sol = solve_ivp(rhs, (t0, t1), [z], method="DOP853", rtol=1e-12, atol=1e-16,
                        t_eval=inside, dense_output=False)
        z_at.update(zip(inside, sol.y[0], strict=True))
        z = float(solve_ivp(rhs, (t0, t1), [z], method="DOP853", rtol=1e-12,
                            atol=1e-16).y[0][-1])
    out = []
    for t in times:
        _, v = sine(t)
        zdot = v - kf * abs(v) * z_at[t] / g(v)
        out.append(kf * z_at[t] + s1 * zdot + s2 * v)
    return np.array(out)


def test_lugre_me_against_an_independent_integration(native):
    """LuGre with damping and a Stribeck peak (rate dependent, so CS is not exact):
    ME's friction force equals the integration above to 1e-6 of Fs."""
    pytest.importorskip("scipy")
    kf, n0, s1, s2, ratio, vs = 5e4, 50.0, 30.0, 40.0, 1.5, 0.02
    params = dict(BASE, radial2_friction=True, radial2_friction_kind=KINDS["lugre"],
                  radial2_sigma1=s1, radial2_sigma2=s2, radial2_stribeck_ratio=ratio,
                  radial2_v_stribeck=vs)
    me, _ = run_me(native, params)
    ref = lugre_reference(kf, n0, ratio * n0, vs, s1, s2, list(me["time"]))
    err = float(np.abs(me["Ffr_radial2"] - ref).max()) / n0
    assert np.abs(ref).max() > n0  # the Stribeck peak and the damping were reached
    assert err < TOL_FORCE, err


def test_model_description_declares_both_interfaces(native):
    from fmpy.validation import validate_fmu

    fmi, path, md, _ = native
    assert validate_fmu(path) == []
    assert md.modelExchange.modelIdentifier == md.coSimulation.modelIdentifier
    assert md.numberOfContinuousStates == 6 and md.numberOfEventIndicators == 6
    assert md.modelExchange.needsCompletedIntegratorStep


def test_interface_calls_are_refused_in_the_other_interface(native):
    """A Model Exchange call on a Co-Simulation instance, doStep on a Model Exchange
    one: fmiError, nothing changed."""
    from ctypes import c_double, c_void_p

    from fmpy.fmi1 import FMICallException

    fmi, path, md, unzipped = native
    kw = dict(guid=md.guid, unzipDirectory=unzipped,
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
    slave = (FMU2Slave if fmi == 2 else FMU3Slave)(**kw)
    slave.instantiate()
    assert getattr(slave.dll, f"fmi{fmi}SetTime")(c_void_p(slave.component),
                                                  c_double(0.5)) == 3
    slave.freeInstance()
    model = (FMU2Model if fmi == 2 else FMU3Model)(**kw)
    model.instantiate()
    if fmi == 2:
        model.setupExperiment(startTime=0.0)
        model.enterInitializationMode()
    else:
        model.enterInitializationMode(startTime=0.0)
    model.exitInitializationMode()
    step = getattr(model.dll, f"fmi{fmi}DoStep")
    args = (c_void_p(model.component), c_double(0.0), c_double(1e-3), 0)
    assert (step(*args) if fmi == 2 else step(*args, None, None, None, None)) == 3
    with pytest.raises(FMICallException):
        model.setContinuousStates(*_states_buffer())  # not in event mode
    model.freeInstance()


def _states_buffer():
    from ctypes import c_double

    x = (c_double * 6)()
    return x, 6
