"""Benchmark of issue 15: AFT cost against a compiled kernel, BLAS threads of the CLI,
the share of stability in a 6-DOF curve. Every figure is printed next to its target as
a ratio measured in the same run.

1. AFT evaluation (forces and analytic Jacobian) of the single-DOF friction preset S1
   (linear mount 91 870 N/m, Jenkins kf 60 000 N/m, Fs 20 N) at H = 7 for N = 64, 256,
   1024 samples: the march backends of ``hbm.friction_march`` (``numba``, the
   default when installed; ``numpy``, the default without numba: the scalar march
   below 192 samples x columns, else ``scan``; ``scan``, the pure-NumPy prefix scan),
   the previous AFT (the per-sample scalar march ``hbm.elements.jenkins_periodic``),
   and a C kernel of the same algorithm compiled here with ``gcc -O3`` and timed
   inside C (a loop of calls, no ctypes overhead; its dot products vectorised by
   gcc): the compiled floor. Target: N = 1024 within 3x of the floor; fixed overhead
   per call (the intercept at N = 0 of the line through the three timings) under
   15 us, for the default backend.
2. ``python -m drymount.cli hbm six_dof_halved`` with the defaults against
   ``DRYMOUNT_THREADS=1`` (target: within 1.2x, wall and CPU; medians of
   ``min(--repeat, 3)`` runs, the two settings alternating); ``--cli-args`` adds
   arguments (e.g. ``"--harmonics 5 --n-samples 64"``: fixed H and N, no ``--tol``
   adaptation); with ``--library-threads`` also the libraries' own threading
   (``DRYMOUNT_THREADS=default``, the old behaviour; slow on a busy machine). The
   load average is printed before and after: the machine may be shared.
3. Share of the Hill stability stage in a 6-DOF H = 7 curve (six_dof_halved,
   2-25 Hz): ``bench/bench_stability.py`` (process time inside
   ``hbm.postprocess._stability`` over the whole curve). Target < 5 %.

Timings are process (CPU) time, best of ``--repeat`` batches, so that other processes
on a shared machine disturb them less; wall times are printed for the CLI runs.

With ``--scaling`` it prints instead how the costs scale with H, N, DOFs and points
(the tables of docs/performance.md).

Run: ``python bench/bench_aft.py [--repeat 7] [--skip-cli] [--library-threads]
[--scaling]``
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_FLOOR_RATIO = 3.0
TARGET_OVERHEAD_US = 15.0
TARGET_THREADS_RATIO = 1.2

C_KERNEL = r"""
#include <stddef.h>
/* One AFT evaluation of one Jenkins element: u = E U, the periodic march of
   hbm.elements.jenkins_periodic (same operations), F = P f, dF = P Z with
   Z[n] = kf (E[n] - E[last[n]]) at stuck samples. Repeated `reps` times. */
void aft(int N, int m, const double *E, const double *P, const double *U,
         double kf, double fs, double w_start, double *F, double *dF,
         double *u, double *f, int *stuck, int *last, double *Z, int reps) {
    for (int r = 0; r < reps; r++) {
        for (int n = 0; n < N; n++) {
            double s = 0.0;
            for (int g = 0; g < m; g++) s += E[n * m + g] * U[g];
            u[n] = s;
        }
        double eps = fs / kf;
        int imax = 0, imin = 0;
        for (int n = 1; n < N; n++) {
            if (u[n] > u[imax]) imax = n;
            if (u[n] < u[imin]) imin = n;
        }
        int start, lst;
        double w;
        if (u[imax] - u[imin] > 2.0 * eps) {
            start = imax; w = u[imax] - eps; lst = imax;
        } else {
            start = 0; w = w_start; lst = -1;
            for (int n = 0; n < N; n++) {
                double t = kf * (u[n] - w);
                if (t > fs) { w = u[n] - fs / kf; lst = n; }
                else if (t < -fs) { w = u[n] + fs / kf; lst = n; }
            }
        }
        for (int j = 0; j < N; j++) {
            int n = start + j; if (n >= N) n -= N;
            double t = kf * (u[n] - w);
            if (t > fs) { f[n] = fs; w = u[n] - fs / kf; lst = n; stuck[n] = 0; }
            else if (t < -fs) { f[n] = -fs; w = u[n] + fs / kf; lst = n; stuck[n] = 0; }
            else { f[n] = t; stuck[n] = 1; }
            last[n] = lst;
        }
        /* Z transposed (m, N): the products below are dot products over n */
        for (int n = 0; n < N; n++)
            for (int g = 0; g < m; g++) {
                double z = 0.0;
                if (stuck[n]) {
                    z = kf * E[n * m + g];
                    if (last[n] >= 0) z -= kf * E[last[n] * m + g];
                }
                Z[g * N + n] = z;
            }
        for (int h = 0; h < m; h++) {
            const double *ph = P + (size_t)h * N;
            double s = 0.0;
            for (int n = 0; n < N; n++) s += ph[n] * f[n];
            F[h] = s;
            for (int g = 0; g < m; g++) {
                const double *zg = Z + (size_t)g * N;
                double d = 0.0;
                for (int n = 0; n < N; n++) d += ph[n] * zg[n];
                dF[h * m + g] = d;
            }
        }
    }
}
"""


def _parse():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--skip-cli", action="store_true", help="skip item 2")
    ap.add_argument("--cli-args", default="",
                    help="extra arguments of the timed `drymount hbm six_dof_halved`")
    ap.add_argument("--library-threads", action="store_true",
                    help="also time the CLI with the libraries' own threading")
    ap.add_argument("--scaling", action="store_true",
                    help="only print how the costs scale with H, N, DOFs and points")
    return ap.parse_args()


def _cpu(fn, number, repeat):
    """Best process time per call over ``repeat`` batches of ``number`` calls, s."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(number):
            fn()
        best = min(best, (time.process_time() - t0) / number)
    return best


