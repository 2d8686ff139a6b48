"""``drymount validate``: the co-simulated steady state against harmonic balance.

For each system (single DOF, quarter car and 6-DOF presets with friction, and the cubic
single DOF, the micro-slip single DOF and the inclined element of Ch. 5, a friction
kind of the mount's axis) a stepped-sine sweep is co-simulated through the mount
FMU (one FMU instance
per mount, driven through fmpy by ``vehicle``) and compared, frequency by frequency,
with multi-harmonic HBM (H = 7 by default) solved at the same frequencies. The
single-harmonic curve (H = 1, the thesis's method) is shown alongside with its error,
for reference only.

Where the response is multi-valued (the cubic spring, and the piecewise spring past its
knee) two stable periodic solutions coexist and the sweep's history decides which one
the co-simulation is on, as on a test rig. The HBM side therefore offers two
candidates per frequency, both exact harmonic-balance solutions: natural continuation
in the sweep's order, and Newton started from the Fourier series of the co-simulated
period; the stable one nearest the co-simulated amplitudes is compared (see
:func:`_hbm_matching`). The 6-DOF preset needs this: past the knee of its piecewise
springs the symmetric periodic solution becomes unstable (Hill) and the engine settles
on an asymmetric one with a static offset, which the co-simulation finds by itself.

Error measure: for each compared DOF, ``|A_cosim - A_hbm| / max_f A_hbm`` (fundamental
amplitudes; the largest over the sweep of the HBM amplitude is the "peak"). A system
passes when the largest error over its points and DOFs is below ``TOL_REL_PEAK`` on
points where the HBM solution is stable. Fundamental amplitudes, not raw samples, are
compared because a Jenkins element that never slips keeps whatever slider offset its
start-up left (PHYSICS.md section 1): HBM starts the slider at zero, the time
simulation keeps its history, and only the offset differs.

The inclined element's family bands (``Case.family_hz``): where one of its surfaces
sticks for the whole period the periodic state is a family and the member depends on
the history, so the sweep's co-simulation need not be on the HBM's member. At those
frequencies the HBM orbit is co-simulated twice, started on the orbit (DOFs and the
element's sliders at phase 0, :func:`vehicle.steady.orbit_start`; in-process
backend) and at rest; the first must stay within ``TOL_FAMILY_ORBIT`` of the orbit
(it counts toward the case's pass), the second's spread is reported (rows with
direction ``orbit`` and ``rest`` in ``points.csv``, a table in the report).

Outputs in ``--out`` (default ``validation/``): ``validation.md`` (the report),
``points.csv`` (every point), one PNG per system. Exit status 0 when every system
passes, 1 otherwise.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from drymount.fmu_src.mount_law import AxisParameters, MountParameters

__all__ = ["Case", "CASES", "CaseResult", "FamilyPoint", "run_case",
           "run_validation", "main", "TOL_REL_PEAK", "TOL_FAMILY_ORBIT",
           "hbm_matching", "compared_dofs"]

from drymount.validation_cases import (  # noqa: F401  (re-exported)
    _ROTATIONS,
    CASES,
    NEGLIGIBLE_RESPONSE,
    TOL_FAMILY_ORBIT,
    TOL_REL_PEAK,
    Case,
    CaseResult,
    FamilyPoint,
)


def _family_points(system, system_hbm, case: Case, dense_amp) -> list[FamilyPoint]:
    """Co-simulate the family-band frequencies of ``case`` from the HBM orbit and
    from rest (in-process backend, the FMU's law: an FMU's ``w_<axis>`` can only
    relax its element, the orbit needs its sliders, :func:`vehicle.steady.
    orbit_start`)."""
    import drymount.hbm as hbm
    import drymount.vehicle.steady as steady

    peak = np.nanmax(dense_amp, axis=0)
    dofs = _compared_dofs(system, dense_amp[np.all(np.isfinite(dense_amp), axis=1)])
    out = []
    for f in case.family_hz:
        r = hbm.solve_frequencies(system_hbm, [f], harmonics=case.harmonics,
                                  n_samples=case.n_samples)
        if not r.n_points:
            raise ValueError(f"{case.name}: no HBM solution at {f} Hz ({r.message})")
        start = steady.orbit_start(system, r.coefficients[0], f, r.n_samples)
        runs = [steady.steady_state(system, f, backend="inproc", start=st)
                for st in (start, "rest")]
        for i in dofs:
            a = [float(r.amplitude[0, i])] + [float(x.amplitude[i]) for x in runs]
            mean = [float(r.coefficients[0, i, 0])] + [float(x.mean[i]) for x in runs]
            out.append(FamilyPoint(float(f), system.dof_names[i],
                                   tuple(int(c) for c in r.stuck[0]), *a,
                                   abs(a[1] - a[0]) / peak[i],
                                   abs(a[2] - a[0]) / peak[i], *mean))
    return out


def _add_family(res: CaseResult, points: list[FamilyPoint]) -> list[float]:
    """Record the family points in ``res`` (rows, maxima); the orbit errors."""
    res.family = points
    for fp in points:
        for direction, amp, err, compared in (
                ("orbit", fp.amp_orbit, fp.err_orbit, True),
                ("rest", fp.amp_rest, fp.err_rest, False)):
            res.rows.append(dict(direction=direction, freq_hz=fp.freq_hz, dof=fp.dof,
                                 amp_cosim=amp, amp_hbm=fp.amp_hbm,
                                 amp_hbm1=float("nan"), err=err,
                                 err_h1=float("nan"), stable=True,
                                 compared=compared))
    res.max_err_orbit = max((fp.err_orbit for fp in points), default=float("nan"))
    res.max_err_rest = max((fp.err_rest for fp in points), default=float("nan"))
    return [fp.err_orbit for fp in points]


def parse_inject(spec: str) -> tuple[str, float]:
    """Parse ``FIELD=FACTOR`` of ``--inject``; raise ValueError naming the problem."""
    allowed = [f.name for f in dataclasses.fields(AxisParameters)
               if f.type in ("float", float)]
    try:
        name, factor = spec.split("=")
        factor = float(factor)
    except ValueError:
        raise ValueError(f"`--inject` must be FIELD=FACTOR, got {spec!r}") from None
    if name not in allowed:
        raise ValueError(f"`--inject` field must be one of {', '.join(allowed)}, "
                         f"got {name!r}")
    if not (np.isfinite(factor) and factor >= 0):
        raise ValueError(f"`--inject` factor must be finite and >= 0, got {factor!r}")
    return name, factor


def perturb(system, spec: str | None):
    """Apply ``--inject FIELD=FACTOR`` to every mount axis of ``system``.

    Scales the named :class:`AxisParameters` field (e.g. ``n0=1.5`` or ``k1=1.1``) on
    the HBM side only, to prove that the comparison detects a wrong parameter.
    """
    if not spec:
        return system
    name, factor = parse_inject(spec)
    def scaled(a):
        return dataclasses.replace(a, **{name: getattr(a, name) * factor})

    params = [MountParameters(*(scaled(a) for a in e.params.axes))
              for e in system.elements]
    return system.with_mount_params(params)


def _compared_dofs(system, amp_hbm: np.ndarray) -> list[int]:
    """Indices of the DOFs with a response worth comparing (see NEGLIGIBLE_RESPONSE)."""
    peaks = amp_hbm.max(axis=0)
    out = []
    for kind in (False, True):
        idx = [i for i, n in enumerate(system.dof_names) if (n in _ROTATIONS) == kind]
        if not idx:
            continue
        top = max(peaks[i] for i in idx)
        out += [i for i in idx if peaks[i] > NEGLIGIBLE_RESPONSE * top]
    return sorted(out)


def _aligned(resp, freqs: np.ndarray, n_dof: int):
    """Amplitudes and stability of ``resp`` on ``freqs`` (NaN/False where missing)."""
    amp = np.full((freqs.size, n_dof), np.nan)
    stable = np.zeros(freqs.size, dtype=bool)
    for j, fj in enumerate(np.asarray(resp.freq_hz)):
        k = np.flatnonzero(np.isclose(freqs, fj, rtol=1e-9, atol=0.0))
        if k.size:
            amp[k[0]] = resp.amplitude[j]
            stable[k[0]] = bool(resp.stable[j])
    return amp, stable


def _hbm_matching(system, freqs: np.ndarray, sweep, harmonics: int,
                  n_samples: int | None = None):
    """Per frequency, the stable HBM solution (H = ``harmonics``) of the branch the
    co-simulated sweep is on.

    Candidates: natural continuation in the sweep's order
    (:func:`hbm.solve_frequencies`), and Newton started from the Fourier series of
    the co-simulated last period (:func:`hbm.branches.solve_from_phasors`). Both
    are exact HBM solutions. They differ where the curve is multi-valued (cubic or
    piecewise hardening: another branch) or where the symmetric solution of a
    symmetric system is unstable and the motion has broken the symmetry (static term
    and even harmonics; Newton started from a symmetric guess stays symmetric). The
    one nearest the co-simulated amplitudes (relative to each DOF's largest
    co-simulated amplitude) is kept, stable ones first.

    Returns ``(amplitude (n, n_dof), stable (n,), message)``.
    """
    import drymount.hbm as hbm
    from drymount.hbm.branches import solve_from_phasors

    n_dof = system.n_dof
    cands, notes = [], []
    kw = dict(harmonics=harmonics, n_samples=None if harmonics == 1 else n_samples)
    for what, solve in (
        ("natural continuation (stops past a fold; the other candidate covers the "
         "rest)", lambda: hbm.solve_frequencies(system, freqs, **kw)),
        ("Newton from the co-simulated period",
         lambda: solve_from_phasors(system, freqs, sweep.phasor,
                                    coefficients=sweep.fourier, **kw)),
    ):
        resp = solve()
        cands.append(_aligned(resp, freqs, n_dof))
        if not resp.success:
            notes.append(f"{what}: {resp.message}")
    a_co = np.asarray(sweep.amplitude)
    scale = np.maximum(a_co.max(axis=0), 1e-300)
    amp = np.full((freqs.size, n_dof), np.nan)
    stable = np.zeros(freqs.size, dtype=bool)
    for k in range(freqs.size):
        best = None
        for a, st in cands:
            if not np.all(np.isfinite(a[k])):
                continue
            d = float(np.max(np.abs(a[k] - a_co[k]) / scale))
            key = (not st[k], d)
            if best is None or key < best[0]:
                best = (key, a[k], st[k])
        if best is not None:
            amp[k], stable[k] = best[1], best[2]
    missing = int(np.sum(~np.isfinite(amp).all(axis=1)))
    if missing:
        notes.append(f"{missing} frequencies without an HBM solution")
    return amp, stable, "; ".join(notes)


#: Public names of the matching used by ``drymount explore --cosim-check``.
hbm_matching = _hbm_matching
compared_dofs = _compared_dofs


def run_case(case: Case, *, quick: bool = False, inject: str | None = None,
             fmu_path=None, progress: bool = True) -> CaseResult:
    """Co-simulate and solve HBM for one case; see the module docstring."""
    import drymount.vehicle as vehicle
    from drymount.config import load_preset

    t0 = time.perf_counter()
    cfg = load_preset(case.preset)
    system = cfg.system
    system_hbm = perturb(system, inject)
    n = case.quick_points if quick else case.points
    freqs = np.linspace(case.fmin_hz, case.fmax_hz, n)
    res = CaseResult(case, dof_names=tuple(system.dof_names))
    errs, errs1 = [], []
    for direction in case.directions:
        f = freqs if direction == "up" else freqs[::-1]
        sw = vehicle.sweep(system, f, direction=direction, backend=case.backend,
                           workers=1, progress=progress, fmu_path=fmu_path)
        a_co = np.asarray(sw.amplitude)
        a_h, stable, msg = _hbm_matching(system_hbm, f, sw, case.harmonics,
                                          case.n_samples)
        a_h1, _, _ = _hbm_matching(system_hbm, f, sw, 1)
        if msg:
            res.message += f"HBM ({direction}): {msg}. "
        dofs = _compared_dofs(system, a_h)
        peak = np.nanmax(a_h, axis=0)
        a_ex = _exact_column(res, system, f, a_h, a_co, stable, dofs)
        for k in range(len(f)):
            for i, dof in enumerate(system.dof_names):
                err = abs(a_co[k, i] - a_h[k, i]) / peak[i] if peak[i] > 0 else 0.0
                err1 = abs(a_co[k, i] - a_h1[k, i]) / peak[i] if peak[i] > 0 else 0.0
                compared = bool(i in dofs and stable[k])
                res.rows.append(dict(direction=direction, freq_hz=float(f[k]), dof=dof,
                                     amp_cosim=float(a_co[k, i]),
                                     amp_hbm=float(a_h[k, i]),
                                     amp_hbm1=float(a_h1[k, i]), err=float(err),
                                     err_h1=float(err1), stable=bool(stable[k]),
                                     compared=compared,
                                     amp_exact=float(a_ex[k, i])))
                if compared:
                    errs.append(err)
                    errs1.append(err1)
        res.curves[direction] = dict(freq_hz=np.asarray(f), cosim=a_co, hbm=a_h,
                                     hbm1=a_h1, stable=stable, dofs=dofs)
    res.dense = _dense_curves(system_hbm, case)
    orbit = []
    if case.family_hz:
        _, amp, _ = res.dense[case.harmonics]
        orbit = _add_family(res, _family_points(system, system_hbm, case, amp))
    res.max_err = max(errs + orbit) if errs else float("nan")
    res.max_err_h1 = max(errs1) if errs1 else float("nan")
    exact_ok = not case.exact or max(res.max_err_exact_hbm,
                                     res.max_err_exact_cosim) <= TOL_REL_PEAK
    res.passed = bool(errs) and res.max_err <= TOL_REL_PEAK and exact_ok and \
        all(e <= TOL_FAMILY_ORBIT for e in orbit)
    if not errs:
        res.message += "no stable point to compare. "
    res.seconds = time.perf_counter() - t0
    return res


def _exact_column(res: CaseResult, system, f, a_h, a_co, stable, dofs) -> np.ndarray:
    """The exact FRF at ``f`` (``Case.exact``; nan otherwise), and the case's
    largest HBM and co-simulation errors against it (of its peak) on the compared
    points, kept in ``res``."""
    if not res.case.exact:
        return np.full_like(a_h, np.nan)
    from drymount.validation_exact import exact_sdof_amplitude

    a_ex = exact_sdof_amplitude(system, f)
    peak = np.max(a_ex, axis=0)
    rows = [k for k in range(len(f)) if stable[k]]
    for attr, a in (("max_err_exact_hbm", a_h), ("max_err_exact_cosim", a_co)):
        e = [abs(a[k, i] - a_ex[k, i]) / peak[i] for k in rows for i in dofs]
        prev = getattr(res, attr)
        setattr(res, attr, max([x for x in (prev,) if x == x] + e) if e else prev)
    return a_ex


def _dense_curves(system, case: Case) -> dict:
    """The continuous HBM curves the plot draws under the validation points: arc-length
    continuation over the case's band at its H and N (fixed, as the points) and at
    H = 1; what a curve that stops early covered is kept."""
    import drymount.hbm as hbm
    from drymount.hbm.options import HBMOptions

    out = {}
    for h, n in ((case.harmonics, case.n_samples), (1, None)):
        resp = hbm.frequency_response(system, case.fmin_hz, case.fmax_hz, harmonics=h,
                                      n_samples=n, options=HBMOptions(tol=None))
        out[h] = (np.asarray(resp.freq_hz), np.asarray(resp.amplitude),
                  np.asarray(resp.stable, dtype=bool))
    return out


def run_validation(*, quick: bool = False, out="validation", inject: str | None = None,
                   cases=None, progress: bool = True,
                   fmu_path=None) -> list[CaseResult]:
    """Run the cases (default :data:`CASES`), write the report, return the results.

    ``fmu_path``: the FMU to co-simulate (any build with the FrictionMount variables,
    e.g. the native FrictionMountNative.fmu); default dist/FrictionMount.fmu, built if
    missing."""
    from drymount.fmu_build import ensure_fmu
    from drymount.fmu_build.native import is_native_fmu

    cases = CASES if cases is None else cases
    if fmu_path is None or not is_native_fmu(fmu_path):  # native: used as is
        fmu_path = ensure_fmu(fmu_path)
    results = []
    for case in cases:
        if progress:
            print(f"validate: {case.name} ({case.preset})", file=sys.stderr)
        results.append(run_case(case, quick=quick, inject=inject, fmu_path=fmu_path,
                                progress=progress))
    from drymount.validation_report import write_report

    write_report(results, Path(out), quick, inject)
    return results


def main(args: argparse.Namespace) -> int:
    """CLI entry: ``drymount validate [--quick] [--out DIR] [--inject F=X]``."""
    names = getattr(args, "systems", None)
    cases = CASES
    if names:
        known = {c.name: c for c in CASES}
        bad = [n for n in names if n not in known]
        if bad:
            print(f"error: `--systems` must be among {', '.join(known)}, got "
                  f"{', '.join(bad)}", file=sys.stderr)
            return 2
        cases = tuple(known[n] for n in names)
    try:
        if getattr(args, "inject", None):
            parse_inject(args.inject)
        results = run_validation(quick=args.quick, out=args.out,
                                 inject=getattr(args, "inject", None), cases=cases,
                                 fmu_path=getattr(args, "fmu", None))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for r in results:
        verdict = "PASS" if r.passed else "FAIL"
        print(f"{r.case.name:24s} max error {100 * r.max_err:7.3f} % of peak "
              f"(H={r.case.harmonics}), H=1: {100 * r.max_err_h1:6.2f} %  {verdict}")
        if r.case.exact:
            print(f"{'':24s} exact FRF: HBM {100 * r.max_err_exact_hbm:.2e} %, "
                  f"co-simulation {100 * r.max_err_exact_cosim:.2e} % of its peak "
                  f"(<= {100 * TOL_REL_PEAK:g} %)")
        if r.family:
            print(f"{'':24s} family bands at "
                  f"{', '.join(f'{f:g}' for f in r.case.family_hz)} Hz: from the HBM "
                  f"orbit {100 * r.max_err_orbit:.3f} % of peak (<= "
                  f"{100 * TOL_FAMILY_ORBIT:g} %), from rest "
                  f"{100 * r.max_err_rest:.2f} % (the member its history selects)")
    print(f"report: {Path(args.out) / 'validation.md'}")
    return 0 if all(r.passed for r in results) else 1
