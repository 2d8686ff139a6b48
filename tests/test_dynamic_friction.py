"""The LuGre and Berg friction elements (fmu_src/lugre.py, fmu_src/berg.py) through
the element contract: the law, both FMUs (PythonFMU, native C for FMI 2.0 and 3.0),
the harness (both backends, batched), the HBM's generic march, static and
characterise, each against a fine-step integration of the law written here:

LuGre (Canudas de Wit et al. 1995), sigma0 = kf:

    dz/dt = v - kf |v| z / g(v),  g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2),
    F = kf z + sigma1 dz/dt + sigma2 v,  Fc = mu n,  Fs = stribeck_ratio Fc

Berg (1998), from the last reversal (xs, Fxs), s the direction of motion:

    dF/du = kf A^2 / (A + kf |u - xs|)^2,  A = Fm - s Fxs,  Fm = mu n

(RK4 along each increment, and for the single-DOF engine RK4 in time of
m x'' = f0 w^2 sin(w t) - k1 x - c x' - F with the element's ODE).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from drymount.fmu_src.mount_law import (AxisParameters, MountParameters, axis_force,
                                        initial_sliders)
from drymount.hbm.systems import sdof

#: the law against its RK4 reference along a path, relative to Fc (RK4 with 400
#: substeps per increment; measured below 1e-10)
RTOL_LAW = 1e-8
#: the FMUs against the in-process law (the same operations; exp/log1p from libm as
#: Python's), relative to the largest force: the bar of a second implementation
RTOL_FMU = 1e-12
#: steady fundamental amplitude of the harness (1024 steps per period) and the HBM
#: (H = 9, N = 512) against the RK4 SDOF reference (4000 steps per period): the
#: 0.2 % of peak of issue 28 (measured: harness 3.9e-6 LuGre, 4.0e-6 Berg; HBM
#: 8.5e-6 LuGre, 3.6e-7 Berg)
RTOL_SDOF = 2e-3
#: characterise (AFT generic march, N = 1024) against the RK4 loop (LuGre: in time
#: with the exact rate; Berg: in u): measured 2.5e-7 and 5e-16
RTOL_K = 1e-5

KF, MU, N0 = 60000.0, 1.0, 10.0
BASE = AxisParameters(law="linear", k1=45935.0, c=150.0, friction=True, kf=KF,
                      mu=MU, n0=N0)
AXES = {
    "lugre": replace(BASE, friction_kind="lugre", sigma1=120.0, sigma2=20.0,
                     stribeck_ratio=1.5, v_stribeck=0.01),
    "berg": replace(BASE, friction_kind="berg"),
}
MASS, F0, FREQ = 70.0, 0.030478, 6.0


# ---------------------------------------------------------------- the references

def _stribeck(p, v, fc):
    return fc + (p.stribeck_ratio * fc - fc) * math.exp(-(v / p.v_stribeck) ** 2)


def lugre_rhs(p, z, v, fc):
    """dz/dt and F of the LuGre law at bristle z and rate v."""
    zdot = v - p.kf * abs(v) * z / _stribeck(p, v, fc)
    return zdot, p.kf * z + p.sigma1 * zdot + p.sigma2 * v


def berg_slope(p, u, xs, fxs, s, fm):
    a = fm - s * fxs
    return p.kf * a * a / (a + p.kf * abs(u - xs)) ** 2


def _rk4(f, y, h):
    k1 = f(y)
    k2 = f(y + 0.5 * h * k1)
    k3 = f(y + 0.5 * h * k2)
    k4 = f(y + h * k3)
    return y + h * (k1 + 2 * k2 + 2 * k3 + k4) / 6.0


def reference_path(kind, us, dt, sub=400):
    """Friction force at the points of ``us`` (one increment of dt seconds each, u
    linear in time inside it), RK4 with ``sub`` substeps per increment, from the
    element relaxed at us[0]."""
    p, fc = AXES[kind], MU * N0
    out = [0.0]
    z = 0.0                                    # LuGre
    F, xs, fxs, s_last = 0.0, us[0], 0.0, 0.0  # Berg
    for a, b in zip(us[:-1], us[1:]):
        if kind == "lugre":
            r = (b - a) / dt
            z = _rk4_steps(lambda z: lugre_rhs(p, z, r, fc)[0], z, dt / sub, sub)
            out.append(lugre_rhs(p, z, r, fc)[1])
            continue
        s = math.copysign(1.0, b - a)
        if s != s_last:
            xs, fxs, s_last = a, F, s
        h = (b - a) / sub
        for i in range(sub):   # RK4 in u of dF/du (Simpson: it depends on u only)
            F = _rk4_u(p, F, a + i * h, h, xs, fxs, s, fc)
        out.append(F)
    return np.array(out)


def _rk4_steps(f, y, h, n):
    for _ in range(n):
        y = _rk4(f, y, h)
    return y


def _rk4_u(p, F, x, h, xs, fxs, s, fm):
    """One RK4 step in u of Berg's dF/du (which depends on u only)."""
    k1 = berg_slope(p, x, xs, fxs, s, fm)
    k2 = berg_slope(p, x + h / 2, xs, fxs, s, fm)
    k4 = berg_slope(p, x + h, xs, fxs, s, fm)
    return F + h * (k1 + 4 * k2 + k4) / 6.0


