"""Outputs read after ``doStep`` mean something (issue 30 item 4, step_record.py).

Every generic master reads outputs after ``doStep``. 6000 steps with friction on two
axes (sines of amplitudes that give regular stick and slip on both: axial 3 eps over
200 steps, radial1 2.4 eps over 120 steps) run through fmpy on the PythonFMU build and
both native builds, reading every output after each step, and are compared with an
independent Jenkins slider march written here:

* ``slipped_<axis>`` and ``slip_<axis>`` read after the step equal the slipping of the
  step in 100 % of the steps; ``kt_<axis>`` is the tangent the step ended with (the
  slip tangent k1 after a slip, k1 + kf after a stick);
* ``dE_fr_<axis>`` summed over a period equals the loop area of the macro-slip element,
  4 Fs (a - Fs / kf), to 1e-9 relative, and its running sum is ``E_fr_<axis>``;
* ``ks_<axis>`` is the secant (R_n - R_n-1) / (u_n - u_n-1) of R = F - c v, a repeated
  deflection gives the tangent the step started from;
* the native builds equal the PythonFMU build to 1e-12 (relative to each output's
  scale), and a state saved after a step restores the record.

Also the small item of ``n_<axis>``: an importer that writes every input's declared
start value before stepping keeps the friction force of ``<axis>_n0``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from native_helpers import all_builds

from drymount.fmu_src.interface import VARIABLES

fmpy = pytest.importorskip("fmpy", reason="pip install fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

H = 1e-4
STEPS = 6000
K1, C = 91870.0, 150.0  # the default law's small-deflection stiffness and damping
#: per driven axis: contact stiffness kf (N/m), slip force n0 = Fs (mu = 1, N),
#: amplitude in slip displacements eps = Fs / kf, period in steps (a multiple of 4:
#: the sampled peaks are exactly +-a)
AXES = {"axial": (60000.0, 200.0, 3.0, 200), "radial1": (40000.0, 150.0, 2.4, 120)}
REAL_OUT = ("F", "Ffr", "kt", "E_fr", "dE_fr", "ks")
BOOL_OUT = ("slip", "slipped")


def _amplitude(axis):
    kf, fs, ratio, _ = AXES[axis]
    return ratio * fs / kf


def _inputs():
    """u, v per driven axis and step."""
    k = np.arange(STEPS)
    out = {}
    for axis, (_kf, _fs, _ratio, n) in AXES.items():
        a, w = _amplitude(axis), 2.0 * math.pi / (n * H)
        out[axis] = ([a * math.sin(2.0 * math.pi * i / n) for i in k.tolist()],
                     [a * w * math.cos(2.0 * math.pi * i / n) for i in k.tolist()])
    return out


def _march(axis, us, vs):
    """Independent reference: the Jenkins slider of the axis marched over the
    deflections (exact return map), with the default linear-range elastic law:
    slipping, friction force, tangent, energy per step, the force less the damper."""
    kf, fs, _, _ = AXES[axis]
    w = 0.0
    out = {"slipping": [], "Ffr": [], "kt": [], "dE": [], "R": []}
    for u in us:
        trial = kf * (u - w)
        slipping = abs(trial) > fs
        if slipping:
            w_new = u - math.copysign(fs / kf, trial)
            ffr = math.copysign(fs, trial)
        else:
            w_new, ffr = w, trial
        out["slipping"].append(slipping)
        out["Ffr"].append(ffr)
        out["kt"].append(K1 if slipping else K1 + kf)
        out["dE"].append(fs * abs(w_new - w))
        out["R"].append(K1 * u + ffr)
        w = w_new
    return {k: np.array(v) for k, v in out.items()}


class _Driver:
    """One FMU through fmpy's FMU2Slave / FMU3Slave: parameters, then per step set
    u, v, doStep, read every output after the step."""

    def __init__(self, path, tmp):
        self.md = read_model_description(str(path))
        self.fmi3 = self.md.fmiVersion.startswith("3")
        cls = FMU3Slave if self.fmi3 else FMU2Slave
        self.fmu = cls(guid=self.md.guid, unzipDirectory=extract(str(path), str(tmp)),
                       modelIdentifier=self.md.coSimulation.modelIdentifier,
                       instanceName="mount")
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}

    def _set(self, kind, names, values):
        f = {("real", False): "setReal", ("real", True): "setFloat64",
             ("bool", False): "setBoolean", ("bool", True): "setBoolean"}[
            (kind, self.fmi3)]
        getattr(self.fmu, f)([self.vr[n] for n in names], list(values))

    def real(self, names):
        f = self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal
        return f([self.vr[n] for n in names])

    def boolean(self, names):
        return self.fmu.getBoolean([self.vr[n] for n in names])

    def start(self, before_exit=None):
        fmu = self.fmu
        fmu.instantiate()
        if self.fmi3:
            fmu.enterInitializationMode(startTime=0.0)
        else:
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
        reals, flags = [], []
        for axis, (kf, fs, _, _) in AXES.items():
            reals += [(f"{axis}_kf", kf), (f"{axis}_n0", fs), (f"{axis}_mu", 1.0)]
            flags.append(f"{axis}_friction")
        self._set("real", [n for n, _ in reals], [x for _, x in reals])
        self._set("bool", flags, [True] * len(flags))
        if before_exit is not None:
            before_exit(self)
        fmu.exitInitializationMode()

    def run(self, inputs, k0=0, k1=STEPS):
        names = [f"{q}_{axis}" for axis in AXES for q in ("u", "v")]
        reals = [f"{q}_{axis}" for axis in AXES for q in REAL_OUT]
        flags = [f"{q}_{axis}" for axis in AXES for q in BOOL_OUT]
        got_r = np.zeros((k1 - k0, len(reals)))
        got_b = np.zeros((k1 - k0, len(flags)), dtype=bool)
        for k in range(k0, k1):
            values = [x for axis in AXES for x in (inputs[axis][0][k],
                                                   inputs[axis][1][k])]
            self._set("real", names, values)
            self.fmu.doStep(k * H, H)
            got_r[k - k0] = self.real(reals)
            got_b[k - k0] = self.boolean(flags)
        return ({n: got_r[:, i] for i, n in enumerate(reals)}
                | {n: got_b[:, i] for i, n in enumerate(flags)})

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    return all_builds(tmp_path_factory.mktemp("poststep"))


@pytest.fixture(scope="module")
def runs(fmus, tmp_path_factory):
    inputs = _inputs()
    out = {}
    for name, path in fmus.items():
        d = _Driver(path, tmp_path_factory.mktemp(name))
        try:
            d.start()
            out[name] = d.run(inputs)
        finally:
            d.close()
    return inputs, out


def test_the_excitation_gives_regular_stick_and_slip_on_both_axes():
    inputs = _inputs()
    for axis, (_kf, _fs, _r, n) in AXES.items():
        us = inputs[axis][0]
        a = _amplitude(axis)
        assert max(us) == a and min(us) == -a  # sampled peaks: the closed form holds
        ref = _march(axis, us, inputs[axis][1])
        slipping = ref["slipping"]
        # per period after the first quarter: one stick and one slip phase per half
        changes = np.count_nonzero(slipping[n // 4 + 1:] != slipping[n // 4:-1])
        periods = (STEPS - n // 4 - 1) / n
        assert abs(changes - 4 * periods) <= 4, (axis, changes, periods)
        assert 0.3 < slipping.mean() < 0.8, (axis, slipping.mean())


@pytest.mark.parametrize("build_name", ["pythonfmu", "native2", "native3"])
def test_slip_read_after_the_step_is_the_slipping_of_the_step(runs, build_name):
    inputs, out = runs
    got = out[build_name]
    for axis, (kf, _fs, _r, _n) in AXES.items():
        ref = _march(axis, *inputs[axis])
        slipping = ref["slipping"]
        assert np.array_equal(got[f"slipped_{axis}"], slipping), (
            axis, np.count_nonzero(got[f"slipped_{axis}"] != slipping))
        assert np.array_equal(got[f"slip_{axis}"], slipping), (
            axis, np.count_nonzero(got[f"slip_{axis}"] != slipping))
        # kt after the step: the tangent it ended with (k1 slipping, k1 + kf stuck)
        assert np.array_equal(got[f"kt_{axis}"], ref["kt"]), axis
        np.testing.assert_allclose(got[f"Ffr_{axis}"], ref["Ffr"], rtol=0,
                                   atol=1e-9 * AXES[axis][1])


@pytest.mark.parametrize("build_name", ["pythonfmu", "native2", "native3"])
def test_energy_per_step_sums_to_the_loop_area(runs, build_name):
    inputs, out = runs
    got = out[build_name]
    for axis, (kf, fs, _r, n) in AXES.items():
        a = _amplitude(axis)
        area = 4.0 * fs * (a - fs / kf)  # macro-slip loop, closed form
        de = got[f"dE_fr_{axis}"]
        ref = _march(axis, *inputs[axis])
        np.testing.assert_allclose(de, ref["dE"], rtol=0, atol=1e-12 * area)
        # steps after the peak at k0 up to the next peak, in every whole period
        for k0 in range(n // 4 + n, STEPS - n, n):
            loop = math.fsum(de[k0 + 1:k0 + n + 1].tolist())
            assert abs(loop - area) <= 1e-9 * area, (axis, k0, loop, area)
        # the committed running energy is the sum of the steps' energies
        np.testing.assert_allclose(got[f"E_fr_{axis}"], np.cumsum(de), rtol=1e-12,
                                   atol=1e-15)


@pytest.mark.parametrize("build_name", ["pythonfmu", "native2", "native3"])
def test_secant_stiffness_of_the_step(runs, build_name):
    inputs, out = runs
    got = out[build_name]
    for axis, (kf, _fs, _r, _n) in AXES.items():
        us, vs = inputs[axis]
        ref = _march(axis, us, vs)
        # the first step measures from the end of initialization (u = 0, R = 0,
        # stuck: tangent k1 + kf); a step with du = 0 gives the tangent it started
        # from (here the first: u_0 = 0)
        u_prev, r_prev, kt_prev, secant = 0.0, 0.0, K1 + kf, []
        for u, r, kt in zip(us, ref["R"].tolist(), ref["kt"].tolist()):
            secant.append((r - r_prev) / (u - u_prev) if u != u_prev else kt_prev)
            u_prev, r_prev, kt_prev = u, r, kt
        assert us[0] == 0.0 and secant[0] == K1 + kf
        np.testing.assert_allclose(got[f"ks_{axis}"], secant, rtol=0,
                                   atol=1e-6 * (K1 + kf))
        # between the stiffest (stuck) and the slip tangent
        assert (got[f"ks_{axis}"] <= K1 + kf + 1e-6).all()
        assert (got[f"ks_{axis}"] >= K1 - 1e-6).all()


def test_native_equals_the_pythonfmu_build(runs):
    _, out = runs
    ref = out["pythonfmu"]
    for build_name in ("native2", "native3"):
        for name, values in out[build_name].items():
            if values.dtype == bool:
                assert np.array_equal(values, ref[name]), (build_name, name)
                continue
            scale = max(1.0, float(np.abs(ref[name]).max()))
            worst = float(np.abs(values - ref[name]).max()) / scale
            assert worst <= 1e-12, (build_name, name, worst)


@pytest.mark.parametrize("build_name", ["pythonfmu", "native2", "native3"])
def test_repeated_deflection_and_restored_state(fmus, tmp_path, build_name):
    """A step with the same inputs has no secant: ks is the tangent it started from;
    a state saved after a step restores kt, slip and the record."""
    inputs = _inputs()
    d = _Driver(fmus[build_name], tmp_path)
    names = [f"{q}_axial" for q in ("kt", "ks", "dE_fr")]
    try:
        d.start()
        d.run(inputs, 0, 45)  # slipping towards the peak at step 50
        kt_after = d.real(["kt_axial"])[0]
        assert d.boolean(["slipped_axial", "slip_axial"]) == [True, True]
        assert kt_after == K1
        fmu = d.fmu
        get = fmu.getFMUState if d.fmi3 else fmu.getFMUstate
        put = fmu.setFMUState if d.fmi3 else fmu.setFMUstate
        state = get()
        before = d.real(names) + d.boolean(["slip_axial", "slipped_axial"])
        d.fmu.doStep(45 * H, H)  # inputs of step 44 again: du = 0
        ks, de = d.real(["ks_axial", "dE_fr_axial"])
        assert ks == kt_after and de == 0.0  # (its slipping: the return map's call)
        put(state)
        assert d.real(names) + d.boolean(["slip_axial", "slipped_axial"]) == before
    finally:
        d.close()


def _declared_start_inputs(d):
    """What an importer writing input start values does: every input at its declared
    start, after the parameters (in initialization mode)."""
    inputs = [v for v in VARIABLES if v.causality == "input"]
    assert all(v.start is not None for v in inputs)
    d._set("real", [v.name for v in inputs], [float(v.start) for v in inputs])


@pytest.mark.parametrize("build_name", ["pythonfmu", "native2", "native3"])
def test_inputs_at_their_declared_start_keep_the_friction_force(fmus, tmp_path,
                                                                build_name):
    inputs = _inputs()
    d = _Driver(fmus[build_name], tmp_path)
    try:
        d.start(before_exit=_declared_start_inputs)
        assert d.real(["n_axial", "n_radial1"]) == [AXES["axial"][1],
                                                     AXES["radial1"][1]]
        got = d.run(inputs, 0, 120)
        for axis, (_kf, fs, _r, _n) in AXES.items():
            ref = _march(axis, inputs[axis][0][:120], inputs[axis][1][:120])
            assert float(np.abs(got[f"Ffr_{axis}"]).max()) == fs  # slips at Fs
            assert np.array_equal(got[f"slipped_{axis}"], ref["slipping"])
        # set in step mode the input wins, 0 included: no contact, no friction force
        d._set("real", ["n_axial"], [0.0])
        d.fmu.doStep(120 * H, H)
        assert d.real(["Ffr_axial", "n_axial"]) == [0.0, 0.0]
    finally:
        d.close()
