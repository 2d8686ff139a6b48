"""The C port of the mount law (fmu_src/native/mount_law.c) against fmu_src/mount_law.py,
called directly through ctypes: every elastic law, the Jenkins return map, the
dissipated energy, the parameter checks and their messages.

Runtime about 3 s (4 x 1e5 random evaluations through ctypes and in Python).
"""

from __future__ import annotations

import ctypes
import math
import struct
from types import SimpleNamespace

import numpy as np
import pytest
from native_helpers import need_gcc, run

from fmu_build.native import CFLAGS, SOURCE_DIR
from fmu_src.mount_law import LAWS, AxisParameters, axis_force

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
                ("mu", ctypes.c_double), ("n0", ctypes.c_double)]


@pytest.fixture(scope="module")
def law(tmp_path_factory):
    """mount_law.c compiled with the FMU's flags into a shared library."""
    need_gcc()
    lib = tmp_path_factory.mktemp("law") / "libmountlaw.so"
    proc = run(["gcc", *CFLAGS, "-fPIC", "-fvisibility=default", "-o", lib,
                SOURCE_DIR / "mount_law.c", "-lm"])
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


@pytest.mark.parametrize("law_name", LAWS)
def test_axis_force_equals_python_law(law, law_name):
    rng = np.random.default_rng(12 + LAWS.index(law_name))
    code = LAWS.index(law_name)
    n = SAMPLES_PER_LAW
    delta, delta_neg = rng.uniform(0.005, 0.015, n), rng.uniform(0.003, 0.012, n)
    u = rng.uniform(-3, 3, n) * delta
    w = u + rng.normal(0.0, 0.01, n)     # stuck, slipping both ways
    v = rng.normal(0.0, 0.5, n)
    k1 = rng.uniform(5e4, 2e5, n)
    kc, k2 = rng.uniform(1e8, 1e9, n), k1 * rng.uniform(0.5, 8.0, n)
    c = rng.uniform(0.0, 300.0, n)
    kf = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(2e4, 1e5, n))  # 20 % frictionless
    fs = np.where(rng.random(n) < 0.1, 0.0, rng.uniform(0.0, 800.0, n))
    cols = [x.tolist() for x in (u, v, w, k1, kc, k2, delta, delta_neg, c, kf, fs)]
    worst = {"force": 0.0, "friction": 0.0, "w_new": 0.0, "tangent": 0.0,
             "dissipated": 0.0}
    scale = {"force": 1.0, "friction": 1.0, "w_new": 1e-9, "tangent": 1.0,
             "dissipated": 1e-12}
    slips = 0
    call = law.ml_axis_force
    for ui, vi, wi, a, b, d, e, f, g, h, s in zip(*cols, strict=True):
        r = call(ui, vi, wi, code, a, b, d, e, f, g, h, s)
        ref = axis_force(ui, vi, wi, code, a, b, d, e, f, g, h, s)
        assert bool(r.slipping) == ref[4]
        slips += ref[4]
        for i, name in ((0, "force"), (1, "friction"), (2, "w_new"), (3, "tangent"),
                        (5, "dissipated")):
            got = getattr(r, name)
            worst[name] = max(worst[name], abs(got - ref[i]))
            scale[name] = max(scale[name], abs(ref[i]))
    assert 0.05 * n < slips < 0.95 * n  # both branches of the return map exercised
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
]


@pytest.mark.parametrize("bad", BAD)
def test_parameter_messages_equal_python(law, bad):
    values = {**AxisParameters().to_dict(), **bad}
    code = values["law"]
    p = Params(law=code if isinstance(code, int) else LAWS.index(code),
               **{k: float(v) for k, v in values.items()
                  if k not in ("law", "friction")},
               friction=int(values["friction"]))
    expected = []
    if isinstance(code, int) and not 0 <= code < len(LAWS):
        # the FMU's own law check (fmu_src/friction_mount.py, _prepare)
        allowed = ", ".join(f"{i} = {name}" for i, name in enumerate(LAWS))
        expected.append(f"`radial1_law` must be one of {allowed}, got {code!r}")
        values["law"] = LAWS[0]
    elif isinstance(code, int):
        values["law"] = LAWS[code]
    expected += AxisParameters.problems(SimpleNamespace(**values), "radial1_")
    assert expected, "every case has a problem"
    assert _problems_c(law, p, "radial1_") == expected


def test_valid_parameters_have_no_problem(law):
    for name in LAWS:
        p = Params(law=LAWS.index(name), k1=1.0, kc=0.0, k2=0.0, delta=1e-3,
                   delta_neg=1e-3, c=0.0, friction=1, kf=1.0, mu=0.0, n0=0.0)
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