def sdof_reference(kind, freq_hz=FREQ, periods=60, steps=4000):
    """Fundamental amplitude of x of the unbalance-driven SDOF on the element (RK4
    in time, the last period; Berg's reference moves to (x, F) where v changes sign
    between steps)."""
    p, fc = AXES[kind], MU * N0
    w = 2.0 * math.pi * freq_hz
    h = 2.0 * math.pi / (w * steps)
    ref = [0.0, 0.0, 0.0]   # Berg: xs, Fxs, s

    def rhs(t, y):
        x, v, q = y
        if kind == "lugre":
            qdot, F = lugre_rhs(p, q, v, fc)
        else:
            s = math.copysign(1.0, v) if v else ref[2]
            F, qdot = q, berg_slope(p, x, ref[0], ref[1], s, fc) * v
        a = (F0 * w * w * math.sin(w * t) - p.k1 * x - p.c * v - F) / MASS
        return np.array((v, a, qdot))

    y, last = np.zeros(3), np.empty(steps)
    for k in range(periods * steps):
        y_new = _rk4_t(rhs, k * h, y, h)
        if kind == "berg":
            s = math.copysign(1.0, y_new[1])
            if s != ref[2]:   # a reversal inside the step: the reference moves there
                ref[:] = [y_new[0], y_new[2], s]
        y = y_new
        if k >= (periods - 1) * steps:
            last[k - (periods - 1) * steps] = y[0]
    th = w * h * (np.arange(steps) + 1)
    return float(np.hypot(2 / steps * last @ np.sin(th), 2 / steps * last @ np.cos(th)))


def _rk4_t(rhs, t, y, h):
    k1 = rhs(t, y)
    k2 = rhs(t + h / 2, y + h / 2 * k1)
    k3 = rhs(t + h / 2, y + h / 2 * k2)
    k4 = rhs(t + h, y + h * k3)
    return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


# ---------------------------------------------------------------- the law

def _path(seed=11, n=300):
    rng = np.random.default_rng(seed)
    return np.concatenate([[0.0], np.cumsum(rng.normal(0.0, 1.5e-4, n))])


def _law_run(p, us, dt, vs=None, ns=None):
    """The in-process law along ``us`` as the FMU protocol runs it: the increment
    to row k spans dt (0 at row 0), rate vs[k] (default the increment's)."""
    w, out, diss = initial_sliders(p, float(us[0])), [], 0.0
    for k, u in enumerate(us.tolist()):
        h = dt if k else 0.0
        v = (u - us[k - 1]) / dt if vs is None and k else (0.0 if vs is None
                                                           else float(vs[k]))
        r = axis_force(u, v, w, p, None if ns is None else float(ns[k]), h)
        assert r.dissipated >= 0.0
        w = r.w_new
        out.append(r.friction_force)
        diss += r.dissipated
    return np.array(out), diss


@pytest.mark.parametrize("kind", list(AXES))
def test_law_against_the_fine_step_integration(kind):
    us, dt = _path(), 1e-3
    got, diss = _law_run(AXES[kind], us, dt)
    ref = reference_path(kind, us, dt)
    assert np.max(np.abs(got - ref)) <= RTOL_LAW * MU * N0
    assert diss > 0.0


