"""Benchmark of the vehicle harness: cost per mount-step and seconds per frequency.

Run: ``python bench/bench_cosim.py [--periods P] [--repeat R] [--quick]``

Part 1, microseconds per mount-step (median of R repeats, each P periods of 256
steps), for a single-DOF system (1 mount, 1 active axis) and the 6-DOF engine
(3 mounts, 3 active axes each):

- ``raw null``: a bare loop over NullMount instances (``bench/null_mount.py``, built
  into a temporary folder: a pythonfmu slave with the FrictionMount variables and a
  ``do_step`` that returns at once) making exactly the harness's FMI calls, one
  ``fmi2SetReal`` (u, v of the active axes), one ``fmi2GetReal`` (F, Ffr of the active
  axes and E_fr) and one ``fmi2DoStep`` per mount and step, through fmpy's raw
  ``FMU2Slave.fmi2*`` functions with preallocated arrays and logging on: the floor of
  the FMI calls on this machine;
- ``raw fmu``: the same bare loop over FrictionMount instances (adds the FMU's own
  Python work, the mount law);
- ``harness null`` / ``harness fmu``: the harness (``vehicle.Master`` with the
  ``fmu`` backend, steady-state loop) driving NullMount / FrictionMount;
- ``inproc``: the harness with the in-process law (no FMI).

The native (C) FMUs (``fmu_build/native.py``, FMI 2.0), measured in the same run:

- ``raw native``: the bare loop over FrictionMountNative instances;
- ``raw null native``: the bare loop over NullMountNative instances (the same C
  interface and bookkeeping, no law);
- ``harness native``: the harness driving FrictionMountNative;
- ``raw native3``: the bare loop over FrictionMountNative3 (FMI 3.0) instances, through
  fmpy's FMU3Slave behind ``vehicle/fmi3_adapter.py`` (one extra Python frame per call).

Ratios: ``raw native / raw fmu`` is the native FMU's cost over the PythonFMU FMU's
through fmpy (target <= 0.5); ``raw native / raw null native`` its cost over the null
native FMU's (target <= 1.5); ``raw native / raw null`` over the PythonFMU null floor.

Ratios: ``harness null / raw null`` is the harness's own cost over the bare FMI floor
(the issue's criterion: <= 1.5); ``harness fmu / raw fmu`` the same with the real
model; ``harness fmu / raw null`` the total over the floor.

Part 2, seconds per steady-state frequency of every preset (``drymount.config``):
a stepped sweep over 3 frequencies of the preset's band, inproc and FMU backends.
"""

from __future__ import annotations

import argparse
import ctypes
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def build_null_fmu(folder: Path) -> Path:
    """Build NullMount.fmu into ``folder`` in a subprocess (keeps this one clean)."""
    dest = folder / "NullMount.fmu"
    code = ("from pythonfmu.builder import FmuBuilder; "
            f"FmuBuilder.build_FMU({str(HERE / 'null_mount.py')!r}, "
            f"dest={str(dest)!r})")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=folder)
    return dest


def raw_loop(system, fmu_path: Path, steps: int) -> float:
    """Microseconds per mount-step of the bare FMI call loop (no harness)."""
    from drymount.vehicle.backends import FMUBackend, Layout

    layout = Layout.of(system)
    be = FMUBackend(system, layout, fmu_path)
    try:
        calls = []
        bufs = []
        for e, fmu in enumerate(be._fmus):
            inb = (ctypes.c_double * be._nin[e])(*([1e-4] * be._nin[e]))
            outb = (ctypes.c_double * be._nout[e])()
            bufs.append((inb, outb))
            calls.append((fmu.fmi2SetReal, fmu.fmi2GetReal, fmu.fmi2DoStep,
                          fmu.component, be._vin[e], be._nin[e], inb, be._vout[e],
                          be._nout[e], outb))
        h = 1e-4
        t0 = time.perf_counter()
        for k in range(steps):
            t = k * h
            for S, G, D, c, vi, ni, pin, vo, no, pout in calls:
                S(c, vi, ni, pin)
                G(c, vo, no, pout)
                D(c, t, h, 1)
        dt = time.perf_counter() - t0
    finally:
        be.close()
    return dt / (steps * layout.n_mounts) * 1e6


def harness_loop(system, backend: str, fmu_path, periods: int) -> float:
    """Microseconds per mount-step of the harness's steady-state loop."""
    from drymount.vehicle.master import Master
    from drymount.vehicle.steady import run_steady

    with Master(system, backend, fmu_path=fmu_path) as m:
        ss = run_steady(m, 5.0, steps_per_period=256, rtol=1e-300,
                        min_periods=periods, max_periods=periods, start="rest")
    return ss.wall_time / (ss.n_steps * len(system.elements)) * 1e6


def systems():
    from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    from drymount.hbm.systems import rigid_engine, sdof

    ax = AxisParameters(law="piecewise", friction=True, n0=10.0)
    s1 = sdof(70.0, MountParameters.from_axial(ax), "unbalance", 0.01)
    mounts = [MountParameters.from_axial(ax, 1.0, friction_axes=f)
              for f in (("radial1",), ("radial2",), ("axial",))]
    s6 = rigid_engine(140.8, [8.63, 10.02, 10.22],
                      [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)], mounts)
    return [("sdof, 1 mount x 1 axis", s1), ("6-DOF, 3 mounts x 3 axes", s6)]


