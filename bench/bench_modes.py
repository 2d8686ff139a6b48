"""Benchmark of the nonlinear modes (issue 29): the cost of ``drymount modes CONFIG
--mode all`` (all six modes of a 6-DOF preset, EPMC continuation in amplitude) as a
ratio to ``drymount hbm CONFIG`` (one frequency-response curve with its stability,
events and error estimates) at the same H and N. Issue 29's target: ratio <= 2.

Both commands run in this process through ``drymount.cli.main`` (imports and the
first call's compilation are warmed up once before timing); outputs go to a
temporary folder. Prints each time (best of ``--repeat``) and the ratio.

Run: ``python bench/bench_modes.py [--config six_dof_halved] [-H 5] [--n-samples 64]
[--repeat 1]``
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time


def _parse():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="six_dof_halved")
    ap.add_argument("-H", "--harmonics", type=int, default=5,
                    help="H of both runs (six_dof_halved's [hbm] harmonics: 5)")
    ap.add_argument("--n-samples", type=int, default=64,
                    help="AFT samples of both runs (the default for H = 5: 64)")
    ap.add_argument("--repeat", type=int, default=1)
    return ap.parse_args()


def _time(argv, repeat: int) -> float:
    from drymount import cli

    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        code = cli.main(argv)
        best = min(best, time.perf_counter() - t0)
        if code != 0:
            raise SystemExit(f"`drymount {' '.join(argv)}` exited {code}")
    return best


def main() -> None:
    args = _parse()
    os.environ.setdefault("DRYMOUNT_THREADS", "1")
    hn = ["--harmonics", str(args.harmonics), "--n-samples", str(args.n_samples)]
    with tempfile.TemporaryDirectory() as tmp:
        modes = ["modes", args.config, "--mode", "all", *hn, "--out",
                 os.path.join(tmp, "modes.csv")]
        hbm = ["hbm", args.config, *hn, "--quiet", "--out",
               os.path.join(tmp, "hbm.csv")]
        # warm-up: imports, the compiled march, BLAS
        _time(["modes", args.config, "--mode", "1", "-H", "1", "--out",
               os.path.join(tmp, "w.csv")], 1)
        t_hbm = _time(hbm, args.repeat)
        t_modes = _time(modes, args.repeat)
    print(f"{args.config}, H = {args.harmonics}, N = {args.n_samples}:")
    print(f"  drymount hbm               {t_hbm:8.2f} s")
    print(f"  drymount modes --mode all  {t_modes:8.2f} s")
    print(f"  ratio modes / hbm          {t_modes / t_hbm:8.2f}  (target <= 2)")


if __name__ == "__main__":
    main()
