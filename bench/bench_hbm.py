"""Benchmark of the harmonic-balance frequency-response curves (issue 3).

Full curves by arc-length continuation, with stability, for

- sdof-H1:  single DOF, m 70 kg, mount linear k 91 870 N/m, c 150 N s/m, Jenkins
            kf 60 000 N/m, Fs 20 N (mu 1, n0 20 N), force amplitude 40 N, 2-15 Hz,
            H = 1 with the closed forms (target <= 0.05 s);
- sdof-H7:  the same at H = 7 with 64 AFT samples (target <= 0.3 s);
- quarter-car-H5: m_e 70, m_s 230, m_us 30 kg, k_s 15 000 N/m, c_s 1000 N s/m,
            tyre 200 000 N/m, mount as above with n0 30 N, road 0.01 m, 1-25 Hz;
- six-dof-H5: rigid engine 140.8 kg, inertias 8.63/10.02/10.22 kg m^2, mounts at
            (-0.5,0.25,0), (0.5,0.25,0), (0,-0.25,-0.5) m, linear 91 870 N/m, c 150,
            lambda 1, friction along x on mount 1 (radial1), y on mount 2 (radial2),
            z on mount 3 (axial), n0 250 N, kf 60 000 N/m, base (0, 0, 0.0035) m,
            2-20 Hz (target <= 2 s).

Prints points, Newton iterations, steps, milliseconds per point and seconds per curve
(best and median of ``--repeat`` runs after a warm-up). With ``--convergence`` it also
prints the fundamental amplitude at the resonance peak of the single-DOF preset for
H = 1, 3, 5, 9, 15 (at the default AFT sample count and at N = 256) and the event-exact
time integration at the peak.

OpenBLAS threads are limited to 1 unless ``--threads`` is given (set before NumPy is
imported): the matrices are small (at most 132 x 132) and threads only add overhead,
a lot of it on a busy machine.

With ``--adaptive`` it also runs each case once with the adaptive defaults of issue 17
(``tol`` = 1e-3: error estimates, H and N raised until the estimate is below tol/2,
chord-error steps, zigzags merged) and prints the cost as a ratio to today's options
(fixed H and N) measured in the same run.

With ``--presets [NAME ...]`` it runs ``drymount hbm``'s curve of each preset (all
eleven without names) twice in the same run: with today's fixed defaults (the
preset's H, N automatic, no error estimate, every turning point kept: the defaults
before issue 17) and with the adaptive defaults (``tol`` = 1e-3, the H cap of 13 for
more than 3 DOF), and prints both times, their ratio, where the adaptation ended and
its error estimate.

Run: ``python bench/bench_hbm.py [--repeat 5] [--convergence] [--adaptive]
[--six-dof-adaptive] [--presets [NAME ...]] [--threads]``
"""

from __future__ import annotations

import argparse
import os
import sys


def _parse():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--convergence", action="store_true")
    ap.add_argument("--threads", action="store_true",
                    help="keep the default BLAS threading")
    ap.add_argument("--no-stability", action="store_true")
    ap.add_argument("--adaptive", action="store_true",
                    help="also compare the adaptive defaults (tol 1e-3) with today's")
    ap.add_argument("--six-dof-adaptive", action="store_true",
                    help="include the six-DOF case in --adaptive (about a minute)")
    ap.add_argument("--presets", nargs="*", default=None, metavar="NAME",
                    help="compare the adaptive defaults with today's on the presets' "
                         "`drymount hbm` curves (all without names)")
    return ap.parse_args()


