"""The C port of the hydraulic fluid path (fmu_src/native/hydraulic.c through
mount_law.c's generic axis force) against fmu_src/mount_law.py and
fmu_src/linear_branches.py, called through ctypes: the propagator of random step
sizes entry by entry, then random trajectories with varying step sizes (and jumps,
dt = 0) with and without a decoupler, Maxwell branches and friction elements: every
output and the whole axis state (the element's, uc, the strokes, the four fluid
states) step by step; the field checks' messages. Runtime about 3 s."""

from __future__ import annotations

import ctypes
import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from native_helpers import random_axis
from test_native_law import Params, Result
from test_native_maxwell import _c_params

from drymount.fmu_src.linear_branches import fluid_propagator
from drymount.fmu_src.mount_law import (LAWS, AxisParameters, axis_force,
                                        initial_sliders, slider_position)

#: Agreement required between C and Python relative to each output's scale
#: (measured: 0, bit-identical).
TOL_REL = 1e-12
AXES_N = 32
STEPS = 300


class Prop(ctypes.Structure):
    _fields_ = [("valid", ctypes.c_int), ("dt", ctypes.c_double),
                ("key", ctypes.c_double * 7), ("phi", (ctypes.c_double * 4) * 4),
                ("g0", ctypes.c_double * 4), ("g1", ctypes.c_double * 4)]


@pytest.fixture(scope="module")
def law(tmp_path_factory):
    """The C law compiled with the FMU's flags (as test_native_maxwell's)."""
    from native_helpers import need_gcc, run

    from drymount.fmu_build.native import CFLAGS, debug_cflags, write_law_sources

    need_gcc()
    folder = tmp_path_factory.mktemp("hydraulic_law")
    lib = folder / "libmountlaw.so"
    proc = run(["gcc", *CFLAGS, *debug_cflags(), "-fPIC", "-fvisibility=default",
                "-o", lib,
                *write_law_sources(folder), "-lm"])
    assert proc.returncode == 0, proc.stderr
    dll = ctypes.CDLL(str(lib))
    P, D = ctypes.POINTER(Params), ctypes.POINTER(ctypes.c_double)
    dll.ml_axis_force_dt.argtypes = [
        ctypes.c_double, ctypes.c_double, ctypes.c_double, D, P, ctypes.c_double, D,
        ctypes.POINTER(Result), ctypes.c_char_p, ctypes.c_size_t]
    dll.ml_state_size.argtypes = [P]
    dll.ml_state_start.argtypes = [P, ctypes.c_double, D]
    dll.ml_state_position_p.restype = ctypes.c_double
    dll.ml_state_position_p.argtypes = [P, D, ctypes.c_int, ctypes.c_int]
    dll.ml_state_tag.argtypes = [P]
    dll.ml_axis_problems.argtypes = [P, ctypes.c_char_p, ctypes.c_char_p,
                                     ctypes.c_size_t]
    return dll


def _fluid(rng, decoupler: bool) -> dict:
    kw = dict(hyd_Ap=float(rng.uniform(2e-3, 8e-3)),
              hyd_C1=float(10 ** rng.uniform(-11, -9)),
              hyd_C2=float(10 ** rng.uniform(-10, -8)),
              hyd_I_i=float(10 ** rng.uniform(5, 7)),
              hyd_R_i=float(rng.choice([0.0, 10 ** rng.uniform(6, 9)])))
    if decoupler:
        kw.update(hyd_I_d=float(10 ** rng.uniform(3, 5)),
                  hyd_R_d=float(rng.choice([0.0, 10 ** rng.uniform(5, 7)])))
    return kw


def _axis(rng, i: int) -> AxisParameters:
    law = LAWS[i % len(LAWS)]
    kinds = (None, "jenkins", "dahl", "lugre")
    kind = kinds[i % len(kinds)]
    p = random_axis(rng, law, kind is not None)
    kw = dict(mu=1.0, **_fluid(rng, i % 2 == 1))
    if kind is not None:
        kw["friction_kind"] = kind
    if i % 3 == 0:   # a Maxwell branch beside the fluid
        kw.update(maxwell_k1=float(rng.uniform(1e4, 2e5)),
                  maxwell_c1=float(rng.uniform(1.0, 2e3)))
    return replace(p, **kw)


