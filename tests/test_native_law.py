"""The C port of the mount law (fmu_src/native/mount_law.c) against
fmu_src/mount_law.py, called directly through ctypes: every elastic law, the Jenkins
return map, micro-slip (Iwan) and non-symmetric friction, the mean slider position,
the dissipated energy, the parameter checks and their messages.

Runtime about 7 s (4 x 1e5 random evaluations and 1e5 micro-slip / non-symmetric steps
through ctypes and in Python).
"""

from __future__ import annotations

import ctypes
import math
import struct
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from native_helpers import need_gcc, random_axis, run

from drymount.fmu_build.native import CFLAGS, debug_cflags, write_law_sources
from drymount.fmu_src import mount_law
from drymount.fmu_src.mount_law import (LAWS, AxisParameters, axis_force,
                                        initial_sliders, mean_slider)

#: Agreement required between C and Python, relative to the force (or stiffness)
#: scale of the samples. Measured: 0 (bit-identical) for every law.
TOL_REL = 1e-12
SAMPLES_PER_LAW = 100_000


class Result(ctypes.Structure):
    _fields_ = [("force", ctypes.c_double), ("friction", ctypes.c_double),
                ("w_new", ctypes.c_double), ("tangent", ctypes.c_double),
                ("slipping", ctypes.c_int), ("dissipated", ctypes.c_double)]


class Params(ctypes.Structure):
    _fields_ = [("law", ctypes.c_int), ("k1", ctypes.c_double), ("kc", ctypes.c_double),
                ("k2", ctypes.c_double), ("delta", ctypes.c_double),
                ("delta_neg", ctypes.c_double), ("c", ctypes.c_double),
                ("friction", ctypes.c_int), ("kf", ctypes.c_double),
                ("mu", ctypes.c_double), ("n0", ctypes.c_double),
                ("sliders", ctypes.c_int), ("spread", ctypes.c_double),
                ("fs_ratio", ctypes.c_double), ("friction_kind", ctypes.c_int)] + [
        (name, ctypes.c_double)
        for name in ("theta_deg", "k", "kf2", "mu1", "mu2", "preload", "sigma1",
                     "sigma2", "stribeck_ratio", "v_stribeck", "maxwell_k1",
                     "maxwell_c1", "maxwell_k2", "maxwell_c2", "maxwell_k3",
                     "maxwell_c3", "hyd_Ap", "hyd_C1", "hyd_C2", "hyd_I_i", "hyd_R_i",
                     "hyd_I_d", "hyd_R_d")]


@pytest.fixture(scope="module")
def law(tmp_path_factory):
    """The C law (mount_law.c with one file per friction element, the messages and
    the generated element table) compiled with the FMU's flags into a shared
    library."""
    need_gcc()
    folder = tmp_path_factory.mktemp("law")
    lib = folder / "libmountlaw.so"
    proc = run(["gcc", *CFLAGS, *debug_cflags(), "-fPIC", "-fvisibility=default",
                "-o", lib,
                *write_law_sources(folder), "-lm"])
    assert proc.returncode == 0, proc.stderr
    dll = ctypes.CDLL(str(lib))
    dll.ml_axis_force.restype = Result
    dll.ml_axis_force.argtypes = [ctypes.c_double] * 3 + [ctypes.c_int] + \
        [ctypes.c_double] * 8
    dll.ml_axis_problems.restype = ctypes.c_int
    dll.ml_axis_problems.argtypes = [ctypes.POINTER(Params), ctypes.c_char_p,
                                     ctypes.c_char_p, ctypes.c_size_t]
    dll.ml_repr_double.argtypes = [ctypes.c_double, ctypes.c_char_p, ctypes.c_size_t]
    return dll


#: The law the C port implements, in FMU code order (fmu_build/native.py checks the
#: registry against it at build time).
C_LAWS = ("linear", "cubic", "piecewise", "piecewise_asym")


def _unit_mu(p):
    """``p`` with mu = 1: its normal-force input n is then the slip force Fs = n
    exactly, which the C calls of this file take."""
    return replace(p, mu=1.0) if p.friction else p


def test_registry_is_the_ported_laws():
    assert LAWS == C_LAWS


