"""Benchmark of issue 27 item 3: the 6-DOF harmonic-balance curve.

Prints, each as a ratio to the yardstick of :mod:`bench.yardstick` timed in the same
run (before and after the curves; the median of those timings):

1. ``drymount hbm six_dof_halved --harmonics 7 --n-samples 1024``: wall time per CSV
   row in yardsticks (target <= 0.008), and the same in process time (the child's CPU
   over the yardstick's CPU: steadier on a loaded machine).
2. The default ``drymount hbm six_dof_halved`` (adaptive: H 5 -> 13, N 64 -> 1024):
   its wall and CPU time in yardsticks, and how many times cheaper in CPU it is than
   the same command of the code the issue measured, commit :data:`ORIGINAL`, run in
   the same run from a ``git archive`` of it (target: 3x cheaper). Until 2026-12-03
   this figure was the ratio to a stored figure, :data:`BEFORE_DEFAULT_CPU`
   yardsticks (b25b28d's 39.5 s CPU, 484 rows, timed once on 2 cores under a load
   of 12); the original measured in the same run costs 55-61 yardsticks on this
   machine, so that ratio overstated the gain by 1.2-1.3x (docs/performance.md, "The
   6-DOF curve, seventh pass"). It is printed second, for the record. Figure 1
   before: 0.052-0.056 yardsticks of CPU per row (531 rows), after 0.036-0.038 (527
   rows); figure 3 before 9.9x, after 7.9-9.1x (docs/performance.md, "The 6-DOF
   curve").
3. One Newton iteration on the 6-DOF problem at H = 7, N = 1024 (a converged point at
   9.5 Hz, perturbed by 1e-6 and corrected at fixed frequency; process time of
   :func:`hbm.continuation.newton`, less its first evaluation, over its iterations)
   against its floor: the
   compiled (else vectorised) Jenkins march of the sampled motion plus one dense solve
   of the bordered (n + 1) system (target: within 5x).

The original's tree is extracted once into the temporary folder
(``drymount-bench-<commit>``; Python and numba cache beside its sources) and run
through :mod:`bench.tree_import`, its numba cache warmed first. Every timed process
has Python's bytecode caches, written by a short curve before the timing, for this
code and the original alike (:mod:`bench.child_env`). ``--baseline TREE``
(another checkout, e.g. ``git archive main | tar -x -C /tmp/main_tree``) runs the
default curve from that tree as well, for a change against main.

Run: ``python bench/bench_hbm_six_dof.py [--skip-default] [--repeat 3]
[--baseline TREE]``
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from child_env import child_env  # noqa: E402
from yardstick import time_once  # noqa: E402

#: The code issue 27 measured (its figure 2 is against this commit's default curve)
ORIGINAL = "b25b28d"
#: The stored figure figure 2 was once against, in yardsticks of CPU (see 2.)
BEFORE_DEFAULT_CPU = 71.7
TARGET_ROW = 0.008
TARGET_SPEEDUP = 3.0
TARGET_NEWTON = 5.0
#: A short curve run before the timed ones: it writes the bytecode caches (and numba's)
#: of the modules a curve imports, as a user's installation has them
#: (bench/child_env.py)
WARM_CURVE = ["six_dof_halved", "--harmonics", "3", "--n-samples", "64", "--fmax", "6"]


def _yardstick_times(repeat: int) -> tuple[list[float], list[float]]:
    """Wall and CPU times of ``repeat`` yardstick runs."""
    wall, cpu = [], []
    for _ in range(repeat):
        c0, w0 = time.process_time(), time.perf_counter()
        time_once()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return wall, cpu


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run_curve(args: list[str], tree: str | None = None) -> tuple[float, float, int]:
    """Wall time, CPU time and CSV rows of ``drymount hbm ARGS`` in a child (from the
    checkout ``tree`` if given)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "curve.csv"
        if tree is None:
            cmd = [sys.executable, "-c", "import sys; from drymount.cli import main; "
                   "sys.exit(main())"]
        else:
            cmd = [sys.executable, str(Path(__file__).parent / "tree_import.py"), tree]
        cmd += ["hbm", *args, "--quiet", "--out", str(out)]
        c0, w0 = _child_cpu(), time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env=child_env())
        wall, cpu = time.perf_counter() - w0, _child_cpu() - c0
        lines = [ln for ln in out.read_text().splitlines()
                 if ln and not ln.startswith("#")]
    return wall, cpu, len(lines) - 1  # minus the header