def _load():
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(
        *os.getloadavg(), os.cpu_count())


def _compile_kernel(tmp: Path):
    gcc = shutil.which("gcc") or shutil.which("cc")
    if gcc is None:
        return None
    src = tmp / "aft_kernel.c"
    lib = tmp / "aft_kernel.so"
    src.write_text(C_KERNEL)
    # -fassociative-math (and what it needs) lets gcc vectorise the dot products
    flags = ["-O3", "-march=native", "-fassociative-math", "-fno-signed-zeros",
             "-fno-trapping-math", "-shared", "-fPIC"]
    subprocess.run([gcc, *flags, "-o", str(lib), str(src)], check=True)
    return ctypes.CDLL(str(lib))


def _c_aft(lib, np, b, U, kf, fs, reps):
    """(F, dF, seconds per call) of the C kernel, timed inside C."""
    N, m = b.N, 2 * b.H + 1
    E = np.ascontiguousarray(b.E)
    P = np.ascontiguousarray(b.P)
    Uc = np.ascontiguousarray(U[:, 0])
    F, dF = np.zeros(m), np.zeros((m, m))
    u, f, Z = np.zeros(N), np.zeros(N), np.zeros((N, m))
    stuck, last = np.zeros(N, np.intc), np.zeros(N, np.intc)
    ptr = [a.ctypes.data_as(ctypes.c_void_p) for a in (E, P, Uc, F, dF, u, f, stuck,
                                                       last, Z)]
    lib.aft.restype = None
    lib.aft.argtypes = ([ctypes.c_int] * 2 + [ctypes.c_void_p] * 3
                        + [ctypes.c_double] * 3 + [ctypes.c_void_p] * 7
                        + [ctypes.c_int])

    def call(r):
        lib.aft(N, m, *ptr[:3], kf, fs, 0.0, *ptr[3:], r)

    call(1)
    best = float("inf")
    for _ in range(5):
        t0 = time.process_time()
        call(reps)
        best = min(best, (time.process_time() - t0) / reps)
    return F.copy(), dF.copy(), best


