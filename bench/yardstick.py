"""The fixed Python + NumPy yardstick that drymount's benchmarks divide their times by.

A ratio to this yardstick, timed in the same run, is stable across machines and loads
where a wall time is not (issue 27): a busy 2-core machine slows both alike.

The yardstick is

- a pure-Python scalar Jenkins march over 1e6 samples (kf 60 000 N/m, Fs 20 N, a
  sine of 1 mm amplitude, 256 samples per period): interpreter speed, and
- 10,000 dense solves of a fixed, well-conditioned 30 x 30 system with NumPy: the
  per-call cost of small linear algebra, as a Newton iteration of the HBM pays it.

``yardstick()`` returns the median of ``repeat`` timings of the two together, in
seconds. Run ``python bench/yardstick.py`` to print it with its two parts.
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import time
from dataclasses import dataclass

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

N_MARCH = 1_000_000
N_SOLVES = 10_000
SIZE = 30


@dataclass(frozen=True)
class YardstickTiming:
    """One timing of the yardstick: its two parts and their sum, in seconds."""

    march_s: float
    solves_s: float

    @property
    def total_s(self) -> float:
        return self.march_s + self.solves_s


def _jenkins_march(n: int = N_MARCH) -> float:
    """March a scalar Jenkins slider over ``n`` samples; return the energy."""
    kf, fs, amp = 60_000.0, 20.0, 1e-3
    w = 0.0
    u_prev = 0.0
    energy = 0.0
    step = 2.0 * math.pi / 256.0
    for i in range(n):
        u = amp * math.sin(step * i)
        f = kf * (u - w)
        if f > fs:
            w = u - fs / kf
            f = fs
        elif f < -fs:
            w = u + fs / kf
            f = -fs
        energy += f * (u - u_prev)
        u_prev = u
    return energy


def _dense_solves(n: int = N_SOLVES, size: int = SIZE) -> float:
    """Solve a fixed 30 x 30 system ``n`` times; return a checksum."""
    rng = np.random.default_rng(0)
    a = rng.standard_normal((size, size)) + size * np.eye(size)
    b = rng.standard_normal(size)
    total = 0.0
    for _ in range(n):
        total += float(np.linalg.solve(a, b)[0])
    return total


def time_once() -> YardstickTiming:
    """Time the two parts once."""
    t0 = time.perf_counter()
    _jenkins_march()
    t1 = time.perf_counter()
    _dense_solves()
    t2 = time.perf_counter()
    return YardstickTiming(march_s=t1 - t0, solves_s=t2 - t1)


def yardstick(repeat: int = 3) -> float:
    """The median over ``repeat`` timings of the yardstick, in seconds."""
    if repeat < 1:
        raise ValueError(f"repeat = {repeat!r}: must be at least 1")
    return statistics.median(time_once().total_s for _ in range(repeat))


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    repeat = int(args[0]) if args else 3
    timings = [time_once() for _ in range(repeat)]
    for t in timings:
        print(f"march {t.march_s:.3f} s  solves {t.solves_s:.3f} s  "
              f"total {t.total_s:.3f} s")
    print(f"yardstick (median of {repeat}): "
          f"{statistics.median(t.total_s for t in timings):.3f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