def test_lugre_without_damping_and_stribeck_is_dahl():
    """sigma1 = sigma2 = 0, Fs = Fc: g is constant and dz/du = 1 - kf sign(du) z / Fc,
    Dahl's law for F = kf z (exponent 1)."""
    us = _path(3)
    a, _ = _law_run(replace(AXES["lugre"], sigma1=0.0, sigma2=0.0,
                            stribeck_ratio=1.0), us, 1e-3)
    b, _ = _law_run(replace(BASE, friction_kind="dahl"), us, 1e-3)
    assert np.max(np.abs(a - b)) <= 1e-13 * MU * N0


def test_lugre_steady_sliding_is_the_stribeck_curve():
    """At a constant rate the bristle settles at z = g(v) / kf: F = g(v) + sigma2 v."""
    p = AXES["lugre"]
    for v in (0.002, 0.01, 0.05):
        dt = 1e-3   # 8 mm and more of sliding: 30 relaxation lengths g / kf and more
        us = v * dt * np.arange(4000)
        F, _ = _law_run(p, us, dt, vs=np.full(us.size, v))
        g = MU * N0 * (1.0 + 0.5 * math.exp(-(v / p.v_stribeck) ** 2))
        assert F[-1] == pytest.approx(g + p.sigma2 * v, rel=1e-12)


def test_berg_virgin_curve_and_reversal():
    """Berg's x2 = Fm / kf: from the virgin state F(x2) = Fm / 2, the tangent after a
    reversal is kf, and cycling between +-X settles on the symmetric loop whose tip
    force Fa solves Fa^2 + Fa (Fm + kf X) - kf X Fm = 0 (F(-X) = -Fa from (X, Fa))."""
    p, fm = AXES["berg"], MU * N0
    x2 = fm / KF
    F, _ = _law_run(p, np.array([0.0, x2]), 1e-3)
    assert F[-1] == pytest.approx(fm / 2, rel=1e-14)
    X = 4 * x2
    F, _ = _law_run(p, np.array([0.0] + [X, -X] * 40), 1e-3)
    b = fm + KF * X
    tip = (-b + math.sqrt(b * b + 4 * KF * X * fm)) / 2
    assert F[-2] == pytest.approx(tip, rel=1e-12)
    assert F[-1] == pytest.approx(-tip, rel=1e-12)
    w = initial_sliders(p)
    r1 = axis_force(X, 0.0, w, p)
    h = 1e-10
    back = axis_force(X - h, 0.0, r1.w_new, p)
    assert (r1.friction_force - back.friction_force) / h == pytest.approx(KF, rel=1e-5)


def test_config_and_set_paths():
    from drymount.config.loading import load_preset
    from drymount.config.schema import ConfigError
    from drymount.paths import override_config

    cfg = override_config(load_preset("sdof_halved"), [
        'mount.friction.kind="lugre"', "mount.friction.sigma1=120",
        "mount.friction.stribeck_ratio=1.5", "mount.friction.v_stribeck=0.02"])
    p = cfg.system.elements[0].params.axial
    assert (p.friction_kind, p.sigma1, p.stribeck_ratio, p.v_stribeck) == (
        "lugre", 120.0, 1.5, 0.02)
    with pytest.raises(ConfigError, match="`mount.friction.v_stribeck` must be "
                                          "finite and > 0, got -1.0"):
        override_config(cfg, ["mount.friction.v_stribeck=-1"])
    cfg = override_config(load_preset("sdof_halved"), ['mount.friction.kind="berg"'])
    assert cfg.system.elements[0].params.axial.friction_kind == "berg"
    with pytest.raises(ConfigError, match="`mount.friction.sigma1`"):
        override_config(cfg, ["mount.friction.sigma1=4"])   # a LuGre field


def test_fmu_variables_have_units_and_descriptions():
    from drymount.fmu_src import interface

    for name, unit in (("sigma1", "N.s/m"), ("sigma2", "N.s/m"),
                       ("stribeck_ratio", "1"), ("v_stribeck", "m/s")):
        for axis in ("axial", "radial1", "radial2"):
            var = interface.variable(f"{axis}_{name}")
            assert var.unit == unit
            assert var.description.startswith(f"{axis}: LuGre element: ")