def bench_aft(args, np):
    from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    from drymount.hbm import aft as aft_mod
    from drymount.hbm.aft import FourierBasis, aft_forces
    from drymount.hbm.elements import jenkins_periodic, nonlinear_axes
    from drymount.hbm.friction_march import resolve_backend
    from drymount.hbm.systems import sdof

    p = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                       mu=1.0, n0=20.0)
    ax = nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 40.0))
    kf, fs = float(ax.kf[0]), float(ax.fs[0])
    H = 7
    # a motion with several reversals per period: stick-slip, both directions
    U = np.zeros((2 * H + 1, 1))
    U[1], U[2], U[5], U[6], U[9] = 1.2e-3, 2.0e-3, 3e-4, -2e-4, 1.5e-4

    def scalar_aft(b):
        """The previous AFT: the scalar march per sample (hbm.elements)."""
        u = b.E @ U
        ff, stuck, last = jenkins_periodic(u[:, 0], kf, fs, 0.0)
        kt = np.where(stuck, kf, 0.0)
        F = b.P @ ff
        dF = (b.P * kt) @ b.E
        sel = np.flatnonzero(stuck & (last >= 0))
        if sel.size:
            dF -= kf * (b.P[:, sel] @ b.E[last[sel]])
        return F, dF

    default = resolve_backend()
    print(f"\n1. AFT of S1 (H = {H}), forces + Jacobian, us per call (process time); "
          f"default march backend: {default}")
    with tempfile.TemporaryDirectory() as tmp:
        lib = _compile_kernel(Path(tmp))
        rows = []
        for N in (64, 256, 1024):
            b = FourierBasis(H, N)
            num = max(20, 20000 // N)
            times = {}
            for backend in ("numba", "numpy", "scan"):
                try:
                    resolve_backend(backend)
                except ValueError:
                    continue
                saved = aft_mod.jenkins_aft
                aft_mod.jenkins_aft = (lambda *a, _s=saved, _b=backend, **k:
                                       _s(*a, backend=_b, **k))
                try:
                    aft_forces(U, ax, b)
                    times[backend] = _cpu(lambda b=b: aft_forces(U, ax, b), num,
                                          args.repeat)
                    F, dF = aft_forces(U, ax, b)
                finally:
                    aft_mod.jenkins_aft = saved
            times["scalar"] = _cpu(lambda b=b: scalar_aft(b), max(5, num // 10),
                                   args.repeat)
            Fs, dFs = scalar_aft(b)
            assert np.max(np.abs(F[:, 0] - Fs)) <= 1e-12 * np.abs(Fs).max()
            assert np.max(np.abs(dF[0] - dFs)) <= 1e-12 * np.abs(dFs).max()
            if lib is not None:
                Fc, dFc, times["C"] = _c_aft(lib, np, b, U, kf, fs,
                                             max(200, 200000 // N))
                err = max(np.max(np.abs(Fc - Fs)) / np.abs(Fs).max(),
                          np.max(np.abs(dFc - dFs)) / np.abs(dFs).max())
                assert err <= 1e-12, f"C kernel differs: {err:.3g}"
            rows.append((N, times))
        _print_aft(np, rows, default)


def _print_aft(np, rows, default):
    names = [k for k in ("numba", "numpy", "scan", "scalar", "C") if k in rows[0][1]]
    label = {"numba": "numba", "numpy": "numpy", "scan": "scan",
             "scalar": "scalar(old)", "C": "C floor"}
    print(f"{'N':>6s} " + " ".join(f"{label[k]:>12s}" for k in names)
          + f" {'default/C':>10s}")
    for N, t in rows:
        ratio = t[default] / t["C"] if "C" in t else float("nan")
        print(f"{N:6d} " + " ".join(f"{1e6 * t[k]:12.1f}" for k in names)
              + f" {ratio:10.2f}")
    N = np.array([r[0] for r in rows], dtype=float)
    for k in names:
        t = np.array([r[1][k] for r in rows]) * 1e6
        slope, icpt = np.polyfit(N, t, 1)
        print(f"   {label[k]:12s} fixed overhead (intercept at N = 0) {icpt:7.1f} us, "
              f"{1e3 * slope:7.1f} ns per sample")
    t = rows[-1][1]
    if "C" in t:
        r = t[default] / t["C"]
        print(f"   target: N = 1024 within {TARGET_FLOOR_RATIO:g}x of the C floor: "
              f"{r:.2f}x -> ratio to target {r / TARGET_FLOOR_RATIO:.2f} "
              f"({'met' if r <= TARGET_FLOOR_RATIO else 'NOT met'})")
    tt = np.array([r[1][default] for r in rows]) * 1e6
    icpt = np.polyfit(N, tt, 1)[1]
    print(f"   target: fixed overhead < {TARGET_OVERHEAD_US:g} us: {icpt:.1f} us -> "
          f"ratio to target {icpt / TARGET_OVERHEAD_US:.2f} "
          f"({'met' if icpt < TARGET_OVERHEAD_US else 'NOT met'})")


def _run_cli(extra_env, tmp, cli_args=()):
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                        "DRYMOUNT_THREADS")}
    env.update(extra_env)
    env["PYTHONPATH"] = str(ROOT)
    before = os.times()
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "drymount.cli", "hbm",
                          "six_dof_halved", "--quiet", *cli_args, "--out",
                          str(Path(tmp) / "six.csv")], cwd=ROOT, env=env,
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"drymount hbm failed ({run.returncode}): {run.stderr}")
    wall = time.perf_counter() - t0
    after = os.times()
    cpu = (after.children_user - before.children_user
           + after.children_system - before.children_system)
    return wall, cpu