def _original_tree() -> str | None:
    """A ``git archive`` of :data:`ORIGINAL` in the temporary folder (extracted once,
    then reused), or None where this is no git checkout holding that commit."""
    repo = Path(__file__).resolve().parents[1]
    tree = Path(tempfile.gettempdir()) / f"drymount-bench-{ORIGINAL}"
    if (tree / "pyproject.toml").is_file():
        return str(tree)
    tmp = Path(tempfile.mkdtemp(prefix=f"drymount-bench-{ORIGINAL}-"))
    try:
        archive = subprocess.run(["git", "-C", str(repo), "archive", ORIGINAL],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(tmp)], input=archive, check=True)
        tmp.rename(tree)
    except (OSError, subprocess.CalledProcessError) as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if (tree / "pyproject.toml").is_file():  # another run extracted it meanwhile
            return str(tree)
        print(f"no tree of {ORIGINAL} ({exc}): figure 2 only against the stored "
              f"figure")
        return None
    return str(tree)


def _warm_tree(tree: str) -> None:
    """Compile ``tree``'s numba kernels (cached beside its sources) by its ``warm()``
    where it has one, then run :data:`WARM_CURVE` from it, which writes the bytecode
    caches of what a curve imports (and, in older trees without ``warm()``, e.g.
    b25b28d, the original of figure 2, compiles the same numba signatures)."""
    probe = subprocess.run(
        [sys.executable, "-c", "import sys; sys.path.insert(0, "
         f"{str(Path(__file__).parent)!r}); import tree_import; "
         f"tree_import.use_tree({tree!r}); import "
         "drymount.hbm.friction_march_numba as m; "
         "sys.exit(0 if hasattr(m, 'warm') and m.warm() is None else 3)"],
        env=child_env())
    if probe.returncode not in (0, 3):
        raise RuntimeError(f"the baseline tree {tree} does not import "
                           f"(exit status {probe.returncode})")
    _run_curve(WARM_CURVE, tree)


def _cpu_per_call(fn, n: int) -> float:
    fn()
    t0 = time.process_time()
    for _ in range(n):
        fn()
    return (time.process_time() - t0) / n


