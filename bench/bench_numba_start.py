"""Does the ``fast`` extra (numba) ever make a fresh process slower? (issue 27 item 2)

Run: ``nice -n 5 python bench/bench_numba_start.py [--repeat R]``

Each case is a fresh ``drymount hbm`` process (CPU seconds of the process and the
children it waited for, ``os.wait4``, and wall seconds; median of R runs), with the
Jenkins march chosen by ``$DRYMOUNT_MARCH``:

- ``numpy``: what an install without the ``fast`` extra runs;
- ``auto``: the default with numba installed (``hbm.march_choice``: NumPy until numba's
  start pays, numba then);
- ``numba``: numba from the first call (the default before issue 27).

``auto`` should never cost more than ``numpy`` (beyond noise) and approach ``numba`` on
long runs. With ``--cold`` each ``auto``/``numba`` run also gets an empty
``$NUMBA_CACHE_DIR`` (a new machine): ``numba`` then compiles in the foreground,
``auto`` in one detached background process (not counted in its CPU time, shown in the
wall time only when it competes for the cores). Ratios are to the yardstick
(``bench/yardstick.py``) timed in the same run.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from child_env import child_env, compile_bytecode, entry_python  # noqa: E402
from yardstick import yardstick  # noqa: E402

#: (label, drymount arguments)
CASES = [
    ("sdof_halved H=3 N=64 (small)", ["hbm", "sdof_halved", "--harmonics", "3",
                                      "--n-samples", "64"]),
    ("sdof_halved H=5 N=1024", ["hbm", "sdof_halved", "--harmonics", "5",
                                "--n-samples", "1024"]),
    ("sdof_halved default (tol)", ["hbm", "sdof_halved"]),
    ("quarter_car_halved default", ["hbm", "quarter_car_halved"]),
]
MARCHES = ("numpy", "auto", "numba")


def run_once(argv, march: str, cwd: str, cache: str | None) -> tuple[float, float]:
    """(CPU s, wall s) of one fresh ``drymount`` process."""
    env = child_env(DRYMOUNT_MARCH=march)
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = cache
    t0 = time.perf_counter()
    p = subprocess.Popen([shutil.which("drymount"), *argv, "-q", "--out",
                          os.path.join(cwd, "c.csv")], cwd=cwd, env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise SystemExit(f"drymount {' '.join(argv)} failed ({status})")
    return ru.ru_utime + ru.ru_stime, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=None,
                    help="labels (substrings) of the cases to run")
    ap.add_argument("--cold", action="store_true",
                    help="an empty numba cache for every auto/numba run")
    args = ap.parse_args()
    compile_bytecode(entry_python(shutil.which("drymount")))  # as pip installs
    ys = yardstick()
    print(f"yardstick {ys:.3f} s; CPU s (wall s) of a fresh process, median of "
          f"{args.repeat}; {'cold' if args.cold else 'warm'} numba cache")
    print(f"{'case':32s}" + "".join(f"{m:>22s}" for m in MARCHES)
          + f"{'auto/numpy':>12s}{'auto/ys':>9s}")
    with tempfile.TemporaryDirectory() as cwd:
        todo = [c for c in CASES
                if not args.only or any(o in c[0] for o in args.only)]
        for label, argv in todo:
            med = {}
            for march in MARCHES:
                runs = []
                for _ in range(args.repeat):
                    cache = (tempfile.mkdtemp(dir=cwd)
                             if args.cold and march != "numpy" else None)
                    runs.append(run_once(argv, march, cwd, cache))
                med[march] = (statistics.median(r[0] for r in runs),
                              statistics.median(r[1] for r in runs))
            cells = "".join(f"{c:>13.2f} ({w:5.2f})" for c, w in med.values())
            print(f"{label:32s}{cells}{med['auto'][0] / med['numpy'][0]:12.2f}"
                  f"{med['auto'][0] / ys:9.2f}")


if __name__ == "__main__":
    main()