def bench_cli(args):
    cli_args = args.cli_args.split()
    print(f"\n2. drymount hbm six_dof_halved {' '.join(cli_args)} (CLI, fresh process "
          f"each run, medians); {_load()}")
    configs = [("defaults", {}), ("DRYMOUNT_THREADS=1", {"DRYMOUNT_THREADS": "1"})]
    if args.library_threads:
        configs.append(("DRYMOUNT_THREADS=default", {"DRYMOUNT_THREADS": "default"}))
    runs = {name: [] for name, _ in configs}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(max(1, min(args.repeat, 3))):
            for name, env in configs:
                runs[name].append(_run_cli(env, tmp, cli_args))
    res = {}
    for name, rr in runs.items():
        w, c = (float(sorted(x)[len(x) // 2]) for x in zip(*rr, strict=True))
        res[name] = (w, c)
        print(f"   {name:26s} wall {w:7.2f} s  CPU {c:7.2f} s   (runs: wall "
              + ", ".join(f"{r[0]:.2f}" for r in rr) + "; CPU "
              + ", ".join(f"{r[1]:.2f}" for r in rr) + ")")
    d, one = res["defaults"], res["DRYMOUNT_THREADS=1"]
    for what, i in (("wall", 0), ("CPU", 1)):
        r = d[i] / one[i]
        print(f"   target: defaults within {TARGET_THREADS_RATIO:g}x of one thread "
              f"({what}): {r:.2f}x -> ratio to target {r / TARGET_THREADS_RATIO:.2f} "
              f"({'met' if r <= TARGET_THREADS_RATIO else 'NOT met'})")
    if "DRYMOUNT_THREADS=default" in res:
        lib = res["DRYMOUNT_THREADS=default"]
        print(f"   library threading / one thread: wall {lib[0] / one[0]:.2f}x, "
              f"CPU {lib[1] / one[1]:.2f}x")
    print(f"   after: {_load()}")


def bench_stability(args, np):
    """Item 3: bench/bench_stability.py's share of the stability stage."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import bench_stability

    bench_stability.bench_share(argparse.Namespace(repeat=max(1, min(args.repeat, 3))),
                                np, prefix="3. ")


def bench_scaling(args, np):
    """How the AFT, the Hill problem and whole curves scale (docs/performance.md)."""
    import scipy.linalg

    import drymount.hbm as hbm
    from drymount.config import resolve_config
    from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    from drymount.hbm.aft import FourierBasis, aft_forces, default_n_samples
    from drymount.hbm.elements import nonlinear_axes
    from drymount.hbm.systems import sdof

    rep = max(3, min(args.repeat, 5))
    p = AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True, kf=60000.0,
                       mu=1.0, n0=20.0)
    ax = nonlinear_axes(sdof(70.0, MountParameters(axial=p), "force", 40.0))
    rng = np.random.default_rng(0)
    print("\nAFT of S1 (default backend), us per call, against H and N; and a batch of "
          "P frequency points in one call (us per point)")
    print(f"{'H':>3s} {'N':>5s} {'1 point':>9s} {'P=30, /pt':>10s}")
    for H in (1, 3, 7, 15):
        for N in sorted({default_n_samples(H), 256, 1024}):
            b = FourierBasis(H, N)
            U = rng.normal(size=(30, 2 * H + 1, 1)) * 1e-3
            t1 = _cpu(lambda b=b, U=U: aft_forces(U[0], ax, b), 200, rep)
            t30 = _cpu(lambda b=b, U=U: aft_forces(U, ax, b), 20, rep) / 30
            print(f"{H:3d} {N:5d} {1e6 * t1:9.1f} {1e6 * t30:10.1f}")
    print("\nHill eigenvalue problem (dense, 2 n (2H+1) square), ms per point")
    for n in (1, 2, 6):
        for H in (1, 3, 5, 7):
            size = 2 * n * (2 * H + 1)
            A = rng.normal(size=(size, size))
            t = _cpu(lambda A=A: scipy.linalg.eigvals(A, check_finite=False), 5, rep)
            print(f"   n = {n}, H = {H:2d}: size {size:4d}  {1e3 * t:8.2f} ms")
    print("\nWhole curves (default options), CPU s, points, ms per point")
    for name, H in (("sdof_halved", 1), ("sdof_halved", 7), ("quarter_car_halved", 7),
                    ("six_dof_halved", 3), ("six_dof_halved", 5),
                    ("six_dof_halved", 7)):
        cfg = resolve_config(name)
        runs = []
        for _ in range(max(1, min(args.repeat, 3))):
            t0 = time.process_time()
            fr = hbm.frequency_response(cfg.system, cfg.sweep.fmin_hz,
                                        cfg.sweep.fmax_hz, harmonics=H)
            runs.append(time.process_time() - t0)
        t = min(runs)
        print(f"   {name:20s} H = {H}: {t:6.2f} s, {len(fr.freq_hz):4d} points, "
              f"{1e3 * t / len(fr.freq_hz):6.2f} ms per point")


def main():
    args = _parse()
    # this process: one BLAS thread, as the CLI (set before NumPy loads)
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    sys.path.insert(0, str(ROOT))
    import numpy as np

    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, {_load()}")
    if args.scaling:
        bench_scaling(args, np)
        return
    bench_aft(args, np)
    if not args.skip_cli:
        bench_cli(args)
    bench_stability(args, np)


if __name__ == "__main__":
    main()