@pytest.mark.parametrize("law_name", C_LAWS)
def test_axis_force_equals_python_law(law, law_name):
    """1e5 random evaluations per law: 200 random axes (friction on for 80 %) x 500
    random (u, v, w, fs), stuck and slipping both ways."""
    rng = np.random.default_rng(12 + C_LAWS.index(law_name))
    code = C_LAWS.index(law_name)
    worst = dict.fromkeys(("force", "friction", "w_new", "tangent", "dissipated"), 0.0)
    scale = {"force": 1.0, "friction": 1.0, "w_new": 1e-9, "tangent": 1.0,
             "dissipated": 1e-12}
    slips = 0
    call = law.ml_axis_force
    per_axis = SAMPLES_PER_LAW // 200
    for _ in range(200):
        p = random_axis(rng, law_name, bool(rng.random() < 0.8))
        kf = p.kf if p.friction else 0.0
        u = (rng.uniform(-3, 3, per_axis) * p.delta).tolist()
        w = (np.asarray(u) + rng.normal(0.0, 0.01, per_axis)).tolist()
        v = rng.normal(0.0, 0.5, per_axis).tolist()
        fs = np.where(rng.random(per_axis) < 0.1, 0.0,
                      rng.uniform(0.0, 800.0, per_axis)).tolist()
        p1 = _unit_mu(p)
        for ui, vi, wi, si in zip(u, v, w, fs, strict=True):
            r = call(ui, vi, wi, code, p.k1, p.kc, p.k2, p.delta, p.delta_neg, p.c,
                     kf, si)
            ref = axis_force(ui, vi, wi, p1, si)
            assert bool(r.slipping) == ref.slipping
            slips += ref.slipping
            for name, value in (("force", ref.force), ("friction", ref.friction_force),
                                ("w_new", ref.w_new), ("tangent", ref.tangent),
                                ("dissipated", ref.dissipated)):
                worst[name] = max(worst[name], abs(getattr(r, name) - value))
                scale[name] = max(scale[name], abs(value))
    assert 0.05 * SAMPLES_PER_LAW < slips < 0.95 * SAMPLES_PER_LAW
    for name, err in worst.items():
        assert err <= TOL_REL * scale[name], (name, err, scale[name])


def _problems_c(law, p: Params, prefix: str) -> list[str]:
    buf = ctypes.create_string_buffer(4096)
    count = law.ml_axis_problems(ctypes.byref(p), prefix.encode(), buf, len(buf))
    text = buf.value.decode()
    return text.split("; ") if count else []


BAD = [
    {"k1": -1.0},
    {"delta": 0.0, "delta_neg": -0.0},
    {"c": math.nan, "mu": math.inf, "n0": -math.inf},
    {"kc": -1e-05, "k2": -1.5e16},
    {"kf": 0.0, "friction": True},
    {"kf": -3.0},
    {"kf": math.nan, "friction": False},
    {"law": 7},
    {"law": -1, "k1": -0.1, "kf": -2.0, "friction": True},
    {"sliders": 0, "spread": 1.0, "fs_ratio": -0.5},
    {"sliders": 65, "spread": math.nan},
]


#: The friction elements of the law (``mount_law.FRICTION_KINDS`` where the law has
#: the inclined element as a friction kind of an axis; the C port has both).
KINDS = getattr(mount_law, "FRICTION_KINDS", ("jenkins",))
if "inclined" in KINDS:
    BAD += [
        {"friction_kind": len(KINDS)},  # one past the last registered element
        {"friction_kind": -1, "law": 5},
        {"friction": True, "friction_kind": "inclined", "theta_deg": 95.0,
         "kf2": 0.0},
        {"friction": True, "friction_kind": "inclined", "theta_deg": 10.0,
         "mu1": 0.5},
        {"friction": True, "friction_kind": "inclined", "sliders": 3,
         "fs_ratio": 0.5, "kf": 0.0},
        # without friction the inclined element's fields are not checked
        {"friction": False, "friction_kind": "inclined", "theta_deg": 95.0,
         "k1": -1.0},
    ]


def _code(values: dict, name: str, table: tuple[str, ...]) -> int:
    value = values.get(name, table[0])
    return value if isinstance(value, int) else table.index(value)


def _params(values: dict) -> Params:
    """The C parameters of raw FMU-like values (codes for law and friction_kind)."""
    out = Params()
    for name, ctype in Params._fields_:
        if name == "law":
            out.law = _code(values, "law", LAWS)
        elif name == "friction_kind":
            out.friction_kind = _code(values, "friction_kind", KINDS)
        elif name in values:
            setattr(out, name, int(values[name]) if ctype is ctypes.c_int
                    else float(values[name]))
    return out


