"""The C port of the inclined two-surface element (fmu_src/native/inclined.c) against
fmu_src/inclined.py, called directly through ctypes: the exact return map on random
trajectories (regime changes, several events in one increment, reversals, bonded
surfaces, 90 degrees), ContactLost as an error code with the same message, the
parameter checks and their messages.

Runtime about 4 s (2e4 random increments through ctypes and in Python).
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
from native_helpers import need_gcc, run

from drymount.fmu_build.native import CFLAGS, debug_cflags, write_law_sources
from drymount.fmu_src.inclined import (
    ContactLost,
    InclinedParameters,
    inclined_forces,
    inclined_update,
)

#: Agreement required between C and Python, relative to the force scale of the
#: trajectory (sliders times their contact stiffness). Measured: 0 (bit-identical).
TOL_REL = 1e-12
DESIGNS = 100
STEPS = 200
FIELDS = ("force", "f1", "f2", "n1", "n2", "w1", "w2", "tangent", "dissipated")


class Params(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in
                ("theta_deg", "k", "kf", "kf2", "mu1", "mu2", "preload")]


class Step(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in FIELDS[:7]] + [
        ("slip1", ctypes.c_int), ("slip2", ctypes.c_int),
        ("tangent", ctypes.c_double), ("dissipated", ctypes.c_double)]


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    """inclined.c (with the rest of the C law, messages.c for the number format)
    compiled with the FMU's flags into a shared library."""
    need_gcc()
    folder = tmp_path_factory.mktemp("inclined")
    out = folder / "libinclined.so"
    proc = run(["gcc", *CFLAGS, *debug_cflags(), "-fPIC", "-fvisibility=default",
                "-o", out,
                *write_law_sources(folder), "-lm"])
    assert proc.returncode == 0, proc.stderr
    dll = ctypes.CDLL(str(out))
    dll.in_update.restype = ctypes.c_int
    dll.in_update.argtypes = [ctypes.c_double] * 4 + [
        ctypes.POINTER(Params), ctypes.POINTER(Step), ctypes.c_char_p, ctypes.c_size_t]
    dll.in_problems.restype = ctypes.c_int
    dll.in_problems.argtypes = [ctypes.POINTER(Params), ctypes.c_char_p,
                                ctypes.c_char_p, ctypes.c_size_t]
    dll.in_forces.argtypes = [ctypes.c_double] * 3 + [
        ctypes.POINTER(Params), ctypes.c_int, ctypes.c_int,
        ctypes.POINTER(ctypes.c_double)]
    return dll


def _c(p) -> Params:
    return Params(**{name: float(getattr(p, name)) for name, _ in Params._fields_})


def _random_design(rng) -> InclinedParameters:
    """A valid random design: theta 35-90 degrees (every 8th exactly 90), bonded
    surfaces (mu = inf) now and then, preloads from 0 to 600 N."""
    while True:
        values = dict(
            theta_deg=90.0 if rng.random() < 0.125 else rng.uniform(35.0, 90.0),
            k=rng.choice([0.0, rng.uniform(5e3, 5e4)]),
            kf=rng.uniform(2e4, 1e5), kf2=rng.uniform(2e4, 1e5),
            mu1=math.inf if rng.random() < 0.1 else rng.uniform(0.0, 0.6),
            mu2=math.inf if rng.random() < 0.1 else rng.uniform(0.0, 0.6),
            preload=rng.choice([0.0, rng.uniform(50.0, 600.0)]))
        values = {k: float(v) for k, v in values.items()}
        if not _python_problems(values):
            return InclinedParameters(**values)


def _python_problems(values: dict) -> list[str]:
    """InclinedParameters(**values).problems() (the constructor raises them)."""
    try:
        InclinedParameters(**values)
    except ValueError as exc:
        return str(exc).removeprefix("invalid inclined element: ").split("; ")
    return []


def _c_update(lib, x, x_old, w1, w2, cp):
    step, msg = Step(), ctypes.create_string_buffer(512)
    status = lib.in_update(x, x_old, w1, w2, ctypes.byref(cp), ctypes.byref(step),
                           msg, len(msg))
    return status, step, msg.value.decode()


