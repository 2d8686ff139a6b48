"""Benchmark of issue 15 item 3: the cost of Hill stability along a curve and its
verdicts against evaluating every point with the dense eigenvalue problem.

1. Share of the stability stage in a 6-DOF H = 7 curve (six_dof_halved, 2-25 Hz):
   process time inside ``hbm.postprocess._stability`` (det J signs along the branch
   and the Hill problems of the schedule) over the process time of the whole
   ``hbm.frequency_response`` call, best of ``--repeat`` runs; with the default
   options (``tol`` = 1e-3: H = 7 fixed by the caller, N raised by the error
   estimate, the curve traced again) and with fixed H = 7, N = 64 (``tol=None``,
   the cheap curve, where the share is largest). Target < 5 %.
2. (``--presets``) On every 6-DOF preset at H = 7 (``tol=None``, 2-25 Hz, 2-40 Hz
   for six_dof_4mount): the points whose verdict differs from the dense problem at
   every point, for the schedule of today (stride 64, Arnoldi, margin rule), the
   previous schedule (stride 16, dense, refinement around changes; kept below for
   the comparison) and Arnoldi at every point.
3. (``--scaling``) Cost of one Hill problem, dense against Arnoldi, for 1, 2 and 6
   DOFs at several H, on the Jacobians of traced curves.

Run: ``python bench/bench_stability.py [--repeat 3] [--presets] [--scaling]``
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_STABILITY_SHARE = 0.05


def _load():
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(
        *os.getloadavg(), os.cpu_count())


class _Hook:
    """Times ``hbm.postprocess._stability`` and keeps the arguments of its last call."""

    def __init__(self):
        import drymount.hbm.postprocess as pp
        self.pp, self.orig = pp, pp._stability
        self.t, self.calls, self.last = 0.0, 0, None

    def __enter__(self):
        def timed(prob, ys, br, stride):
            t0 = time.process_time()
            try:
                return self.orig(prob, ys, br, stride)
            finally:
                self.t += time.process_time() - t0
                self.calls += 1
                self.last = (prob, ys, br)
        self.pp._stability = timed
        return self

    def __exit__(self, *exc):
        self.pp._stability = self.orig


def _count_methods():
    """Counts of Hill problems by method, by wrapping the schedule's hill_verdict."""
    import drymount.hbm.stability_schedule as ss
    counts = {}
    orig = ss.hill_verdict

    def counted(*a, **k):
        v = orig(*a, **k)
        counts[v.method.value] = counts.get(v.method.value, 0) + 1
        return v
    ss.hill_verdict = counted
    return counts, lambda: setattr(ss, "hill_verdict", orig)


def _reference(last):
    """Verdicts of the dense problem at every point of the last traced branch."""
    from drymount.hbm.stability_schedule import _stability
    prob, ys, br = last
    t0 = time.process_time()
    stable, _ = _stability(prob, ys, br, 1, dense=True)
    return stable, time.process_time() - t0


