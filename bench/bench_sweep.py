"""Benchmark of stepped sweeps (issue 15, items 4 and 5): batched in-process stepping
and sweeps that find the peak.

Run: ``python bench/bench_sweep.py [--repeat R] [--points P]``

1. Native cost per mount-step and frequency (CPU time, best of R): the harness with
   the scalar in-process law (``Master.run_period``, one frequency) against
   ``vehicle.batch`` stepping P frequencies (default 30) at once, for
   quarter_car_halved (1 mount, 1 active axis) and six_dof_halved (3 mounts, 9 axes).
   Target: under 1 us per mount-step and frequency in a 30-point batch.
2. A P-point sweep of quarter_car_halved over its band (CPU s, in-process, after the
   imports): serial inproc, batched inproc, each against the HBM curve of the band
   (``api.hbm``, H = 7) measured in the same run.
3. The peak that a P-point sweep reads against HBM's (the reference): the grid, with
   ``refine=8``, with ``refine=4`` guided by the HBM curve. Target: within 1 %.

BLAS runs with one thread (as the command line does). Every figure is printed next
to its target as a ratio.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import drymount.vehicle as vehicle  # noqa: E402
from drymount import api  # noqa: E402
from drymount.vehicle.batch import _Batch, _masters  # noqa: E402
from drymount.vehicle.master import Master  # noqa: E402
from drymount.vehicle.steady import _begin  # noqa: E402

#: Target of item 4: in-process us per mount-step and frequency in a 30-point batch.
TARGET_STEP_US = 1.0
#: Target of item 5: relative error of the swept peak against HBM's.
TARGET_PEAK = 0.01
PERIODS = 4


def _load():
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(
        *os.getloadavg(), os.cpu_count())


def _best(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def step_costs(name, points, repeat):
    """(scalar us per mount-step, batched us per mount-step and frequency)."""
    s = api.load(name).system
    f = np.linspace(2.0, 12.0, points)
    scalar = Master(s, "inproc")
    _begin(scalar, 5.0, None, "linear")
    N = scalar._periodic[1]
    t_scalar = _best(lambda: [scalar.run_period() for _ in range(PERIODS)], repeat)
    masters = _masters(s, points)
    for m, x in zip(masters, f, strict=True):
        _begin(m, float(x), None, "linear")
    batch = _Batch(masters)

    def run():
        for _ in range(PERIODS):
            for m in masters:
                m._next_period()
            batch.run_rows(N)
            for m in masters:
                m._finish_period()
    t_batch = _best(run, repeat)
    mounts = len(s.elements)
    steps = PERIODS * N
    return (t_scalar / steps / mounts * 1e6,
            t_batch / steps / points / mounts * 1e6, mounts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--points", type=int, default=30)
    a = ap.parse_args()
    P = a.points
    print(f"1. in-process cost per mount-step and frequency, {P}-point batch "
          f"(CPU, best of {a.repeat}); {_load()}")
    print(f"   {'model':<20} {'mounts':>6} {'scalar us':>10} {'batched us':>11} "
          f"{'speed-up':>9} {'target us':>10} {'ratio':>6}")
    for name in ("quarter_car_halved", "six_dof_halved"):
        sc, ba, mounts = step_costs(name, P, a.repeat)
        print(f"   {name:<20} {mounts:>6} {sc:>10.2f} {ba:>11.3f} {sc / ba:>8.1f}x "
              f"{TARGET_STEP_US:>10.2f} {ba / TARGET_STEP_US:>6.2f}")

    print(f"\n2. {P}-point sweep of quarter_car_halved against its HBM curve "
          f"(CPU s, best of {a.repeat}); {_load()}")
    m = api.load("quarter_car_halved")
    lo, hi = m.config.sweep.fmin_hz, m.config.sweep.fmax_hz
    f = np.linspace(lo, hi, P)
    curve = api.hbm(m, progress=False)
    t_hbm = _best(lambda: api.hbm(m, progress=False), a.repeat)
    runs = {}
    for label, kw in (("serial inproc", {}), ("batched inproc", {"batch": True})):
        res = {}

        def go(kw=kw, res=res):
            res["r"] = vehicle.sweep(m.system, f, backend="inproc", progress=False,
                                     **kw)
        runs[label] = (_best(go, a.repeat), res["r"])
    print(f"   HBM curve (H = {curve.result.harmonics}, {len(curve.freq_hz)} points): "
          f"{t_hbm:.3f} s")
    for label, (t, _r) in runs.items():
        print(f"   {label:<15} {t:7.3f} s   sweep / HBM {t / t_hbm:6.1f}x")
    t_s, t_b = runs["serial inproc"][0], runs["batched inproc"][0]
    print(f"   batched / serial: {t_b / t_s:.2f}")

    print(f"\n3. peak of a {P}-point sweep of quarter_car_halved against HBM's; "
          f"{_load()}")
    ref = float(np.max(curve.transmissibility))
    fref = float(curve.freq_hz[np.argmax(curve.transmissibility)])
    print(f"   HBM peak {ref:.4f} at {fref:.3f} Hz; target |error| < "
          f"{TARGET_PEAK:.0%}")
    cases = (("grid only (batched)", {"batch": True}),
             ("refine=8", {"refine": 8}),
             ("refine=4 --hbm (batched)", {"refine": 4, "hbm": curve, "batch": True}))
    for label, kw in cases:
        t0 = time.process_time()
        r = vehicle.sweep(m.system, f, backend="inproc", progress=False, **kw)
        t = time.process_time() - t0
        i = int(np.argmax(r.transmissibility))
        err = r.transmissibility[i] / ref - 1
        print(f"   {label:<26} {len(r.freq_hz):>3} points  peak "
              f"{r.transmissibility[i]:.4f} at {r.freq_hz[i]:.3f} Hz  error "
              f"{err:+.2%}  ratio to target {abs(err) / TARGET_PEAK:5.2f}  "
              f"({t:.2f} s CPU)")


if __name__ == "__main__":
    main()
