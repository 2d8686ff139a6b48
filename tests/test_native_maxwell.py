"""The C port of the Maxwell branches (fmu_src/native/maxwell.c through mount_law.c's
generic axis force) against fmu_src/mount_law.py, called through ctypes on random
trajectories: every output and the whole axis state (the element's, uc and the
strokes) step by step, with and without a friction element of each kind the branches
sit beside. Runtime about 2 s.
"""

from __future__ import annotations

import ctypes
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from native_helpers import need_gcc, random_axis, run
from test_native_law import Params, Result

from drymount.fmu_build.native import CFLAGS, debug_cflags, write_law_sources
from drymount.fmu_src.mount_law import (LAWS, AxisParameters, axis_force,
                                        initial_sliders, slider_position)

#: Agreement required between C and Python relative to each output's scale
#: (measured: 0, bit-identical).
TOL_REL = 1e-12
AXES_N = 48
STEPS = 300


@pytest.fixture(scope="module")
def law(tmp_path_factory):
    need_gcc()
    folder = tmp_path_factory.mktemp("maxwell_law")
    lib = folder / "libmountlaw.so"
    proc = run(["gcc", *CFLAGS, *debug_cflags(), "-fPIC", "-fvisibility=default",
                "-o", lib,
                *write_law_sources(folder), "-lm"])
    assert proc.returncode == 0, proc.stderr
    dll = ctypes.CDLL(str(lib))
    dll.ml_axis_force_dt.restype = ctypes.c_int
    dll.ml_axis_force_dt.argtypes = [
        ctypes.c_double, ctypes.c_double, ctypes.c_double,
        ctypes.POINTER(ctypes.c_double), ctypes.POINTER(Params), ctypes.c_double,
        ctypes.POINTER(ctypes.c_double), ctypes.POINTER(Result), ctypes.c_char_p,
        ctypes.c_size_t]
    dll.ml_state_size.restype = ctypes.c_int
    dll.ml_state_size.argtypes = [ctypes.POINTER(Params)]
    dll.ml_state_start.argtypes = [ctypes.POINTER(Params), ctypes.c_double,
                                   ctypes.POINTER(ctypes.c_double)]
    dll.ml_state_position_p.restype = ctypes.c_double
    dll.ml_state_position_p.argtypes = [ctypes.POINTER(Params),
                                        ctypes.POINTER(ctypes.c_double), ctypes.c_int,
                                        ctypes.c_int]
    dll.ml_state_tag.restype = ctypes.c_int
    dll.ml_state_tag.argtypes = [ctypes.POINTER(Params)]
    dll.ml_axis_problems.restype = ctypes.c_int
    dll.ml_axis_problems.argtypes = [ctypes.POINTER(Params), ctypes.c_char_p,
                                     ctypes.c_char_p, ctypes.c_size_t]
    return dll


def _c_params(p: AxisParameters) -> Params:
    names = [n for n, _ in Params._fields_]
    kw = {n: getattr(p, n) for n in names if n not in ("law", "friction",
                                                       "friction_kind")}
    return Params(law=LAWS.index(p.law), friction=int(p.friction),
                  friction_kind=["jenkins", "inclined", "dahl", "lugre", "berg"].index(
                      p.friction_kind), **kw)


def _axis(rng, i: int) -> AxisParameters:
    law = LAWS[i % len(LAWS)]
    kinds = (None, "jenkins", "dahl", "lugre")
    kind = kinds[i % len(kinds)]
    p = random_axis(rng, law, kind is not None)
    kw = dict(mu=1.0)
    if kind is not None:
        kw["friction_kind"] = kind
    if kind == "lugre":
        kw.update(sigma1=float(rng.uniform(0, 200)), sigma2=float(rng.uniform(0, 50)),
                  stribeck_ratio=float(rng.uniform(1.0, 2.0)), v_stribeck=0.02)
    # one to three branches, some slots absent (k or c zero)
    for j in range(1, 4):
        on = rng.random() < 0.7 or j == 1
        kw[f"maxwell_k{j}"] = float(rng.uniform(1e4, 2e5)) if on else 0.0
        kw[f"maxwell_c{j}"] = float(rng.choice([0.0, rng.uniform(1.0, 2e3)])) \
            if j > 1 else float(rng.uniform(1.0, 2e3))
    return replace(p, **kw)


def test_maxwell_axis_equals_python_law(law):
    rng = np.random.default_rng(2028)
    worst = dict.fromkeys(("force", "friction", "tangent", "dissipated", "state"), 0.0)
    scale = dict.fromkeys(worst, 1e-300)
    for i in range(AXES_N):
        p = _axis(rng, i)
        assert p.has_maxwell
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
        dt = np.where(rng.random(STEPS) < 0.05, 0.0,
                      rng.uniform(1e-5, 5e-3, STEPS)).tolist()
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
            worst["state"] = max(worst["state"], float(np.max(np.abs(got - w_py))))
            scale["state"] = max(scale["state"], float(np.max(np.abs(w_py))))
            assert r.w_new == slider_position(p, w_py)
            tag = law.ml_state_tag(ctypes.byref(cp))
            assert law.ml_state_position_p(ctypes.byref(cp), w_new, n, tag) \
                == slider_position(p, w_py)
            ctypes.memmove(w_c, w_new, 8 * n)
    for name, err in worst.items():
        assert err <= TOL_REL * scale[name], (name, err, scale[name])


def test_maxwell_problems_match_python(law):
    values = AxisParameters(law="linear", k1=1e5).to_dict()
    values.update(maxwell_k2=-1.0, maxwell_c3=float("inf"))
    bad = SimpleNamespace(**values)
    cp = _c_params(bad)
    buf = ctypes.create_string_buffer(4096)
    count = law.ml_axis_problems(ctypes.byref(cp), b"axial_", buf, 4096)
    expected = AxisParameters.problems(bad, "axial_")
    assert count == len(expected) == 2
    assert buf.value.decode() == "; ".join(expected)