def bench_share(args, np, prefix=""):
    import drymount.hbm as hbm
    from drymount.config import resolve_config

    cfg = resolve_config("six_dof_halved")
    print(f"\n{prefix}Stability share of a 6-DOF H = 7 curve (six_dof_halved, "
          f"2-25 Hz); {_load()}")
    worst = 0.0
    for label, opts in (("default options (tol 1e-3)", hbm.HBMOptions()),
                        ("fixed H = 7, N = 64 (tol=None)", hbm.HBMOptions(tol=None))):
        runs = []
        for _ in range(max(1, args.repeat)):
            counts, restore = _count_methods()
            try:
                with _Hook() as hook:
                    t0 = time.process_time()
                    fr = hbm.frequency_response(cfg.system, 2.0, 25.0, harmonics=7,
                                                options=opts)
                    tot = time.process_time() - t0
            finally:
                restore()
            runs.append((hook.t / tot, hook.t, tot, dict(counts), hook.calls,
                         hook.last))
        share, st, tot, counts, ncalls, last = min(runs, key=lambda r: r[0])
        ref, t_ref = _reference(last)
        diff = int(np.sum(ref != np.asarray(fr.stable)[:len(ref)]))
        npts = len(fr.freq_hz)
        print(f"   {label}: {npts} points (N = {fr.n_samples}), stability stage run "
              f"{ncalls}x, Hill problems {counts}; stability {st:.3f} s of "
              f"{tot:.2f} s CPU = {100 * share:.1f} % -> ratio to target "
              f"{share / TARGET_STABILITY_SHARE:.2f} "
              f"({'met' if share < TARGET_STABILITY_SHARE else 'NOT met'})")
        print(f"      dense Hill at every point of the last trace (the reference): "
              f"{t_ref:.2f} s ({100 * t_ref / (tot - st + t_ref):.0f} % of such a "
              f"curve); verdicts differing from it: {diff} of {len(ref)}")
        worst = max(worst, share)
    print(f"   target: stability < {100 * TARGET_STABILITY_SHARE:g} % of the curve, "
          f"worst of the two: {100 * worst:.1f} % -> ratio to target "
          f"{worst / TARGET_STABILITY_SHARE:.2f} "
          f"({'met' if worst < TARGET_STABILITY_SHARE else 'NOT met'})")
    return worst


