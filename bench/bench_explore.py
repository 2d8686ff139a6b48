"""Benchmark of ``drymount explore`` backends (issue 16): designs per second.

The same exploration (``examples/design/sdof_n0.toml``: single DOF, H = 1, 1-200 Hz,
two objectives and a constraint, ``--designs`` Latin-hypercube designs) runs

- serially, in this process;
- on 2 local processes (``--workers 2``, spawn);
- on a 2-worker Dask LocalCluster (``--dask local:2``), if dask.distributed is
  installed;

each timed from the call to the finished table (pool / cluster start-up included, as
a user sees it) and again without start-up (the rate while designs stream). Prints
designs per second, the speed-up against serial measured in the same run, checks that
every backend wrote the same table, and projects the time of 10,000 designs of this
kind and of the 6-DOF layout study (one 6-DOF H = 1 curve is timed here too).

Run: ``python bench/bench_explore.py [--designs 96] [--chunk 8]``
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


def _run(cfg, space, backend, out: Path) -> tuple[float, float]:
    """(wall seconds including start-up, designs/s while streaming)."""
    from drymount.design import explore

    t0 = time.perf_counter()
    res = explore(cfg, space, out, backend, progress=False)
    wall = time.perf_counter() - t0
    return wall, res.rate


def _six_dof_seconds() -> float:
    import hbm
    from drymount.config import load_config

    cfg = load_config(ROOT / "examples" / "design" / "six_dof_layout.toml")
    t0 = time.perf_counter()
    hbm.frequency_response(cfg.system, 2.0, 25.0, harmonics=1)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=96)
    ap.add_argument("--chunk", type=int, default=8)
    args = ap.parse_args()
    from drymount.config import load_config
    from drymount.design import design_space, parse_backend

    cfg = load_config(ROOT / "examples" / "design" / "sdof_n0.toml")
    space = replace(design_space(cfg), samples=args.designs, chunk=args.chunk)
    backends = [("serial", parse_backend(1)), ("2 processes", parse_backend(2))]
    try:
        import distributed  # noqa: F401

        backends.append(("LocalCluster 2", parse_backend(1, "local:2")))
    except ModuleNotFoundError:
        print("dask.distributed not installed: LocalCluster skipped "
              "(pip install 'drymount[dask]')")
    print(f"{args.designs} single-DOF designs (H = 1, 1-200 Hz), chunks of "
          f"{args.chunk}, on {os.cpu_count()} cores")
    print(f"{'backend':<16}{'wall s':>9}{'designs/s':>11}{'streaming/s':>13}"
          f"{'vs serial':>11}{'10k designs':>13}")
    tables, base = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for name, backend in backends:
            out = Path(tmp) / name.replace(" ", "_")
            wall, stream = _run(cfg, space, backend, out)
            rate = args.designs / wall
            base = base or rate
            tables.append((out / "designs.csv").read_text())
            print(f"{name:<16}{wall:>9.2f}{rate:>11.1f}{stream:>13.1f}"
                  f"{rate / base:>10.2f}x{PROJECTED_DESIGNS / stream / 60:>11.1f} min")
    print("identical tables on every backend:", all(t == tables[0] for t in tables))
    t6 = _six_dof_seconds()
    print(f"one 6-DOF layout design (H = 1, 2-25 Hz): {t6:.2f} s; 10,000 of them: "
          f"{PROJECTED_DESIGNS * t6 / 3600:.1f} h serial, "
          f"{PROJECTED_DESIGNS * t6 / 3600 / 2:.1f} h on 2 workers, "
          f"{PROJECTED_DESIGNS * t6 / 3600 / 64:.2f} h on 64 cluster cores "
          f"(linear scaling, the designs are independent)")


if __name__ == "__main__":
    main()
