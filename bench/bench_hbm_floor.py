"""The floor of ``drymount hbm six_dof_halved --harmonics 7 --n-samples 1024``.

Issue 27 item 3 asks for at most 0.008 yardsticks of wall time per CSV row of this
curve with every number unchanged. This bench measures how low *any* implementation
that computes the same points could go: the numerical kernels the curve cannot do
without, each timed alone on the curve's own arrays and multiplied by how often the
run calls it, with no Python around them at all:

- the start: a fresh interpreter importing NumPy (the BLAS whose products must stay
  bit for bit) and ``scipy.sparse.linalg`` (ARPACK, for Hill's stability),
- per residual evaluation (counted in the run by resolution: the curve's H = 7,
  N = 1024 and the error estimate's references, each timed at its own resolution):
  the products and passes of
  :meth:`hbm.residual.HarmonicBalance.residual` and of the problem's scaling, into kept
  buffers, and the two C kernels of the AFT (samples, slip memory),
- the dense solves of Newton's corrector and of the tangent (counted by shape, timed
  on a matrix of that shape),
- ARPACK's own calls (``dnaupd``/``dneupd``, timed in the run), the LU factors and
  solves of Hill's operator and its products (counted, timed alone).

Each kernel timed alone finds its arrays in cache, which the run's kernels, one after
another, do not: one more reason the sum is a lower bound.

What is left out (the continuation's logic, the events' bookkeeping, the options,
the CSV and its header) only raises the real figure, so the sum is a lower bound.
It prints the floor and the run's own wall time, each per CSV row in yardsticks
(:mod:`bench.yardstick`, timed in the same run).

Run: ``python bench/bench_hbm_floor.py [--repeat 3]``
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import os
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from yardstick import time_once  # noqa: E402

HBM_ARGS = ["hbm", "six_dof_halved", "--harmonics", "7", "--n-samples", "1024"]
TARGET_ROW = 0.008


def _best(fn, n: int = 200, rounds: int = 5) -> float:
    """Smallest mean wall time of ``fn()`` over ``rounds`` batches of ``n`` calls, s."""
    fn()
    return min(timeit.repeat(fn, number=n, repeat=rounds)) / n


def start_time(repeat: int = 5) -> float:
    """Median wall time of a fresh interpreter importing NumPy and ARPACK's SciPy, s."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import numpy, scipy.sparse.linalg"],
                       check=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


class _Counting:
    """A module stand-in forwarding every attribute, counting the calls of
    ``names`` by the shape of their first argument."""

    def __init__(self, module, names):
        self._module, self.calls = module, collections.Counter()
        for name in names:
            setattr(self, name, self._wrap(name, getattr(module, name)))

    def _wrap(self, name, fn):
        def counted(a, *args, **kwargs):
            self.calls[(name, np.shape(a))] += 1
            return fn(a, *args, **kwargs)
        return counted

    def __getattr__(self, name):
        return getattr(self._module, name)


class RunCounts:
    """What one in-process run of the curve called: evaluations, solves by shape,
    LAPACK calls of the continuation and of Hill's operator by shape, ARPACK's own
    time and the CSV rows."""

    def __init__(self):
        self.n_eval = collections.Counter()   # by (H, N)
        self.n_matvec = 0
        self.solves = collections.Counter()
        self.lapack = collections.Counter()
        self.arpack_s = 0.0
        self.rows = 0