def test_propagator_equals_python(law):
    law.ml_fluid_propagator.argtypes = [ctypes.POINTER(Params), ctypes.c_double,
                                        ctypes.POINTER(Prop)]
    rng = np.random.default_rng(2838)
    for i in range(40):
        p = _axis(rng, i)
        dt = float(10 ** rng.uniform(-6, -1))
        phi, g0, g1 = fluid_propagator(p.hydraulic, dt)
        out = Prop()
        law.ml_fluid_propagator(ctypes.byref(_c_params(p)), dt, ctypes.byref(out))
        got = [[out.phi[r][c] for c in range(4)] for r in range(4)]
        assert got == phi and list(out.g0) == g0 and list(out.g1) == g1, (i, dt)


def test_fsum_is_pythons(law):
    law.ml_fsum.restype = ctypes.c_double
    law.ml_fsum.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.c_int]
    rng = np.random.default_rng(2839)
    for _ in range(500):
        n = int(rng.integers(1, 9))
        x = (rng.normal(size=n) * 10.0 ** rng.integers(-20, 20, size=n)).tolist()
        x += [-v for v in x[: int(rng.integers(0, n + 1))]]   # cancellations
        arr = (ctypes.c_double * len(x))(*x)
        assert law.ml_fsum(arr, len(x)) == math.fsum(x)
    assert law.ml_fsum((ctypes.c_double * 3)(1.0, 1e100, -1e100), 3) == 1.0


def test_fluid_axis_equals_python_law(law):
    rng = np.random.default_rng(2837)
    worst = dict.fromkeys(("force", "friction", "tangent", "dissipated", "state"), 0.0)
    scale = dict.fromkeys(worst, 1e-300)
    for i in range(AXES_N):
        p = _axis(rng, i)
        assert p.has_hydraulic
        cp = _c_params(p)
        n = law.ml_state_size(ctypes.byref(cp))
        w_py = initial_sliders(p, 0.0)
        assert n == len(w_py)
        w_c = (ctypes.c_double * 80)()
        law.ml_state_start(ctypes.byref(cp), 0.0, w_c)
        assert list(w_c[:n]) == list(w_py)
        w_new = (ctypes.c_double * 80)()
        r = Result()
        u = np.cumsum(rng.normal(0.0, 1e-3, STEPS)).tolist()
        v = rng.normal(0.0, 0.3, STEPS).tolist()
        dt = np.where(rng.random(STEPS) < 0.05, 0.0,   # varying steps and jumps
                      10 ** rng.uniform(-5, -2, STEPS)).tolist()
        fs = (p.n0 * rng.uniform(0.5, 1.5, STEPS)).tolist()
        for ui, vi, di, si in zip(u, v, dt, fs, strict=True):
            assert law.ml_axis_force_dt(ui, vi, di, w_c, ctypes.byref(cp), si, w_new,
                                        ctypes.byref(r), None, 0) == 0
            ref = axis_force(ui, vi, w_py, p, si, di)
            for name, value in (("force", ref.force), ("friction", ref.friction_force),
                                ("tangent", ref.tangent),
                                ("dissipated", ref.dissipated)):
                worst[name] = max(worst[name], abs(getattr(r, name) - value))
                scale[name] = max(scale[name], abs(value))
            w_py = ref.w_new
            got = np.array(w_new[:n])
            # per entry against its own scale: the fluid's x1 (m^3) is small
            err = np.abs(got - w_py) / np.maximum(np.abs(w_py), 1e-300)
            worst["state"] = max(worst["state"], float(np.max(np.where(
                np.array(w_py) == 0.0, np.abs(got), err))))
            scale["state"] = 1.0
            assert r.w_new == slider_position(p, w_py)
            tag = law.ml_state_tag(ctypes.byref(cp))
            assert law.ml_state_position_p(ctypes.byref(cp), w_new, n, tag) \
                == slider_position(p, w_py)
            ctypes.memmove(w_c, w_new, 8 * n)
    for name, err in worst.items():
        assert err <= TOL_REL * scale[name], (name, err, scale[name])


def test_fluid_problems_match_python(law):
    values = AxisParameters(law="linear", k1=1e5).to_dict()
    values.update(hyd_Ap=5e-3, hyd_C1=0.0, hyd_C2=-1.0, hyd_I_i=0.0,
                  hyd_R_d=float("nan"))
    bad = SimpleNamespace(**values)
    buf = ctypes.create_string_buffer(4096)
    count = law.ml_axis_problems(ctypes.byref(_c_params(bad)), b"axial_", buf, 4096)
    expected = AxisParameters.problems(bad, "axial_")
    assert count == len(expected) == 4
    assert buf.value.decode() == "; ".join(expected)
