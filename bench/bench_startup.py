"""Start-up cost of the command line (issue 27 item 1): CPU seconds of a fresh process.

Run: ``nice -n 5 python bench/bench_startup.py [--repeat R] [--drymount PATH]``

For each case, the user + system CPU time of a fresh ``drymount ...`` process (the
process and its children, ``os.wait4``), median of R runs, and its ratio to the
yardstick (``bench/yardstick.py``) timed in the same run. Target: every case within
0.3 s CPU. ``--drymount`` times another installation's entry point (e.g. a checkout
of main in its own venv) for a before/after table.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from child_env import child_env, compile_bytecode, entry_python  # noqa: E402
from yardstick import yardstick  # noqa: E402

#: (label, argv): the cases of the issue, each a fresh process.
CASES = [
    ("drymount --help", ["--help"]),
    ("drymount --version", ["--version"]),
    ("presets list", ["presets", "list"]),
    ("hbm --help", ["hbm", "--help"]),
    ("sweep --help", ["sweep", "--help"]),
    ("explore --help", ["explore", "--help"]),
    ("usage error: --harmonics 0", ["hbm", "sdof_halved", "--harmonics", "0"]),
    ("usage error: unknown option", ["sweep", "sdof_halved", "--bogus"]),
    ("config error: no such preset", ["hbm", "sdof_halvd"]),
    ("config error: a bad --set value", ["hbm", "sdof_halved", "--set",
                                         "mount.k1=-1"]),
    ("usage error: --out a directory", ["sweep", "sdof_halved", "--out", "."]),
]
LIMIT_S = 0.3


def cpu_seconds(cmd: list[str], cwd: str) -> float:
    """User + system CPU seconds of one run of ``cmd`` (children included)."""
    env = child_env()
    p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    _, _, ru = os.wait4(p.pid, 0)
    return ru.ru_utime + ru.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--drymount", default=shutil.which("drymount"),
                    help="the drymount entry point to time (default: on PATH)")
    args = ap.parse_args()
    compile_bytecode(entry_python(args.drymount))  # as installed by pip
    ys = yardstick()
    print(f"yardstick {ys:.3f} s; {args.drymount}; median of {args.repeat} runs")
    print(f"{'case':34s} {'CPU s':>7s} {'/ yardstick':>12s}  within {LIMIT_S} s")
    with tempfile.TemporaryDirectory() as cwd:
        for label, argv in CASES:
            runs = [cpu_seconds([args.drymount, *argv], cwd)
                    for _ in range(args.repeat)]
            t = statistics.median(runs)
            print(f"{label:34s} {t:7.3f} {t / ys:12.3f}  "
                  f"{'yes' if t <= LIMIT_S else 'NO'}")


if __name__ == "__main__":
    main()
