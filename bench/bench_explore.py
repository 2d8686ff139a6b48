"""Benchmark of ``drymount explore`` backends (issue 16): designs per second.

Two explorations, each run

- serially, in this process;
- on 2 local processes (``--workers 2``, spawn);
- on a 2-worker Dask LocalCluster (``--dask local:2``), if dask.distributed is
  installed;

``sdof``: ``examples/design/sdof_n0.toml`` (single DOF, H = 1, 1-200 Hz, ~0.03 s per
design: the per-task overhead of a backend shows); ``six_dof``:
``examples/design/six_dof_layout.toml`` (6 DOF, H = 1, 2-25 Hz, ~0.5-1.5 s per design:
the work dominates). Each is timed from the call to the finished table (start-up of
the pool or cluster included, as a user sees it: "wall") and from the moment the
backend was up ("streaming"). Prints designs per second, the speed-up against serial
measured in the same run, whether every backend wrote the same table, and the
projected time of 10,000 designs at the streaming rate.

The machine is shared: the ratios measured in one run are what counts, and on a
loaded 2-core machine two workers cannot reach 2x.

Run: ``python bench/bench_explore.py [--sdof 96] [--six-dof 16] [--chunk 4]``
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PROJECTED_DESIGNS = 10_000


def _backends():
    from drymount.design import parse_backend

    out = [("serial", parse_backend(1)), ("2 processes", parse_backend(2))]
    try:
        import distributed  # noqa: F401

        out.append(("LocalCluster 2", parse_backend(1, "local:2")))
    except ModuleNotFoundError:
        print("dask.distributed not installed: LocalCluster skipped "
              "(pip install 'drymount[dask]')")
    return out


def _bench(example: str, n: int, chunk: int, tmp: Path) -> None:
    from drymount.config import load_config
    from drymount.design import design_space, explore

    cfg = load_config(ROOT / "examples" / "design" / example)
    space = replace(design_space(cfg), samples=n, chunk=chunk)
    print(f"\n{example}: {n} designs (H = {space.harmonics}, "
          f"{space.band_hz[0]:g}-{space.band_hz[1]:g} Hz), chunks of {chunk}")
    print(f"{'backend':<16}{'wall s':>8}{'designs/s':>11}{'streaming/s':>13}"
          f"{'vs serial':>11}{'10k designs':>13}")
    tables, base = [], None
    for name, backend in _backends():
        out = tmp / f"{example}_{name.replace(' ', '_')}"
        t0 = time.perf_counter()
        res = explore(cfg, space, out, backend, progress=False)
        wall = time.perf_counter() - t0
        rate = n / wall
        base = base or res.rate
        tables.append((out / "designs.csv").read_text())
        hours = PROJECTED_DESIGNS / res.rate / 3600
        print(f"{name:<16}{wall:>8.1f}{rate:>11.2f}{res.rate:>13.2f}"
              f"{res.rate / base:>10.2f}x{hours:>11.2f} h")
    print("identical tables on every backend:", all(t == tables[0] for t in tables))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sdof", type=int, default=96)
    ap.add_argument("--six-dof", type=int, default=16)
    ap.add_argument("--chunk", type=int, default=4)
    args = ap.parse_args()
    print(f"{os.cpu_count()} cores; load average {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        _bench("sdof_n0.toml", args.sdof, args.chunk, Path(tmp))
        _bench("six_dof_layout.toml", args.six_dof, args.chunk, Path(tmp))


if __name__ == "__main__":
    main()