def newton_vs_floor(n_calls: int = 20) -> tuple[float, float]:
    """Process time of one Newton iteration and of its floor, s (see 3.)."""
    from drymount.config.loading import load_preset
    from drymount.hbm.continuation import newton
    from drymount.hbm.friction_march import jenkins_march
    from drymount.hbm.options import HBMOptions
    from drymount.hbm.problem import build_problem

    prob = build_problem(load_preset("six_dof_halved").system, 2.0, 25.0, 7, 1024)
    settings = HBMOptions().continuation_settings()
    n = prob.hb.size
    y0 = prob.linear_guess(9.5, stuck=False)
    y, ok, _, msg = newton(prob, y0, settings, fixed=n)
    if not ok:
        raise RuntimeError(f"no solution at 9.5 Hz: {msg}")
    rng = np.random.default_rng(0)
    y_start = y + 1e-6 * rng.standard_normal(y.size) * np.abs(y).max()
    y_start[-1] = y[-1]
    its = newton(prob, y_start, settings, fixed=n).n_iter
    # an iteration: the solve, the evaluation at the new iterate, the tests; the
    # evaluation at the start (before the first iteration) is not one
    # (the problem hands out its last evaluation again without computing it: forget
    # it, so that this is the evaluation Newton's first call pays)
    def first_evaluation():
        prob._last = None
        return prob(y_start)

    t_eval = _cpu_per_call(first_evaluation, n_calls)
    t_newton = (_cpu_per_call(lambda: newton(prob, y_start, settings, fixed=n),
                              n_calls) - t_eval) / max(its, 1)
    hb = prob.hb
    X, _ = prob.x_of(y)
    u = hb.basis.E @ hb.axis_coefficients(X)
    ax, fr = hb.axes, hb.axes.friction
    kf, fs, w0 = ax.kf[fr], ax.fs[fr], ax.w_start[fr].astype(float)
    uf = np.ascontiguousarray(u[:, fr])
    R, J = prob(y)
    A = np.vstack([J[:, :-1], np.ones((1, n))])
    A = np.hstack([A, np.append(J[:, -1], 1.0)[:, None]])
    b = np.append(-R, 0.0)
    # the floor's march: numba's where installed (as in the earlier passes; its
    # call has less Python than the unbound C wrapper), else the default
    from drymount.hbm.friction_march import _HAVE_NUMBA
    floor = "numba" if _HAVE_NUMBA else None
    t_floor = (_cpu_per_call(lambda: jenkins_march(uf, kf, fs, w0, backend=floor),
                             10 * n_calls)
               + _cpu_per_call(lambda: np.linalg.solve(A, b), 10 * n_calls))
    return t_newton, t_floor


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="yardstick timings")
    ap.add_argument("--skip-default", action="store_true",
                    help="skip the default curve (minutes on a loaded machine)")
    ap.add_argument("--baseline", metavar="TREE",
                    help="also run the default curve from this checkout (e.g. main)")
    args = ap.parse_args(argv)
    original = None if args.skip_default else _original_tree()
    _run_curve(WARM_CURVE)  # this code's caches, as for the trees below
    for tree in (original, args.baseline):
        if tree:
            _warm_tree(tree)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    wall_y, cpu_y = _yardstick_times(args.repeat)
    t_newton, t_floor = newton_vs_floor()
    w7, c7, rows7 = _run_curve(["six_dof_halved", "--harmonics", "7",
                                "--n-samples", "1024"])
    default = None if args.skip_default else _run_curve(["six_dof_halved"])
    orig = None if original is None else _run_curve(["six_dof_halved"], original)
    base = None if args.skip_default or not args.baseline else \
        _run_curve(["six_dof_halved"], args.baseline)
    w2, c2 = _yardstick_times(args.repeat)
    ys_wall, ys_cpu = float(np.median(wall_y + w2)), float(np.median(cpu_y + c2))
    print(f"yardstick: {ys_wall:.3f} s wall, {ys_cpu:.3f} s CPU "
          f"(median of {2 * args.repeat})")
    print(f"1. H = 7, N = 1024: {rows7} rows, {w7:.1f} s wall, {c7:.1f} s CPU; per "
          f"row {w7 / rows7 / ys_wall:.4f} yardsticks wall, "
          f"{c7 / rows7 / ys_cpu:.4f} CPU (target <= {TARGET_ROW})")
    if default is not None:
        wd, cd, rowsd = default
        ratio = BEFORE_DEFAULT_CPU / (cd / ys_cpu)
        print(f"2. default curve: {rowsd} rows, {wd:.1f} s wall, {cd:.1f} s CPU = "
              f"{wd / ys_wall:.1f} yardsticks wall, {cd / ys_cpu:.1f} CPU")
        if orig is not None:
            wo, co, rowso = orig
            print(f"   the original ({ORIGINAL}) in this run: {rowso} rows, "
                  f"{co:.1f} s CPU = {co / ys_cpu:.1f} yardsticks; this code "
                  f"{co / cd:.2f}x cheaper in CPU, {wo / wd:.2f}x in wall (target >= "
                  f"{TARGET_SPEEDUP}x)")
        print(f"   against the stored figure ({BEFORE_DEFAULT_CPU:.1f} yardsticks, "
              f"load 12): {ratio:.2f}x (not a ratio of one run: for the record)")
        if base is not None:
            wb, cb, rowsb = base
            print(f"   baseline {args.baseline}: {rowsb} rows, {wb:.1f} s wall, "
                  f"{cb:.1f} s CPU = {cb / ys_cpu:.1f} yardsticks CPU; this tree "
                  f"{cb / cd:.2f}x cheaper in CPU ({wb / wd:.2f}x in wall)")
    print(f"3. Newton iteration (H = 7, N = 1024, 90 unknowns): "
          f"{1e6 * t_newton:.0f} us, floor (march + dense solve) {1e6 * t_floor:.0f} "
          f"us: {t_newton / t_floor:.1f}x the floor (target <= {TARGET_NEWTON}x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