# ---------------------------------------------------------------- the FMUs

#: communication step of the FMU runs, s
H = 1e-4


def _instance(rng):
    """Three axes: LuGre (Stribeck, damped), Berg, LuGre on a cubic law."""
    from native_helpers import random_axis

    return (replace(random_axis(rng, "piecewise", True), friction_kind="lugre",
                    sigma1=150.0, sigma2=10.0, stribeck_ratio=1.6, v_stribeck=0.05),
            replace(random_axis(rng, "linear", True), friction_kind="berg"),
            replace(random_axis(rng, "cubic", True), friction_kind="lugre",
                    sigma1=0.0, sigma2=0.0, stribeck_ratio=0.7, v_stribeck=0.2))


def _reference(axes, traj):
    """Outputs F, Ffr, kt, E_fr per step and axis of the in-process law under the FMU
    protocol (the increment to row k spans H, 0 at row 0)."""
    steps = traj.u.shape[0]
    out = np.zeros((steps, 4, 3))
    for j, p in enumerate(axes):
        w, e = initial_sliders(p), 0.0
        for k in range(steps):
            r = axis_force(float(traj.u[k, j]), float(traj.v[k, j]), w, p,
                           float(traj.n[k, j]), H if k else 0.0)
            out[k, :, j] = (r.force, r.friction_force, r.tangent, e + r.dissipated)
            w, e = r.w_new, e + r.dissipated
    return out


class _Fmu:
    """One instance of an FMU through fmpy (FMI 2.0 or 3.0)."""

    def __init__(self, path):
        from fmpy import extract, read_model_description

        md = read_model_description(str(path))
        self.fmi = 2 if md.fmiVersion.startswith("2") else 3
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        kw = dict(unzipDirectory=extract(str(path)), instanceName="dyn",
                  modelIdentifier=md.coSimulation.modelIdentifier)
        if self.fmi == 2:
            from fmpy.fmi2 import FMU2Slave
            self.fmu = FMU2Slave(guid=md.guid, **kw)
        else:
            from fmpy.fmi3 import FMU3Slave
            self.fmu = FMU3Slave(guid=md.guid, **kw)
        self.fmu.instantiate()
        f = self.fmu
        self.set_real = f.setReal if self.fmi == 2 else f.setFloat64
        self.get_real = f.getReal if self.fmi == 2 else f.getFloat64
        self.set_int = f.setInteger if self.fmi == 2 else f.setInt32

    def start(self, axes):
        from drymount.vehicle.backends import fmu_parameter_values

        values = fmu_parameter_values(MountParameters(*axes))
        f = self.fmu
        for typ, setter in (("Real", self.set_real), ("Integer", self.set_int),
                            ("Boolean", f.setBoolean)):
            setter([self.vr[n] for n in values[typ]], list(values[typ].values()))
        if self.fmi == 2:
            f.setupExperiment(startTime=0.0)
            f.enterInitializationMode()
        else:
            f.enterInitializationMode(startTime=0.0)
        f.exitInitializationMode()

    def run(self, traj, k0, k1, out):
        names = [f"{q}_{a}" for a in ("axial", "radial1", "radial2")
                 for q in ("u", "v", "n")]
        outs = [f"{q}_{a}" for q in ("F", "Ffr", "kt", "E_fr")
                for a in ("axial", "radial1", "radial2")]
        vin, vout = [self.vr[n] for n in names], [self.vr[n] for n in outs]
        x = np.stack([traj.u, traj.v, traj.n], axis=2).reshape(traj.u.shape[0], 9)
        for k in range(k0, k1):
            self.set_real(vin, x[k].tolist())
            out[k] = np.array(self.get_real(vout)).reshape(4, 3)
            self.fmu.doStep(k * H, H)

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


@pytest.fixture(scope="module")
def native_fmus(tmp_path_factory):
    from native_helpers import build
    folder = tmp_path_factory.mktemp("dynamic_native")
    return {fmi: build(folder, fmi) for fmi in (2, 3)}