def _fmu_code_check(values: dict, name: str, table) -> list[str]:
    """The FMU's own check of an integer code (fmu_src/friction_mount.py, _prepare);
    replaces an invalid code by the first entry as it does."""
    code = values.get(name)
    if not isinstance(code, int):
        return []
    if 0 <= code < len(table):
        values[name] = table[code]
        return []
    allowed = ", ".join(f"{i} = {entry}" for i, entry in enumerate(table))
    values[name] = table[0]
    return [f"`radial1_{name}` must be one of {allowed}, got {code!r}"]


@pytest.mark.parametrize("bad", BAD)
def test_parameter_messages_equal_python(law, bad):
    values = {**AxisParameters().to_dict(), **bad}
    p = _params(values)
    expected = _fmu_code_check(values, "law", LAWS)
    if "friction_kind" in values:
        expected += _fmu_code_check(values, "friction_kind", KINDS)
    expected += AxisParameters.problems(SimpleNamespace(**values), "radial1_")
    assert expected, "every case has a problem"
    # compared as text ("; " also occurs inside one message) and count
    assert _problems_text_c(law, p, "radial1_") == ("; ".join(expected), len(expected))


def _problems_text_c(law, p: Params, prefix: str) -> tuple[str, int]:
    buf = ctypes.create_string_buffer(4096)
    count = law.ml_axis_problems(ctypes.byref(p), prefix.encode(), buf, len(buf))
    return buf.value.decode(), count


def test_valid_parameters_have_no_problem(law):
    for name in LAWS:
        p = Params(law=LAWS.index(name), k1=1.0, kc=0.0, k2=0.0, delta=1e-3,
                   delta_neg=1e-3, c=0.0, friction=1, kf=1.0, mu=0.0, n0=0.0,
                   sliders=1, spread=0.0, fs_ratio=1.0)
        assert _problems_c(law, p, "axial_") == []


def test_float_text_equals_python_repr(law):
    """The messages print values as Python's repr does (shortest round trip)."""
    rng = np.random.default_rng(5)
    values = [0.0, -0.0, 1.0, -1.5, 0.1, 1e-05, 0.0001, 1e16, 1e15, 123456789.0,
              1.5e-300, 5e-324, 1.7976931348623157e308, 0.30000000000000004,
              91870.0, 0.01225, 2.5e-05, 1e22, 9007199254740993.0]
    values += (rng.standard_normal(4000) * 10.0 ** rng.integers(-30, 30, 4000)).tolist()
    values += [struct.unpack("d", rng.bytes(8))[0] for _ in range(4000)]
    buf = ctypes.create_string_buffer(64)
    for x in values:
        law.ml_repr_double(x, buf, len(buf))
        assert buf.value.decode() == repr(x)


# ---------------------------------------------------------------------- micro-slip

#: Measured: 0 (bit-identical) for every output and slider; the mean slider position
#: (math.fsum port) is compared for equality.
MICRO_STEPS = 500
MICRO_AXES = 200


def _general_law(law):
    """ctypes signatures of the general-friction entry points of mount_law.c."""
    law.ml_axis_force_w.restype = ctypes.c_int
    law.ml_axis_force_w.argtypes = [
        ctypes.c_double, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
        ctypes.POINTER(Params), ctypes.c_double, ctypes.POINTER(ctypes.c_double),
        ctypes.POINTER(Result), ctypes.c_char_p, ctypes.c_size_t]
    law.ml_mean_slider.restype = ctypes.c_double
    law.ml_mean_slider.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.c_int]
    law.ml_state_size.restype = ctypes.c_int
    law.ml_state_size.argtypes = [ctypes.POINTER(Params)]
    return law


def _c_params(p: AxisParameters) -> Params:
    return Params(law=LAWS.index(p.law), k1=p.k1, kc=p.kc, k2=p.k2, delta=p.delta,
                  delta_neg=p.delta_neg, c=p.c, friction=int(p.friction), kf=p.kf,
                  mu=p.mu, n0=p.n0, sliders=p.sliders, spread=p.spread,
                  fs_ratio=p.fs_ratio)


