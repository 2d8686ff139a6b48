"""What a user waits for in each command (issue 27 item 5), as ratios to the yardstick.

Run: ``nice -n 5 python bench/bench_commands.py [--drymount PATH] [--repeat R]
[--only LABEL ...] [--scaling]``

Each case is one fresh ``drymount`` process: its CPU seconds (user + system of the
process and the children it waited for, ``os.wait4``) and its wall seconds, median of
R runs, divided by the yardstick (``bench/yardstick.py``) timed in the same run.
``--drymount`` times another installation's entry point (a checkout of main at
b25b28d in its own venv gave the "before" column of docs/performance.md). The
in-process backend is ``--backend inproc`` (``native`` in installations before the
rename of issue 24; found from ``sweep --help``).

``--scaling`` adds the runs behind the scaling rules of docs/performance.md: the
single-DOF curve at H = 3, 5, 7 (N = 256) and N = 64, 256, 1024 (H = 5), one curve at
H = 5, N = 256 for 1, 2 and 6 DOFs, and stepped sweeps of 10 and 30 points.
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
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from child_env import child_env, compile_bytecode, entry_python  # noqa: E402
from yardstick import yardstick  # noqa: E402


def cases(backend: str) -> list[tuple[str, list[str]]]:
    """(label, drymount arguments) of the table; ``backend`` the in-process one."""
    return [
        ("start-up: drymount --help", ["--help"]),
        ("start-up: presets list", ["presets", "list"]),
        ("single-DOF curve: hbm sdof_halved", ["hbm", "sdof_halved", "-q"]),
        ("quarter car: hbm quarter_car_halved", ["hbm", "quarter_car_halved", "-q"]),
        ("6-DOF default curve: hbm six_dof_halved", ["hbm", "six_dof_halved", "-q"]),
        ("30-point sweep: sweep sdof_halved", ["sweep", "sdof_halved", "--points", "30",
                                              "--backend", backend, "-q"]),
        ("64-design exploration: explore sdof_n0",
         ["explore", str(ROOT / "examples" / "design" / "sdof_n0.toml"), "-q"]),
    ]


def scaling_cases(backend: str) -> list[tuple[str, list[str]]]:
    out = []
    for H in (3, 5, 7):
        out.append((f"sdof curve H={H} N=256", ["hbm", "sdof_halved", "--harmonics",
                                                str(H), "--n-samples", "256", "-q"]))
    for N in (64, 1024):
        out.append((f"sdof curve H=5 N={N}", ["hbm", "sdof_halved", "--harmonics", "5",
                                              "--n-samples", str(N), "-q"]))
    for preset, dofs in (("quarter_car_halved", 2), ("six_dof_halved", 6)):
        out.append((f"{dofs}-DOF curve H=5 N=256", ["hbm", preset, "--harmonics", "5",
                                                    "--n-samples", "256", "-q"]))
    out.append(("sweep 10 points", ["sweep", "sdof_halved", "--points", "10",
                                    "--backend", backend, "-q"]))
    return out


def run_once(exe: str, argv: list[str], cwd: str) -> tuple[float, float, int]:
    """(CPU s, wall s, exit status) of one fresh process."""
    env = child_env()
    out = [] if argv[0].startswith("--") or argv[:2] == ["presets", "list"] else [
        "--out", os.path.join(cwd, "out" if argv[0] == "explore" else "out.csv")]
    t0 = time.perf_counter()
    p = subprocess.Popen([exe, *argv, *out], cwd=cwd, env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    return ru.ru_utime + ru.ru_stime, time.perf_counter() - t0, status


def inproc_name(exe: str) -> str:
    text = subprocess.run([exe, "sweep", "--help"], capture_output=True,
                          text=True).stdout
    return "inproc" if "inproc" in text else "native"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--drymount", default=shutil.which("drymount"))
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--only", nargs="*", default=None,
                    help="labels (substrings) of the cases to run")
    ap.add_argument("--scaling", action="store_true")
    args = ap.parse_args()
    compile_bytecode(entry_python(args.drymount))  # as installed by pip
    backend = inproc_name(args.drymount)
    todo = cases(backend) + (scaling_cases(backend) if args.scaling else [])
    if args.only:
        todo = [c for c in todo if any(s in c[0] for s in args.only)]
    ys = yardstick()
    print(f"yardstick {ys:.3f} s; {args.drymount}; median of {args.repeat}")
    print(f"{'command':44s}{'CPU s':>9s}{'wall s':>9s}{'CPU/ys':>9s}{'wall/ys':>9s}")
    with tempfile.TemporaryDirectory() as cwd:
        for label, argv in todo:
            runs = [run_once(args.drymount, argv, cwd) for _ in range(args.repeat)]
            cpu = statistics.median(r[0] for r in runs)
            wall = statistics.median(r[1] for r in runs)
            bad = [r[2] for r in runs if r[2] != 0]
            note = f"  exit status {bad[0]}" if bad else ""
            print(f"{label:44s}{cpu:9.2f}{wall:9.2f}{cpu / ys:9.3f}{wall / ys:9.3f}"
                  f"{note}", flush=True)


if __name__ == "__main__":
    main()