def _previous_schedule(prob, ys, br, stride=16):
    """The schedule before issue 15 item 3 was finished (dense Hill; stride 16, both
    sides of det J sign changes, every stride/4-th point around a change of verdict,
    bisection), kept here to count its differences."""
    import numpy as np

    from drymount.hbm.stability import is_stable
    hb, npts = prob.hb, len(ys)
    stable, done = np.ones(npts, bool), np.zeros(npts, bool)
    jac = [(br.jacobian[i][:, :-1] * (prob.rs / prob.xs), prob.x_of(y)[1])
           for i, y in enumerate(ys)]
    sign = np.array([np.linalg.slogdet(J)[0] for J, _ in jac])

    def evaluate(i):
        if not done[i]:
            stable[i], done[i] = is_stable(hb, *jac[i]).stable, True

    def bisect(a, b):
        while b - a >= 2:
            if stable[a] == stable[b]:
                stable[a + 1:b] = stable[a]
                return
            c = (a + b) // 2
            evaluate(c)
            bisect(a, c)
            a = c

    key = set(range(0, npts, stride)) | {npts - 1}
    key |= {j for i in range(1, npts) if sign[i] != sign[i - 1] for j in (i - 1, i)}
    for i in sorted(key):
        evaluate(i)
    keys, fine, extra = sorted(key), max(1, stride // 4), set()
    for k in range(len(keys) - 1):
        if stable[keys[k]] != stable[keys[k + 1]]:
            for kk in range(max(0, k - 1), min(len(keys) - 1, k + 2)):
                extra |= set(range(keys[kk], keys[kk + 1], fine))
    for i in sorted(extra):
        evaluate(i)
    keys = sorted(key | extra)
    for a, b in zip(keys[:-1], keys[1:], strict=True):
        if np.all(sign[a:b + 1] == sign[a]):
            bisect(a, b)
        else:
            for i in range(a + 1, b):
                evaluate(i)
    return stable, int(done.sum())


def bench_presets(args, np):
    import drymount.hbm as hbm
    from drymount.config import resolve_config
    from drymount.hbm.stability import hill_verdict
    from drymount.hbm.stability_schedule import _stability

    print(f"\nVerdicts against the dense problem at every point, H = 7, tol=None; "
          f"{_load()}")
    print("   points whose verdict differs from the reference (Hill problems solved)")
    print(f"   {'preset':18s} {'points':>6s} {'unstable':>8s} {'today':>12s} "
          f"{'previous':>12s} {'Arnoldi, all':>13s}")
    for name, fmax in (("six_dof_halved", 25.0), ("six_dof_lambda12", 25.0),
                       ("six_dof_original", 25.0), ("six_dof_4mount", 40.0)):
        cfg = resolve_config(name)
        with _Hook() as hook:
            hbm.frequency_response(cfg.system, 2.0, fmax, harmonics=7,
                                   options=hbm.HBMOptions(tol=None))
        prob, ys, br = hook.last
        ref, _ = _reference(hook.last)
        counts, restore = _count_methods()
        try:
            today, _ = _stability(prob, ys, br, hbm.HBMOptions().stability_stride)
        finally:
            restore()
        prev, n_prev = _previous_schedule(prob, ys, br)
        arn = np.array([hill_verdict(prob.hb, br.jacobian[i][:, :-1]
                                     * (prob.rs / prob.xs), prob.x_of(y)[1]).stable
                        for i, y in enumerate(ys)])
        print(f"   {name:18s} {len(ref):6d} {int(np.sum(~ref)):8d} "
              f"{int(np.sum(today != ref)):5d} ({sum(counts.values()):4d}) "
              f"{int(np.sum(prev != ref)):5d} ({n_prev:4d}) "
              f"{int(np.sum(arn != ref)):6d} ({len(ref):4d})")


def bench_scaling(args, np):
    import drymount.hbm as hbm
    from drymount.config import resolve_config
    from drymount.hbm.hill_arnoldi import MIN_SIZE, central_eigenvalues
    from drymount.hbm.stability import hill_eigenvalues

    print(f"\nOne Hill problem, ms (CPU, best of 3 over 8 points of the curve); "
          f"{_load()}")
    print(f"   {'preset':20s} {'n':>2s} {'H':>3s} {'size':>5s} {'dense':>8s} "
          f"{'Arnoldi':>8s} {'ratio':>6s}  (Arnoldi from size {MIN_SIZE})")
    for name, H in (("sdof_halved", 7), ("quarter_car_halved", 7),
                    ("six_dof_halved", 3), ("six_dof_halved", 5),
                    ("six_dof_halved", 7), ("six_dof_halved", 10)):
        cfg = resolve_config(name)
        with _Hook() as hook:
            hbm.frequency_response(cfg.system, cfg.sweep.fmin_hz, cfg.sweep.fmax_hz,
                                   harmonics=H, options=hbm.HBMOptions(tol=None))
        prob, ys, br = hook.last
        idx = np.linspace(0, len(br.jacobian) - 1, 8).astype(int)
        pts = [(br.jacobian[i][:, :-1] * (prob.rs / prob.xs), prob.x_of(ys[i])[1])
               for i in idx]
        hb = prob.hb

        def run(fn, pts=pts, hb=hb):
            best = float("inf")
            for _ in range(3):
                t0 = time.process_time()
                out = [fn(hb, J, w) for J, w in pts]
                best = min(best, (time.process_time() - t0) / len(pts))
            return best, out

        td, _ = run(hill_eigenvalues)
        size = 2 * hb.m * hb.n
        if size < MIN_SIZE:
            print(f"   {name:20s} {hb.n:2d} {H:3d} {size:5d} {1e3 * td:8.2f} "
                  f"{'-':>8s} {'-':>6s}")
            continue
        ta, out = run(central_eigenvalues)
        fb = sum(o is None for o in out)
        print(f"   {name:20s} {hb.n:2d} {H:3d} {size:5d} {1e3 * td:8.2f} "
              f"{1e3 * ta:8.2f} {td / ta:6.2f}  ({fb} of 8 fell back to dense)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--presets", action="store_true")
    ap.add_argument("--scaling", action="store_true")
    args = ap.parse_args()
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    sys.path.insert(0, str(ROOT))
    import numpy as np

    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, {_load()}")
    bench_share(args, np)
    if args.presets:
        bench_presets(args, np)
    if args.scaling:
        bench_scaling(args, np)


if __name__ == "__main__":
    main()