def main():
    args = _parse()
    if not args.threads:
        for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(var, "1")
    import time

    import numpy as np

    import drymount.hbm as hbm
    from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    from drymount.hbm.systems import quarter_car, rigid_engine, sdof

    def fr_axis(n0):
        return AxisParameters(law="linear", k1=91870.0, c=150.0, friction=True,
                              kf=60000.0, mu=1.0, n0=n0)

    s1 = sdof(70.0, MountParameters(axial=fr_axis(20.0)), "force", 40.0)
    qc = quarter_car(70, 230, 30, 15000, 1000, 200000, 0.0,
                     MountParameters(axial=fr_axis(30.0)), road_amplitude=0.01)
    mps = [MountParameters.from_axial(fr_axis(250.0), 1.0, (a,))
           for a in ("radial1", "radial2", "axial")]
    six = rigid_engine(140.8, [8.63, 10.02, 10.22],
                       [(-0.5, 0.25, 0.0), (0.5, 0.25, 0.0), (0.0, -0.25, -0.5)], mps,
                       amplitude=(0.0, 0.0, 0.0035))
    # today's (before issue 17): fixed H and N, steps by the tangent angle only, no
    # error estimate, every turning point kept; the table's targets are for these
    opts = hbm.HBMOptions(stability=not args.no_stability, tol=None,
                          error_estimate=False, zigzag_refine=1)
    cases = [
        ("sdof-H1 (closed forms)", s1, 2.0, 15.0, dict(harmonics=1), 0.05),
        ("sdof-H7 (AFT N=64)", s1, 2.0, 15.0, dict(harmonics=7, n_samples=64), 0.3),
        ("quarter-car-H5", qc, 1.0, 25.0, dict(harmonics=5), None),
        ("six-dof-H5", six, 2.0, 20.0, dict(harmonics=5), 2.0),
    ]
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', 'default')}, "
          f"stability={opts.stability}, repeat={args.repeat}")
    hdr = (f"{'case':26s} {'points':>6s} {'newton':>6s} {'steps':>5s} "
           f"{'ms/point':>8s} {'best s':>7s} {'median s':>8s} {'target s':>8s} ok")
    print(hdr)
    print("-" * len(hdr))
    for name, system, fmin, fmax, kw, target in cases:
        hbm.frequency_response(system, fmin, fmax, options=opts, **kw)  # warm-up
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            r = hbm.frequency_response(system, fmin, fmax, options=opts, **kw)
            times.append(time.perf_counter() - t0)
        best, med = min(times), float(np.median(times))
        ok = "-" if target is None else ("yes" if best <= target else "NO")
        tg = "-" if target is None else f"{target:.2f}"
        print(f"{name:26s} {r.n_points:6d} {r.n_newton:6d} {r.n_steps:5d} "
              f"{1e3 * best / r.n_points:8.2f} {best:7.3f} {med:8.3f} {tg:>8s} {ok}"
              f"{'' if r.success else '  FAILED: ' + r.message}")
    if args.adaptive:
        _adaptive(hbm, np, cases, opts, args.six_dof_adaptive)
    if args.presets is not None:
        _presets(hbm, args.presets)
    if args.convergence:
        _convergence(hbm, np, s1, opts)


def _adaptive(hbm, np, cases, today, six):
    """One curve per case with today's options and with the defaults (tol = 1e-3:
    error estimates, H and N raised until the estimate is below tol/2, chord-error
    steps, zigzags merged), H and N given as where the adaptation starts; the cost
    as a ratio of the two times measured here."""
    import dataclasses
    import time

    new = dataclasses.replace(today, tol=1e-3, error_estimate=True, zigzag_refine=4)
    print("\nadaptive defaults (tol 1e-3) against today's, one run each:")
    hdr = (f"{'case':26s} {'today pts':>9s} {'s':>6s} {'tps':>4s} | {'tol pts':>7s} "
           f"{'H':>3s} {'N':>5s} {'s':>7s} {'tps':>4s} {'err est':>8s} {'cost':>6s}")
    print(hdr)
    print("-" * len(hdr))
    for name, system, fmin, fmax, kw, _ in cases:
        if name.startswith("six") and not six:
            print(f"{name:26s} (skipped: --six-dof-adaptive runs it, minutes)")
            continue
        start = dataclasses.replace(today, harmonics=kw["harmonics"],
                                    n_samples=kw.get("n_samples"))
        t0 = time.perf_counter()
        r0 = hbm.frequency_response(system, fmin, fmax, options=start)
        t1 = time.perf_counter()
        r1 = hbm.frequency_response(system, fmin, fmax, options=dataclasses.replace(
            new, harmonics=start.harmonics, n_samples=start.n_samples))
        t2 = time.perf_counter()
        tp0 = len(r0.turning_points)
        print(f"{name:26s} {r0.n_points:9d} {t1 - t0:6.2f} {tp0:4d} | "
              f"{r1.n_points:7d} {r1.harmonics:3d} {r1.n_samples:5d} {t2 - t1:7.2f} "
              f"{len(r1.turning_points):4d} {r1.error_max():8.1e} "
              f"{(t2 - t1) / (t1 - t0):5.1f}x")