def part1(real_fmu: Path, null_fmu: Path, periods: int, repeat: int,
          native_fmus: dict[str, Path]) -> list[dict]:
    rows = []
    steps = periods * 256
    for label, system in systems():
        res = {k: [] for k in ("raw null", "raw fmu", "harness null", "harness fmu",
                               "inproc", "raw native", "raw null native",
                               "harness native", "raw native3")}
        for _ in range(repeat):
            res["raw null"].append(raw_loop(system, null_fmu, steps))
            res["raw fmu"].append(raw_loop(system, real_fmu, steps))
            res["raw native"].append(raw_loop(system, native_fmus["native"], steps))
            res["raw null native"].append(raw_loop(system, native_fmus["null"], steps))
            res["raw native3"].append(raw_loop(system, native_fmus["native3"], steps))
            res["harness null"].append(harness_loop(system, "fmu", null_fmu, periods))
            res["harness fmu"].append(harness_loop(system, "fmu", real_fmu, periods))
            res["harness native"].append(harness_loop(system, "fmu",
                                                      native_fmus["native"], periods))
            res["inproc"].append(harness_loop(system, "inproc", None, periods))
        med = {k: statistics.median(v) for k, v in res.items()}
        med["label"] = label
        rows.append(med)
    print(f"\nus per mount-step (median of {repeat} x {steps} steps)")
    head = ("system", "raw null", "raw fmu", "harness null", "harness fmu", "inproc",
            "h.null/raw null", "h.fmu/raw fmu", "h.fmu/raw null")
    print("  ".join(f"{h:>15}" if i else f"{h:<26}" for i, h in enumerate(head)))
    for r in rows:
        vals = [r["raw null"], r["raw fmu"], r["harness null"], r["harness fmu"],
                r["inproc"], r["harness null"] / r["raw null"],
                r["harness fmu"] / r["raw fmu"], r["harness fmu"] / r["raw null"]]
        print(f"{r['label']:<26}  " + "  ".join(f"{v:15.2f}" for v in vals))
    print_native(rows)
    return rows


def print_native(rows: list[dict]) -> None:
    """The native FMU's row: cost per mount-step and the issue's ratios."""
    print("\nnative (C) FMU, FMI 2.0, us per mount-step (same run)")
    head = ("system", "raw native", "raw null nat.", "harness native",
            "nat./pythonfmu", "nat./null nat.", "nat./raw null", "raw native3")
    print("  ".join(f"{h:>15}" if i else f"{h:<26}" for i, h in enumerate(head)))
    for r in rows:
        vals = [r["raw native"], r["raw null native"], r["harness native"],
                r["raw native"] / r["raw fmu"], r["raw native"] / r["raw null native"],
                r["raw native"] / r["raw null"], r["raw native3"]]
        print(f"{r['label']:<26}  " + "  ".join(f"{v:15.2f}" for v in vals))
    worst_py = max(r["raw native"] / r["raw fmu"] for r in rows)
    worst_null = max(r["raw native"] / r["raw null native"] for r in rows)
    print(f"targets: native/pythonfmu {worst_py:.2f} <= 0.5 "
          f"{'met' if worst_py <= 0.5 else 'MISSED'}; native/null native "
          f"{worst_null:.2f} <= 1.5 {'met' if worst_null <= 1.5 else 'MISSED'}")


def part2(real_fmu: Path, quick: bool) -> None:
    from drymount.config import list_presets, load_preset
    from drymount.vehicle.sweep import sweep

    names = list_presets()
    if quick:
        names = names[:3]
    print("\nseconds per steady-state frequency (stepped sweep of 3 frequencies in the "
          "preset's band, from the linear start, default rtol)")
    print(f"{'preset':<24}{'band Hz':>14}{'inproc s':>12}{'fmu s':>12}"
          f"{'periods':>10}{'converged':>11}")
    for name in names:
        cfg = load_preset(name)
        f = np.linspace(cfg.sweep.fmin_hz, cfg.sweep.fmax_hz, 5)[1:4]
        out = {}
        for backend in ("inproc", "fmu"):
            sw = sweep(cfg.system, f, backend=backend, fmu_path=real_fmu,
                       progress=False)
            out[backend] = sw
        band = f"{cfg.sweep.fmin_hz:g}-{cfg.sweep.fmax_hz:g}"
        print(f"{name:<24}{band:>14}{out['inproc'].elapsed / f.size:12.3f}"
              f"{out['fmu'].elapsed / f.size:12.3f}"
              f"{np.mean(out['fmu'].n_periods):10.0f}"
              f"{str(bool(out['fmu'].success)):>11}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=20,
                    help="periods of 256 steps per timing (default 20)")
    ap.add_argument("--repeat", type=int, default=3, help="repeats (default 3)")
    ap.add_argument("--quick", action="store_true",
                    help="part 2 on the first 3 presets only")
    ap.add_argument("--skip-presets", action="store_true", help="part 1 only")
    args = ap.parse_args(argv)
    from drymount.fmu_build import build_fmu
    from drymount.fmu_build.native import build_native_fmu

    with tempfile.TemporaryDirectory(prefix="drymount_bench_") as tmp:
        tmp = Path(tmp)
        real = build_fmu(tmp / "FrictionMount.fmu")
        null = build_null_fmu(tmp)
        native = {"native": build_native_fmu(tmp / "FrictionMountNative.fmu").path,
                  "null": build_native_fmu(tmp / "NullMountNative.fmu", null=True).path,
                  "native3": build_native_fmu(tmp / "FrictionMountNative3.fmu",
                                              fmi=3).path}
        print(f"python {sys.version.split()[0]}, FMUs built in {tmp}")
        part1(real, null, args.periods, args.repeat, native)
        if not args.skip_presets:
            part2(real, args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
