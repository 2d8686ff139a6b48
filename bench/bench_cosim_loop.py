"""The co-simulation loop's own cost: the harness against the raw FMI calls it makes
(issue 27 item 4).

Run: ``python bench/bench_cosim_loop.py [--periods P] [--repeat R]``

For the single-DOF system (1 mount, 1 active axis) and the 6-DOF engine (3 mounts,
3 active axes each), with the PythonFMU build (``FrictionMount.fmu``), the native C
build (``FrictionMountNative.fmu``, FMI 2.0) and its FMI 3.0 build, microseconds per
mount-step (CPU time of the process, median of R interleaved repeats of P periods each):

- ``raw``: a bare loop over fresh instances of the same FMU with the same parameters
  making exactly the harness's calls per mount and step, one set of all the mount's
  inputs, one get of all its outputs, one doStep, the cheapest way Python can make
  them (the FMU's own functions through ctypes, every argument prebuilt:
  ``vehicle.backends.raw_fmi_calls``), statuses checked, on the inputs the harness
  computed (recorded from a harness run of the same periods) at the same times: the
  floor of the FMI calls;
- ``raw fmpy``: the same loop through fmpy's ``fmi2SetReal`` / ``fmi2GetReal`` /
  ``fmi2DoStep`` wrappers (what the harness called before);
- ``harness``: ``vehicle.Master`` (``fmu`` backend) running the same periods with
  ``begin_periodic`` / ``run_period`` (the loop of a steady state or sweep: the calls,
  the linear update, the per-period bookkeeping and records).

- ``harness py``: the same with the Python stepping loop (``$DRYMOUNT_C_LOOP=0``;
  the native FMUs run the C loop of :mod:`vehicle.c_loop` otherwise, the PythonFMU
  build always the Python loop);

- ``W.dot``: the linear update alone, the one matrix-vector product per step
  (``W.dot(x, y)``, the same call as the harness's) on a copy of the row buffer.

Ratio ``harness / raw`` (the automatic choice) is the harness's total cost over
the FMI calls (target <= 1.2); ``py / raw`` the Python loop's; ``(raw + dot) /
raw`` is the least the Python loop can cost while the product stays NumPy's (the
results bit for bit). Each row's figures come from one run, repeats interleaved.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import ctypes  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_cosim import systems  # noqa: E402

#: Target: the harness's cost per mount-step over the raw FMI calls.
TARGET = 1.2
FREQ_HZ = 6.0


class Raw:
    """Fresh instances of an FMU driven by a bare loop of the harness's calls on a
    recorded input trajectory ``uv`` (steps, 2m) at the times ``times``."""

    def __init__(self, system, fmu_path, uv: np.ndarray, times: list, h: float):
        from drymount.vehicle.backends import FMUBackend, Layout, raw_fmi_calls

        L = Layout.of(system)
        self.be = FMUBackend(system, L, fmu_path)
        self.uv = np.ascontiguousarray(uv)
        self.out = np.zeros((uv.shape[0], L.n_out))
        self.times = list(times)
        self.steps = uv.shape[0]
        self.n_mounts = L.n_mounts
        dbl = ctypes.POINTER(ctypes.c_double)
        self.t_arg = ctypes.c_double(0.0)
        be = self.be
        raws = [raw_fmi_calls(f, h, self.t_arg) for f in be._fmus]
        self.calls, self.wrapped = [], []
        ub, ob = self.uv.ctypes.data, self.out.ctypes.data
        no = L.n_out
        for k in range(self.steps):
            row, wrow = [], []
            for e, (r, fmu) in enumerate(zip(raws, be._fmus, strict=True)):
                pin = ctypes.cast(ub + 8 * (k * 2 * L.m + L.uv_off(e)), dbl)
                pout = ctypes.cast(ob + 8 * (k * no + L.out_off(e) - L.o_out), dbl)
                row.append((r.set_real, r.set_args(be._vin[e], be._nin[e], pin),
                            r.get_real, r.get_args(be._vout[e], be._nout[e], pout),
                            r.do_step, r.step_args))
                wrow.append((fmu.fmi2SetReal, fmu.fmi2GetReal, fmu.fmi2DoStep,
                             fmu.component, be._vin[e], be._nin[e], pin,
                             be._vout[e], be._nout[e], pout))
            self.calls.append(row)
            self.wrapped.append(wrow)
        self.h = h
        self.offset = 0.0  # time of the next pass over the trajectory

    def run(self) -> float:
        """One pass over the trajectory; seconds."""
        t_arg, off = self.t_arg, self.offset
        times = [off + t for t in self.times]
        t0 = time.process_time()
        for row, t in zip(self.calls, times):
            t_arg.value = t
            for S, sa, G, ga, D, da in row:
                if S(*sa) > 1 or G(*ga) > 1 or D(*da) > 1:
                    raise RuntimeError("FMI call failed")
        dt = time.process_time() - t0
        self.offset = times[-1] + self.h
        return dt

    def run_wrapped(self) -> float:
        """One pass through fmpy's wrappers; seconds."""
        h, off = self.h, self.offset
        times = [off + t for t in self.times]
        t0 = time.process_time()
        for row, t in zip(self.wrapped, times):
            for S, G, D, c, vi, ni, pin, vo, no, pout in row:
                S(c, vi, ni, pin)
                G(c, vo, no, pout)
                D(c, t, h, 1)
        dt = time.process_time() - t0
        self.offset = times[-1] + self.h
        return dt

    def close(self):
        self.be.close()