def _worst(got, ref):
    scale = np.maximum(np.abs(ref).max(axis=(0, 2)), 1.0)   # per output
    return float(np.max(np.abs(got - ref).max(axis=(0, 2)) / scale))


@pytest.mark.parametrize("fmi", [2, 3])
def test_native_equals_python_on_random_trajectories_and_restores(fmi, native_fmus):
    """3000 steps of random_trajectory (reversals inside steps, normal force varying
    and lost about 10 % of the time) on LuGre and Berg axes: every output of the C
    FMU equals the in-process law (1e-12 of each output's scale; measured 0); the
    state serialized at step 1500 and restored in a fresh instance replays the
    second half identically (the bristle, Berg's reference and the step size)."""
    pytest.importorskip("fmpy")
    from native_helpers import random_trajectory

    rng = np.random.default_rng(28)
    axes = _instance(rng)
    traj = random_trajectory(rng, 3000, h=H, amplitude=0.004, n0=300.0)
    ref = _reference(axes, traj)
    a, b = _Fmu(native_fmus[fmi]), _Fmu(native_fmus[fmi])
    got, again = np.zeros_like(ref), np.zeros_like(ref)
    try:
        a.start(axes)
        a.run(traj, 0, 1500, got)
        get_state = a.fmu.getFMUstate if fmi == 2 else a.fmu.getFMUState
        ser = a.fmu.serializeFMUstate if fmi == 2 else a.fmu.serializeFMUState
        blob = ser(get_state())
        assert bytes(blob[:8]) == b"DMNTST07"
        a.run(traj, 1500, 3000, got)
        b.start(axes)
        de = b.fmu.deSerializeFMUstate if fmi == 2 else b.fmu.deserializeFMUState
        set_state = b.fmu.setFMUstate if fmi == 2 else b.fmu.setFMUState
        set_state(de(blob))
        b.run(traj, 1500, 3000, again)
    finally:
        a.close()
        b.close()
    assert _worst(got, ref) <= RTOL_FMU
    assert np.array_equal(again[1500:], got[1500:])
    assert ref[-1, 3].min() > 0.0   # every axis dissipated


def test_pythonfmu_equals_the_law(tmp_path):
    """The PythonFMU build on the same kind of trajectory (800 steps)."""
    pytest.importorskip("fmpy")
    from native_helpers import random_trajectory

    from drymount.fmu_build import build_fmu

    rng = np.random.default_rng(29)
    axes = _instance(rng)
    traj = random_trajectory(rng, 800, h=H, amplitude=0.004, n0=300.0)
    ref = _reference(axes, traj)
    f = _Fmu(build_fmu(tmp_path / "FrictionMount.fmu"))
    got = np.zeros_like(ref)
    try:
        f.start(axes)
        f.run(traj, 0, 800, got)
    finally:
        f.close()
    assert _worst(got, ref) <= RTOL_FMU


# ---------------------------------------------------------------- the harness, HBM

def _system(kind):
    return sdof(MASS, MountParameters.from_axial(AXES[kind]), "unbalance", F0)


@pytest.fixture(scope="module")
def references():
    return {kind: sdof_reference(kind) for kind in AXES}


@pytest.mark.parametrize("kind", list(AXES))
def test_harness_both_backends_and_batched(kind, references, native_fmus):
    from drymount.vehicle.batch import steady_states
    from drymount.vehicle.master import Master
    from drymount.vehicle.steady import run_steady, steady_state

    ref = references[kind]
    s = _system(kind)
    a = steady_state(s, FREQ, backend="inproc", steps_per_period=1024)
    assert abs(a.amplitude[0] - ref) <= RTOL_SDOF * ref
    b = steady_states(s, [FREQ], steps_per_period=1024)[0]
    assert b.amplitude[0] == pytest.approx(a.amplitude[0], rel=1e-12)
    with Master(s, "fmu", fmu_path=native_fmus[2]) as m:
        c = run_steady(m, FREQ, start="linear", steps_per_period=1024)
    assert c.amplitude[0] == pytest.approx(a.amplitude[0], rel=1e-12)


@pytest.mark.parametrize("kind", list(AXES))
def test_hbm_generic_march_against_the_reference(kind, references):
    from drymount import hbm

    ref = references[kind]
    r = hbm.solve_frequencies(_system(kind), [FREQ], harmonics=9, n_samples=512)
    assert r.success
    assert abs(r.amplitude[0, 0] - ref) <= RTOL_SDOF * ref


