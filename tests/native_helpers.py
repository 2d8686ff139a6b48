"""Shared pieces of the native-FMU tests: random trajectories, the reference run of
``fmu_src/mount_law.py`` with the FMU's protocol, builds of the native FMUs.

The protocol (fmu_src/friction_mount.py): per step the inputs u, v, n at t_k are set,
the outputs are the trial return map ``axis_force(u, v, w_committed)`` with the slip
force ``mu * max(n, 0)``, then ``doStep`` commits ``w`` and adds the dissipated energy.
"""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from drymount.fmu_src.mount_law import (AXES, LAWS, AxisParameters, axis_force,
                               initial_sliders, law_code, mean_slider)

ROOT = Path(__file__).resolve().parent.parent
#: Output columns compared, per axis, then the total energy.
AXIS_OUTPUTS = ("F", "Ffr", "kt", "slip", "E_fr")


@dataclass(frozen=True)
class Trajectory:
    """Inputs per step and axis: deflection u [m], rate v [m/s], normal force n [N]."""

    u: np.ndarray  # (steps, 3)
    v: np.ndarray
    n: np.ndarray


@dataclass(frozen=True)
class Outputs:
    """Outputs per step: per-axis arrays (steps, 3) and the total energy (steps,)."""

    F: np.ndarray
    Ffr: np.ndarray
    kt: np.ndarray
    slip: np.ndarray
    E_fr: np.ndarray
    E_total: np.ndarray
    #: committed slider position w_<axis> after each step (the mean of a micro-slip
    #: axis's sliders); None where not read
    w: np.ndarray | None = None


def random_trajectory(rng: np.random.Generator, steps: int, h: float = 1e-4,
                      amplitude: float = 0.02, n0: float = 400.0) -> Trajectory:
    """Deflections crossing the knees (|u| up to ~2 delta) with reversals between
    samples: a sum of sines, some above the sampling's Nyquist frequency (so the
    motion reverses inside steps), plus a random walk; normal forces varying around
    ``n0`` and dropping below zero (contact loss) about 10 % of the time."""
    t = np.arange(steps) * h
    u = np.zeros((steps, 3))
    for j in range(3):
        for _ in range(4):
            f = rng.uniform(1.0, 200.0)
            u[:, j] += rng.uniform(0.1, 0.4) * amplitude * np.sin(
                2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        # aliased component: a period shorter than two steps reverses inside a step
        f_fast = rng.uniform(0.6, 0.95) / h
        u[:, j] += 0.05 * amplitude * np.sin(2 * np.pi * f_fast * t)
        u[:, j] += np.cumsum(rng.normal(0.0, 0.002 * amplitude, steps))
    v = np.gradient(u, h, axis=0) + rng.normal(0.0, 0.01, (steps, 3))
    # a random walk wrapped into [-0.12, 1.08] n0: about 10 % negative (lost contact)
    walk = 0.5 + np.cumsum(rng.normal(0.0, 0.02, (steps, 3)), axis=0)
    n = n0 * (walk % 1.2 - 0.12)
    return Trajectory(u, v, n)


def random_axis(rng: np.random.Generator, law: str, friction: bool) -> AxisParameters:
    """Random valid parameters of one axis (thesis-like magnitudes)."""
    k1 = rng.uniform(5e4, 2e5)
    return AxisParameters(
        law=law, k1=k1, kc=rng.uniform(1e8, 1e9), k2=k1 * rng.uniform(2.0, 8.0),
        delta=rng.uniform(0.005, 0.015), delta_neg=rng.uniform(0.003, 0.012),
        c=rng.uniform(0.0, 300.0), friction=friction, kf=rng.uniform(2e4, 1e5),
        mu=rng.uniform(0.2, 1.5), n0=rng.uniform(50.0, 500.0))


def reference_run(axes: tuple[AxisParameters, ...], traj: Trajectory) -> Outputs:
    """The FMU protocol on ``fmu_src/mount_law.py`` (Python floats, step by step)."""
    steps = traj.u.shape[0]
    out = {name: np.zeros((steps, 3)) for name in AXIS_OUTPUTS}
    committed, dissipated = np.zeros((steps, 3)), np.zeros((steps, 3))
    w_after = np.zeros((steps, 3))
    for j, p in enumerate(axes):
        w, e = initial_sliders(p), 0.0
        F, Ffr, kt, slip, E = (out[name][:, j] for name in AXIS_OUTPUTS)
        for k, (u, v, n) in enumerate(zip(traj.u[:, j].tolist(), traj.v[:, j].tolist(),
                                          traj.n[:, j].tolist())):
            r = axis_force(u, v, w, p, n)  # Fs = mu max(n, 0) in the element
            F[k], Ffr[k], kt[k], slip[k], E[k] = r[0], r[1], r[3], r[4], e + r[5]
            committed[k, j], dissipated[k, j] = e, r[5]
            w = r[2]
            w_after[k, j] = mean_slider(w)
            e += r[5]
    # the FMU's summation order: e0 + d0 + e1 + d1 + e2 + d2
    e_total = np.zeros(steps)
    for j in range(3):  # elementwise, in that order
        e_total = e_total + committed[:, j] + dissipated[:, j]
    return Outputs(**out, E_total=e_total, w=w_after)


def scales(ref: Outputs) -> dict[str, float]:
    """Scale of each output for the relative comparison (max magnitude, >= 1)."""
    force = max(1.0, float(np.abs(ref.F).max()))
    return {"F": force, "Ffr": force, "kt": max(1.0, float(np.abs(ref.kt).max())),
            "E_fr": max(1.0, float(np.abs(ref.E_total).max())), "slip": 1.0}


def worst_relative(ref: Outputs, got: Outputs) -> dict[str, float]:
    """Largest |got - ref| / scale of every output."""
    s = scales(ref)
    out = {name: float(np.abs(getattr(got, name) - getattr(ref, name)).max()) / s[name]
           for name in AXIS_OUTPUTS}
    out["E_total"] = float(np.abs(got.E_total - ref.E_total).max()) / s["E_fr"]
    return out


def parameter_values(axes: tuple[AxisParameters, ...]) -> dict[str, object]:
    """FMU parameter values ``<axis>_<field>`` of three axes (integer codes for the
    law and, where the law has friction kinds, the friction kind)."""
    from drymount.fmu_src import mount_law

    codes = {"law": law_code,
             "friction_kind": getattr(mount_law, "friction_kind_code", None)}
    out = {}
    for axis, p in zip(AXES, axes, strict=True):
        for name, value in p.to_dict().items():
            out[f"{axis}_{name}"] = codes[name](value) if name in codes else value
    return out


#: (law, friction) of each axis of four instances: every law with and without friction.
LAW_LAYOUT = (
    (("linear", True), ("cubic", False), ("piecewise", True)),
    (("piecewise_asym", True), ("linear", False), ("cubic", True)),
    (("piecewise", False), ("piecewise_asym", False), ("linear", True)),
    (("cubic", True), ("piecewise", False), ("piecewise_asym", True)),
)
assert {x for inst in LAW_LAYOUT for x in inst} == {(law, f) for law in LAWS
                                                   for f in (True, False)}


def random_instance(rng, layout) -> tuple[AxisParameters, ...]:
    return tuple(random_axis(rng, law, friction) for law, friction in layout)


#: (law, sliders, spread, fs_ratio) of each axis (friction on) of two instances:
#: micro-slip with and without spread and fs_ratio (also 0 and 64 sliders), and the
#: non-symmetric macro-slip element.
GENERAL_LAYOUT = (
    (("piecewise", 8, 0.6, 1.0), ("cubic", 1, 0.0, 0.4), ("linear", 64, 0.9, 1.7)),
    (("piecewise_asym", 3, 0.3, 0.0), ("linear", 1, 0.0, 2.5),
     ("piecewise", 17, 0.0, 1.0)),
)


def random_general_instance(rng, layout) -> tuple[AxisParameters, ...]:
    """Random axes with the friction elements of a :data:`GENERAL_LAYOUT` entry."""
    return tuple(replace(random_axis(rng, law, True), sliders=sliders, spread=spread,
                         fs_ratio=ratio) for law, sliders, spread, ratio in layout)


def without_friction(axes):
    return tuple(replace(p, friction=False) for p in axes)


def need_gcc():
    if shutil.which("gcc") is None:
        pytest.skip("gcc not found: the native FMU is compiled at build time")


def build(folder: Path, fmi: int, null: bool = False) -> Path:
    """Build a native FMU into ``folder`` (in this process: the builder only runs gcc
    and writes a zip)."""
    from drymount.fmu_build.native import build_native_fmu

    need_gcc()
    return build_native_fmu(folder / f"native{fmi}{'null' if null else ''}.fmu",
                            fmi=fmi, null=null).path


def run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True,
                          check=False, **kw)