def _general_axis(rng, i: int) -> AxisParameters:
    """Axis ``i`` of the sweep: micro-slip (2 to 64 sliders, spread 0 to 0.95, with
    and without fs_ratio), non-symmetric macro-slip, and a few without friction."""
    law_name = C_LAWS[i % len(C_LAWS)]
    kind = i % 5
    sliders = 1 if kind == 3 else int(rng.choice([2, 3, 8, 17, 64]))
    spread = float(rng.choice([0.0, rng.uniform(0.0, 0.95)]))
    fs_ratio = 1.0 if kind == 0 else float(rng.choice(
        [0.0, rng.uniform(0.1, 0.9), rng.uniform(1.1, 3.0)]))
    return replace(random_axis(rng, law_name, kind != 4), sliders=sliders,
                   spread=spread, fs_ratio=fs_ratio)


def test_micro_slip_and_fs_ratio_equal_python_law(law):
    """1e5 steps: 200 axes (micro-slip, non-symmetric, both, friction off) x 500
    steps of a random walk with reversals and a varying slip force (10 % zero:
    contact lost), the slider state carried from step to step as in the FMU."""
    law = _general_law(law)
    rng = np.random.default_rng(314)
    worst = dict.fromkeys(("force", "friction", "tangent", "dissipated"), 0.0)
    scale = dict.fromkeys(worst, 1.0)
    slips = sliders_off = 0
    for i in range(MICRO_AXES):
        p = _general_axis(rng, i)
        cp = _c_params(p)
        n = law.ml_state_size(ctypes.byref(cp))
        assert n == (p.sliders if p.micro_slip else 1)
        eps = p.fs / p.kf if p.friction and p.fs > 0 else 1e-3
        # steps of up to 1.5 eps with random signs: partial and full slip, reversals
        u = np.cumsum(rng.normal(0.0, 0.6 * eps, MICRO_STEPS)).tolist()
        v = rng.normal(0.0, 0.5, MICRO_STEPS).tolist()
        fs = np.where(rng.random(MICRO_STEPS) < 0.1, 0.0,
                      p.fs * rng.uniform(0.5, 1.5, MICRO_STEPS)).tolist()
        w_py = initial_sliders(p)
        p1 = _unit_mu(p)
        w_c = (ctypes.c_double * 64)()
        w_new = (ctypes.c_double * 64)()
        r = Result()
        for ui, vi, si in zip(u, v, fs, strict=True):
            assert law.ml_axis_force_w(ui, vi, w_c, ctypes.byref(cp), si, w_new,
                                       ctypes.byref(r), None, 0) == 0
            ref = axis_force(ui, vi, w_py, p1, si)
            assert bool(r.slipping) == ref.slipping
            slips += ref.slipping
            for name, value in (("force", ref.force), ("friction", ref.friction_force),
                                ("tangent", ref.tangent),
                                ("dissipated", ref.dissipated)):
                worst[name] = max(worst[name], abs(getattr(r, name) - value))
                scale[name] = max(scale[name], abs(value))
            w_py = ref.w_new
            got = list(w_new[:n])
            assert got == (list(w_py) if isinstance(w_py, tuple) else [w_py])
            ctypes.memmove(w_c, w_new, 8 * n)
            assert law.ml_mean_slider(w_c, n) == mean_slider(w_py)
            sliders_off += isinstance(w_py, tuple) and len(set(w_py)) > 1
    assert 0.05 * MICRO_AXES * MICRO_STEPS < slips < 0.95 * MICRO_AXES * MICRO_STEPS
    assert sliders_off > 0.1 * MICRO_AXES * MICRO_STEPS  # sliders apart (measured 21 %)
    for name, err in worst.items():
        assert err <= TOL_REL * scale[name], (name, err, scale[name])


def test_mean_slider_is_python_fsum(law):
    """ml_mean_slider == mount_law.mean_slider (math.fsum / n) exactly, on sums with
    cancellation and ties of the half-even rounding."""
    law = _general_law(law)
    rng = np.random.default_rng(9)
    cases = [[1e-16, 1.0, 1e16], [1.0, 1e100, 1.0, -1e100], [0.1] * 10 + [0.2],
             [1e308, -1e308, 1e-300], [2.0 ** -1074, 1.0, -1.0],
             [1.0, 2.0 ** -53, 2.0 ** -106, 3.0]]
    for _ in range(3000):
        n = int(rng.integers(2, 65))
        mag = 10.0 ** rng.integers(-20, 20, n)
        cases.append((rng.standard_normal(n) * mag).tolist())
    buf = (ctypes.c_double * 64)()
    for w in cases:
        for i, x in enumerate(w):
            buf[i] = x
        assert law.ml_mean_slider(buf, len(w)) == mean_slider(tuple(w)), w