def _presets(hbm, names):
    """``drymount hbm``'s curve of each preset with today's fixed defaults and with
    the adaptive ones, timed in the same run; the ratio is the adaptive defaults'
    cost."""
    import dataclasses
    import time

    from drymount.config.loading import list_presets
    from drymount.paths import load_with_overrides

    names = names or list_presets()
    print("\npresets: `drymount hbm` defaults, today's (fixed H, N) against the "
          "adaptive ones (tol 1e-3), one run each:")
    hdr = (f"{'preset':22s} {'DOF':>3s} {'today s':>8s} | {'tol s':>7s} {'H':>3s} "
           f"{'N':>5s} {'err est':>8s} {'met':>4s} {'cost':>6s}")
    print(hdr)
    print("-" * len(hdr))
    for name in names:
        cfg = load_with_overrides(name, ())
        band = (cfg.sweep.fmin_hz, cfg.sweep.fmax_hz)
        adaptive = cfg.hbm.options()
        today = dataclasses.replace(adaptive, tol=None, error_estimate=False,
                                    zigzag_refine=1)
        t0 = time.perf_counter()
        hbm.frequency_response(cfg.system, *band, options=today)
        t1 = time.perf_counter()
        r = hbm.frequency_response(cfg.system, *band, options=adaptive)
        t2 = time.perf_counter()
        print(f"{name:22s} {cfg.system.n_dof:3d} {t1 - t0:8.2f} | {t2 - t1:7.2f} "
              f"{r.harmonics:3d} {r.n_samples:5d} {r.error_max():8.1e} "
              f"{'yes' if r.tol_met else 'NO':>4s} {(t2 - t1) / (t1 - t0):5.1f}x")


def _convergence(hbm, np, s1, opts):
    """Amplitude at the resonance peak against H, at the default AFT sample count and
    at a fixed N = 256 (which separates harmonic truncation from the sampling of the
    stick-slip reversals), and the event-exact time integration at the peak."""
    from drymount.hbm.aft import default_n_samples
    from drymount.hbm.reference import periodic_response
    f = np.linspace(5.80, 5.92, 41)
    print("\nsdof preset, fundamental amplitude at the resonance peak "
          "(41 frequencies 5.80-5.92 Hz):")
    for fixed in (None, 256):
        res = {}
        for H in (1, 3, 5, 9, 15):
            n = None if H == 1 and fixed is None else (fixed or default_n_samples(H))
            r = hbm.solve_frequencies(s1, f, harmonics=H, n_samples=n, options=opts)
            i = int(np.argmax(r.amplitude[:, 0]))
            res[H] = (r.amplitude[i, 0], f[i], r.peak[i, 0], n)
        for H, (a, fi, pk, n) in res.items():
            how = "closed forms" if n is None else f"N={n}"
            print(f"  H={H:2d} ({how:12s}): amplitude {a * 1e3:.6f} mm at {fi:.4f} Hz, "
                  f"max|x| {pk * 1e3:.6f} mm, rel. diff. to H=15 "
                  f"{abs(a / res[15][0] - 1):.2e}")
    fpk = res[15][1]
    ref = periodic_response(s1, fpk)
    print(f"  event-exact time integration at {fpk:.4f} Hz: amplitude "
          f"{ref.amplitude[0] * 1e3:.6f} mm, max|x| {ref.peak[0] * 1e3:.6f} mm; "
          f"H=15 N=256 differs by {abs(res[15][0] / ref.amplitude[0] - 1):.2e} "
          f"(amplitude), {abs(res[15][2] / ref.peak[0] - 1):.2e} (max|x|)")

if __name__ == "__main__":
    main()