def count_run() -> RunCounts:
    """Run the curve in this process with counters on its kernels' entry points."""
    from scipy.sparse.linalg._eigen.arpack import _arpacklib

    from drymount.cli import main
    from drymount.hbm import continuation, hill_arnoldi, problem

    rc = RunCounts()
    evaluate = problem._Problem._evaluate
    solve = np.linalg.solve
    matvec = hill_arnoldi._InverseHill.matvec

    def counted_evaluate(self, y):
        rc.n_eval[(self.hb.H, self.hb.basis.N)] += 1
        return evaluate(self, y)

    def counted_matvec(self, v):
        rc.n_matvec += 1
        return matvec(self, v)

    def counted_solve(a, b):
        rc.solves[np.shape(a)] += 1
        return solve(a, b)

    def timed(fn):
        def run(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                rc.arpack_s += time.perf_counter() - t0
        return run

    lap_c = _Counting(continuation.lapack, ["dgesv"])
    lap_h = _Counting(hill_arnoldi.lapack, ["dgetrf", "dgetrs"])
    saved = {name: getattr(_arpacklib, name) for name in ("dnaupd_wrap", "dneupd_wrap")}
    problem._Problem._evaluate = counted_evaluate
    hill_arnoldi._InverseHill.matvec = hill_arnoldi._InverseHill._matvec = \
        counted_matvec
    np.linalg.solve = counted_solve
    continuation.lapack, hill_arnoldi.lapack = lap_c, lap_h
    for name, fn in saved.items():
        setattr(_arpacklib, name, timed(fn))
    try:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "curve.csv"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                main([*HBM_ARGS, "--quiet", "--out", str(out)])
            rc.rows = sum(1 for ln in out.read_text().splitlines()
                          if ln and not ln.startswith("#")) - 1
    finally:
        problem._Problem._evaluate = evaluate
        hill_arnoldi._InverseHill.matvec = hill_arnoldi._InverseHill._matvec = matvec
        np.linalg.solve = solve
        continuation.lapack, hill_arnoldi.lapack = lap_c._module, lap_h._module
        for name, fn in saved.items():
            setattr(_arpacklib, name, fn)
    rc.lapack = lap_c.calls + lap_h.calls
    return rc


def converged_point(H: int = 7, N: int = 1024):
    """The scaled problem of the curve (or of its error estimate's reference
    resolution) and a converged point of it at 9.5 Hz."""
    from drymount.config.loading import load_preset
    from drymount.hbm.continuation import newton
    from drymount.hbm.options import HBMOptions
    from drymount.hbm.problem import build_problem

    prob = build_problem(load_preset("six_dof_halved").system, 2.0, 25.0, H, N)
    settings = HBMOptions().continuation_settings()
    y, ok, _, msg = newton(prob, prob.linear_guess(9.5, stuck=False), settings,
                           fixed=prob.hb.size)
    if not ok:
        raise RuntimeError(f"no solution at 9.5 Hz: {msg}")
    return prob, y


def evaluation_kernels(prob, y) -> dict[str, float]:
    """Wall time of each kernel of one residual evaluation with its Jacobian at ``y``,
    alone, into kept buffers, s. An elementwise pass over a matrix is timed as one
    NumPy operation over it (a compiled residual would fuse the passes NumPy makes
    one by one; it must still stream each matrix once)."""
    from drymount.hbm import aft_native
    from drymount.hbm.aft import _plan

    hb = prob.hb
    X, w = prob.x_of(y)
    m, n, na, N = hb.m, hb.n, hb.axes.n, hb.basis.N
    E, P = hb.basis.E, hb.basis.P
    hb.basis.gram(np.zeros((N, na)))   # builds the two maps of the harmonic form
    E2t, G = hb.basis._gram
    kern = aft_native.bound(_plan(hb.axes), hb.basis, 1, na)
    size = hb.size
    A, T = np.empty((size, size)), np.empty((size, size))
    Jy = np.empty((size, size + 1))
    U = hb.axis_coefficients(X)
    u = kern.u.reshape(N, na)
    np.matmul(E, U, out=u)
    kern.lib.dm_aft_samples(*kern._samples)
    f, kt = kern.f.reshape(N, na), kern.kt.reshape(N, na)
    F = P @ f
    sums = np.swapaxes(E2t @ kt, -1, -2)
    dF = np.ascontiguousarray((sums @ G).reshape(na, m, m))
    dFt = np.ascontiguousarray(dF.transpose(1, 2, 0)).reshape(m * m, na)
    BB = hb.BB.reshape(na, n * n)
    prod = np.dot(dFt, BB).reshape(m, m, n, n).transpose(0, 2, 1, 3)
    Jv = A.reshape(m, n, m, n)
    slip = kern._slip
    ptr = aft_native._ptr(dF)
    Xr = X.reshape(m, n)
    return {
        "linear matrix (1 pass)": _best(lambda: np.add(hb.A0, hb.A1, out=A)),
        "A @ X": _best(lambda: A @ X),
        "axis coefficients": _best(lambda: Xr @ hb.Bt.T),
        "E @ U": _best(lambda: np.matmul(E, U, out=u)),
        "C samples": _best(lambda: kern.lib.dm_aft_samples(*kern._samples)),
        "P @ f": _best(lambda: P @ f),
        "gram: E2^T kt": _best(lambda: E2t @ kt),
        "gram: sums G": _best(lambda: sums @ G),
        "C slip memory": _best(lambda: kern.lib.dm_slip_memory(*slip[:5], ptr,
                                                                *slip[5:])),
        "F @ B": _best(lambda: F @ hb.Bt),
        "dF transposed copy": _best(lambda: np.ascontiguousarray(
            dF.transpose(1, 2, 0))),
        "dF^T BB": _best(lambda: np.dot(dFt, BB)),
        "J += (strided add)": _best(lambda: np.add(Jv, prod, out=Jv)),
        "dR/domega (1 pass + gemv)": _best(lambda: (np.add(hb.A1, hb.A2, out=T),
                                                    T @ X)),
        "scaling (1 pass)": _best(lambda: np.multiply(A, prob.xs, out=Jy[:, :-1])),
    }


def solve_times(shapes) -> dict[tuple, float]:
    """Wall time of one ``np.linalg.solve`` per matrix shape, s."""
    rng = np.random.default_rng(1)
    out = {}
    for shape in shapes:
        a = rng.standard_normal(shape) + shape[0] * np.eye(shape[0])
        b = rng.standard_normal(shape[0])
        out[shape] = _best(lambda a=a, b=b: np.linalg.solve(a, b))
    return out


def lapack_times(keys) -> dict[tuple, float]:
    """Wall time of one LAPACK call (dgesv, dgetrf, dgetrs) per name and shape, s."""
    from scipy.linalg import lapack

    rng = np.random.default_rng(2)
    out = {}
    for name, shape in keys:
        k = shape[0]
        a = rng.standard_normal((k, k)) + k * np.eye(k)
        if name == "dgetrs":
            lu, piv, _ = lapack.dgetrf(a)
            b = rng.standard_normal(k)
            out[(name, shape)] = _best(lambda lu=lu, piv=piv, b=b:
                                       lapack.dgetrs(lu, piv, b))
        elif name == "dgesv":
            b = rng.standard_normal(k)
            out[(name, shape)] = _best(lambda a=a, b=b: lapack.dgesv(a, b))
        else:
            out[(name, shape)] = _best(lambda a=a: lapack.dgetrf(a))
    return out


def yardstick(repeat: int) -> float:
    return statistics.median(time_once().total_s for _ in range(repeat))


def command_wall(repeat: int = 3) -> float:
    """Median wall time of the curve's command in a fresh process, s."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", "import sys; from drymount.cli "
                            "import main; sys.exit(main())", *HBM_ARGS, "--quiet",
                            "--out", str(Path(tmp) / "c.csv")], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


def floor_parts(rc: RunCounts, t_start: float) -> tuple[dict[str, float], list[str]]:
    """The floor's parts, s, and a line per resolution on its evaluation's kernels."""
    lines, t_evals, n_evals, size = [], 0.0, 0, 0
    for (H, N), count in sorted(rc.n_eval.items()):
        prob, y = converged_point(H, N)
        if (H, N) == (7, 1024):   # the curve's own: the one Hill's operator is of
            size = prob.hb.size
        kern = evaluation_kernels(prob, y)
        per_eval = sum(kern.values())
        t_eval = _best(lambda prob=prob, y=y: (setattr(prob, "_last", None),
                                               prob(y)), n=50)
        t_evals += count * per_eval
        n_evals += count
        lines.append(f"H = {H}, N = {N}: {count} evaluations; one costs "
                     f"{1e6 * t_eval:.0f} us as the problem makes it, "
                     f"{t_eval / per_eval:.2f}x its kernels ({1e6 * per_eval:.0f} us: "
                     + ", ".join(f"{k} {1e6 * v:.1f}" for k, v in kern.items()) + ")")
    t_solve = solve_times(rc.solves)
    t_lap = lapack_times(rc.lapack)
    B, v = np.ones((size, 2 * size)), np.ones(2 * size)
    parts = {
        "start (interpreter, NumPy, scipy.sparse.linalg)": t_start,
        f"{n_evals} evaluations' kernels": t_evals,
        f"{sum(rc.solves.values())} dense solves (Newton)":
            sum(c * t_solve[s] for s, c in rc.solves.items()),
        f"{sum(rc.lapack.values())} LAPACK calls (tangent, Hill's LU)":
            sum(c * t_lap[k] for k, c in rc.lapack.items()),
        f"{rc.n_matvec} products of Hill's operator": rc.n_matvec * _best(
            lambda: B @ v),
        "ARPACK's own calls (timed in the run)": rc.arpack_s,
    }
    return parts, lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="yardstick timings")
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    ys = [yardstick(args.repeat)]
    t_cmd = command_wall()
    t_start = start_time()
    rc = count_run()
    parts, lines = floor_parts(rc, t_start)
    ys.append(yardstick(args.repeat))
    ys_s = statistics.median(ys)
    floor = sum(parts.values())
    print(f"yardstick {ys_s:.3f} s (median of {2 * args.repeat}); {rc.rows} rows")
    for line in lines:
        print(line)
    for k, v in parts.items():
        print(f"  {k}: {v:.3f} s")
    print(f"floor {floor:.2f} s = {floor / rc.rows / ys_s:.4f} yardsticks per row; "
          f"the command (fresh process, median of 3) {t_cmd:.2f} s = "
          f"{t_cmd / rc.rows / ys_s:.4f} per row, {t_cmd / floor:.2f}x the floor "
          f"(target <= {TARGET_ROW} per row: at most "
          f"{TARGET_ROW * rc.rows * ys_s / floor:.2f}x the floor)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