def test_return_map_equals_python(lib):
    """2e4 increments: 100 designs x 200 steps of a random walk (mostly small steps,
    every 10th large enough to cross several stick/slip events), the sliders carried
    from step to step; where Python raises ContactLost, C returns the error code with
    the same message and the walk restarts at rest."""
    rng = np.random.default_rng(55)
    worst = dict.fromkeys(FIELDS, 0.0)
    scale = 1.0
    changes = lost = slips = 0
    for _ in range(DESIGNS):
        p = _random_design(rng)
        cp = _c(p)
        eps = 0.3 * (p.preload + 100.0) / p.kf  # about a slip displacement, m
        x = w1 = w2 = 0.0
        prev = (False, False)
        for _ in range(STEPS):
            # pulled towards x = 2 eps (pressed in), where contact mostly holds
            dx = 0.1 * (2.0 * eps - x) + rng.normal(
                0.0, eps * (4.0 if rng.random() < 0.1 else 0.5))
            x_new = x + dx
            status, got, msg = _c_update(lib, x_new, x, w1, w2, cp)
            try:
                ref = inclined_update(x_new, x, w1, w2, p)
            except ContactLost as exc:
                assert (status, msg) == (1, str(exc))
                lost += 1
                x = w1 = w2 = 0.0
                continue
            assert status == 0, msg
            assert (bool(got.slip1), bool(got.slip2)) == (ref.slip1, ref.slip2)
            slips += ref.slip1 or ref.slip2
            changes += (ref.slip1, ref.slip2) != prev
            prev = (ref.slip1, ref.slip2)
            scale = max(scale, abs(ref.force), abs(ref.n1))
            for name in FIELDS:
                k = p.kf if name == "w1" else p.kf2 if name == "w2" else 1.0
                worst[name] = max(worst[name],
                                  abs(getattr(got, name) - getattr(ref, name)) * k)
            x, w1, w2 = x_new, ref.w1, ref.w2
    # measured: 5092 regime changes, 3024 ContactLost, 10252 slipping; errors all 0
    assert changes > 0.1 * DESIGNS * STEPS and 0 < lost < 0.2 * DESIGNS * STEPS
    assert 0.1 * DESIGNS * STEPS < slips < 0.9 * DESIGNS * STEPS
    for name, err in worst.items():
        assert err <= TOL_REL * scale, (name, err, scale)


def test_forces_of_every_regime_equal_python(lib):
    rng = np.random.default_rng(8)
    out = (ctypes.c_double * 4)()
    for _ in range(500):
        p = _random_design(rng)
        x, w1, w2 = rng.normal(0.0, 0.005, 3).tolist()
        for sig1 in (-1, 0, 1):
            for sig2 in (-1, 0, 1):
                if (sig1 and math.isinf(p.mu1)) or (sig2 and math.isinf(p.mu2)):
                    continue  # a bonded surface has no slipping regime
                lib.in_forces(x, w1, w2, ctypes.byref(_c(p)), sig1, sig2, out)
                assert list(out) == list(inclined_forces(x, w1, w2, p,
                                                         (sig1, sig2)))


def test_many_events_in_one_increment_give_the_same_error(lib):
    """A long increment from a loaded state: the same result or the same message."""
    p = InclinedParameters(theta_deg=50.0, mu1=0.45, mu2=0.45, preload=50.0)
    for x_old, x in ((0.0, 0.05), (0.02, -0.03), (0.0, -0.001)):
        status, got, msg = _c_update(lib, x, x_old, 0.0, 0.0, _c(p))
        try:
            ref = inclined_update(x, x_old, 0.0, 0.0, p)
        except ContactLost as exc:
            assert (status, msg) == (1, str(exc))
        else:
            assert status == 0 and got.force == ref.force and got.w1 == ref.w1


def _problems_c(lib, values: dict, prefix: str) -> list[str]:
    buf = ctypes.create_string_buffer(4096)
    count = lib.in_problems(ctypes.byref(Params(**values)), prefix.encode(), buf,
                            len(buf))
    return buf.value.decode().split("; ") if count else []


BAD = [
    {"theta_deg": 95.0},
    {"theta_deg": 0.0, "k": -1.0, "kf": 0.0},
    {"kf2": math.inf, "mu1": -0.1, "mu2": math.nan, "preload": -5.0},
    {"theta_deg": math.nan, "k": math.inf},
    {"theta_deg": 10.0, "mu1": 0.5},            # self-locks
    {"theta_deg": 30.0, "mu1": math.inf, "mu2": 0.9},
    {"theta_deg": 45.0, "mu1": 1.0, "mu2": 0.0},  # determinant exactly about 0
]


@pytest.mark.parametrize("bad", BAD)
def test_parameter_messages_equal_python(lib, bad):
    values = {**{name: float(getattr(InclinedParameters(), name))
                 for name, _ in Params._fields_}, **bad}
    expected = [m.replace("`", "`radial1_", 1) for m in _python_problems(values)]
    assert expected, "every case has a problem"
    assert _problems_c(lib, values, "radial1_") == expected


def test_valid_designs_have_no_problem(lib):
    rng = np.random.default_rng(3)
    for _ in range(200):
        p = _random_design(rng)
        assert _problems_c(lib, {n: getattr(p, n) for n, _ in Params._fields_},
                           "axial_") == []