def host_config(folder, md, instances, h: float) -> str:
    """The config of tests/c_host/native_host.c for ``instances`` ((axes,
    trajectory) pairs, trajectories written into ``folder``) at step ``h``: inputs
    u, v, n; outputs F, Ffr, kt, E_fr per axis, E_fr, then slip per axis."""
    steps = instances[0][1].u.shape[0]
    vr = {v.name: v.valueReference for v in md.modelVariables}
    types = {v.name: v.type for v in md.modelVariables}
    ins = [vr[f"{q}_{a}"] for a in AXES for q in ("u", "v", "n")]
    outs = [vr[f"{q}_{a}"] for q in ("F", "Ffr", "kt", "E_fr") for a in AXES]
    outs.append(vr["E_fr"])
    lines = [f"steps {steps} h {h!r}",
             f"inputs {len(ins)} " + " ".join(map(str, ins)),
             f"outputs {len(outs)} " + " ".join(map(str, outs)),
             "booleans 3 " + " ".join(str(vr[f"slip_{a}"]) for a in AXES)]
    for i, (axes, traj) in enumerate(instances):
        x = np.stack([traj.u, traj.v, traj.n], axis=2).reshape(steps, 9)
        x.astype("<f8").tofile(folder / f"in{i}.bin")
        src, dst = folder / f"in{i}.bin", folder / f"out{i}.bin"
        lines.append(f"instance mount{i} {src} {dst}")
        for name, value in parameter_values(axes).items():
            kind = {"Real": "real", "Integer": "integer", "Boolean": "boolean"}[
                types[name]]
            lines.append(f"{kind} {vr[name]} {float(value)!r}")
    return "\n".join(lines) + "\n"


def all_builds(folder: Path) -> dict[str, Path]:
    """The three builds in ``folder``: ``pythonfmu`` (FMI 2.0), ``native2``,
    ``native3`` (skips without pythonfmu or gcc)."""
    pytest.importorskip("pythonfmu", reason="the PythonFMU build needs pythonfmu")
    from drymount.fmu_build import build_fmu

    return {"pythonfmu": build_fmu(folder / "FrictionMount.fmu"),
            "native2": build(folder, 2), "native3": build(folder, 3)}