@pytest.mark.parametrize("kind", list(AXES))
def test_static_working_point_carries_no_friction_force(kind):
    from drymount.hbm.static import static_equilibrium

    point = static_equilibrium(_system(kind), np.array([-MASS * 9.81]))
    assert point.q[0] == pytest.approx(-MASS * 9.81 / BASE.k1, rel=1e-12)


def _loop_reference(kind, X, omega, n=1024, periods=25):
    """K* of the friction force's fundamental under u = X sin(omega t) from the RK4
    reference (the last of 25 periods: Berg's loop settles by a factor ~0.15 per
    period at this amplitude), plus k1 and i omega c."""
    th = 2 * np.pi * np.arange(periods * n + 1) / n
    if kind == "lugre":   # RK4 in time with the exact rate X omega cos(omega t)
        F = _lugre_loop(X, omega, th, sub=10)[-n:]
    else:                 # rate independent: RK4 in u
        F = reference_path(kind, X * np.sin(th), 2 * np.pi / (omega * n),
                           sub=10)[-n:]
    th = th[-n:]
    fund = complex(2 / n * F @ np.sin(th), 2 / n * F @ np.cos(th)) / X
    return fund + BASE.k1 + 1j * omega * BASE.c


def _lugre_loop(X, omega, th, sub):
    """LuGre's force at the phases ``th`` under u = X sin(th), th = omega t."""
    p, fc = AXES["lugre"], MU * N0
    h = (th[1] - th[0]) / (sub * omega)

    def zdot(t, z):
        return lugre_rhs(p, z, X * omega * math.cos(omega * t), fc)[0]

    z, t, out = 0.0, 0.0, [0.0]
    for _ in th[1:]:
        for _ in range(sub):
            k1 = zdot(t, z)
            k2 = zdot(t + h / 2, z + h / 2 * k1)
            k3 = zdot(t + h / 2, z + h / 2 * k2)
            k4 = zdot(t + h, z + h * k3)
            z += h * (k1 + 2 * k2 + 2 * k3 + k4) / 6
            t += h
        out.append(lugre_rhs(p, z, X * omega * math.cos(omega * t), fc)[1])
    return np.array(out)


@pytest.mark.parametrize("kind", list(AXES))
def test_characterise_against_the_loop(kind):
    """dynamic_stiffness (the AFT's generic march at each frequency) against the RK4
    loop; LuGre's loop changes with the frequency, Berg's does not."""
    from drymount.hbm.characterise import dynamic_stiffness

    X, freqs = 5e-4, [2.0, 12.0]
    got = dynamic_stiffness(AXES[kind], freqs, [X], n_samples=1024).K[0, 0]
    for k, f in enumerate(freqs):
        ref = _loop_reference(kind, X, 2 * np.pi * f)
        assert abs(got[k] - ref) <= RTOL_K * abs(ref)
    friction = got - BASE.k1 - 1j * 2 * np.pi * np.array(freqs) * BASE.c
    moved = abs(friction[1] - friction[0]) / abs(friction[0])
    assert moved > 0.01 if kind == "lugre" else moved < 1e-9


def test_characterise_cross_check_settles_the_element():
    """drymount characterise's time-domain check of a LuGre axis at 0.1 mm, 30 Hz
    (the bristle settles slowly below its relaxation length g / kf; four periods
    left 2.6e-5): marched as long as the maps' march, at their sampling, the two
    agree to round-off (measured 5e-15)."""
    from drymount.characterise import CROSSCHECK_RTOL, AxisMap, cross_check
    from drymount.hbm.characterise import dynamic_stiffness

    p = replace(AXES["lugre"], law="piecewise", k1=91870.0, k2=513800.0,
                delta=0.01225, delta_neg=0.01225)
    m = dynamic_stiffness(p, [5.0, 30.0], [1e-4, 2e-3])
    checks = cross_check([AxisMap("mount", "axial", p, m)], "law")
    assert len(checks) == 2
    assert max(c.rel_error for c in checks) <= 1e-3 * CROSSCHECK_RTOL