def measure(system, fmu_path, periods: int, repeat: int) -> dict:
    from drymount.vehicle.inputs import HarmonicInput
    from drymount.vehicle.master import Master

    m = Master(system, "fmu", fmu_path=fmu_path)
    N = m.steps_per_period(FREQ_HZ)
    h = 1.0 / (FREQ_HZ * N)
    m.begin_periodic(HarmonicInput(system, FREQ_HZ), N, h)
    os.environ["DRYMOUNT_C_LOOP"] = "0"
    try:
        mp = Master(system, "fmu", fmu_path=fmu_path)
        mp.begin_periodic(HarmonicInput(system, FREQ_HZ), N, h)  # binds: no C loop
    finally:
        del os.environ["DRYMOUNT_C_LOOP"]
    assert mp.backend._c_loop is None
    c_used = m.backend._c_loop is not None
    L = m.layout
    # the inputs of the harness's own periods (warm-up: the first `periods` periods)
    uv, times = [], []
    for p in range(periods):
        rec = m.run_period()
        del rec
        uv.append(m._rec[:N, :2 * L.m].copy())
        times += [(p * N + k) * h for k in range(N)]
    raw = Raw(system, fmu_path, np.vstack(uv), times, h)
    res = {"raw": [], "raw fmpy": [], "harness": [], "harness py": [], "dot": []}
    steps = periods * N * L.n_mounts
    # the linear update alone (one W.dot per step) on a copy of the row buffer
    buf = m._rec.copy()
    Wdot = m._Wh.copy().dot
    xs = [buf[k, L.o_x:] for k in range(N)]
    ys = [buf[k + 1, :L.n_next] for k in range(N)]
    try:
        for _ in range(repeat):
            res["raw"].append(raw.run() / steps * 1e6)
            t0 = time.process_time()
            for _ in range(periods):
                m.run_period()
            res["harness"].append((time.process_time() - t0) / steps * 1e6)
            res["raw fmpy"].append(raw.run_wrapped() / steps * 1e6)
            t0 = time.process_time()
            for _ in range(periods):
                mp.run_period()
            res["harness py"].append((time.process_time() - t0) / steps * 1e6)
            t0 = time.process_time()
            for _ in range(periods):
                for x, y in zip(xs, ys):
                    Wdot(x, y)
            res["dot"].append((time.process_time() - t0) / steps * 1e6)
    finally:
        raw.close()
        m.close()
        mp.close()
    out = {k: statistics.median(v) for k, v in res.items()}
    out["loop"] = "C" if c_used else "Python"
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=20,
                    help="periods per timing (default 20)")
    ap.add_argument("--repeat", type=int, default=5, help="repeats (default 5)")
    args = ap.parse_args(argv)
    from drymount.fmu_build import build_fmu
    from drymount.fmu_build.native import build_native_fmu

    with tempfile.TemporaryDirectory(prefix="drymount_loop_") as tmp:
        tmp = Path(tmp)
        fmus = {"PythonFMU": build_fmu(tmp / "FrictionMount.fmu"),
                "native": build_native_fmu(tmp / "FrictionMountNative.fmu").path,
                "native FMI 3": build_native_fmu(tmp / "FrictionMountNative3.fmu",
                                                 fmi=3).path}
        print(f"python {sys.version.split()[0]}; load average "
              "{:.2f} {:.2f} {:.2f} on {} cores".format(*os.getloadavg(),
                                                       os.cpu_count()))
        print(f"us per mount-step, median of {args.repeat} interleaved repeats of "
              f"{args.periods} periods at {FREQ_HZ:g} Hz")
        head = ("system", "FMU", "raw", "raw fmpy", "harness py", "harness", "W.dot",
                "harness/raw", "py/raw", "(raw+dot)/raw", "loop", "met")
        print(f"{head[0]:<26}{head[1]:<14}" + "".join(f"{x:>12}" for x in head[2:9])
              + f"{head[9]:>14}{head[10]:>8}{head[11]:>6}")
        worst = 0.0
        for label, system in systems():
            for name, path in fmus.items():
                r = measure(system, path, args.periods, args.repeat)
                ratio = r["harness"] / r["raw"]
                worst = max(worst, ratio)
                print(f"{label:<26}{name:<14}{r['raw']:12.2f}{r['raw fmpy']:12.2f}"
                      f"{r['harness py']:12.2f}{r['harness']:12.2f}{r['dot']:12.2f}"
                      f"{ratio:12.2f}{r['harness py'] / r['raw']:12.2f}"
                      f"{(r['raw'] + r['dot']) / r['raw']:14.2f}{r['loop']:>8}"
                      f"{'yes' if ratio <= TARGET else 'NO':>6}")
        print(f"worst harness/raw {worst:.2f} (target <= {TARGET})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
