"""Frequency-response curves by harmonic balance: the user-facing drivers.

- :func:`frequency_response`: arc-length continuation from ``fmin`` to ``fmax``
  (thesis Sec. 3.2, eq. 3.57-3.66), through folds, with turning points and stability.
- :func:`solve_frequencies`: Newton at given frequencies, each started from the tangent
  prediction of the previous solution (eq. 3.53-3.56); for validation.

Both return a :class:`hbm.result.FrequencyResponse`.
"""

from __future__ import annotations

import dataclasses
import math
import re
import sys
from typing import NamedTuple

import numpy as np

from hbm.aft import default_n_samples
from hbm.continuation import Branch, Status, continue_branch, newton
from hbm.error_estimate import estimate_errors
from hbm.folds import CurveEvent, locate_folds, locate_peaks, merge_spurious_pairs
from hbm.linear import linear_frf
from hbm.options import HBMOptions
from hbm.residual import HarmonicBalance
from hbm.result import FrequencyResponse, MarkedPoint
from hbm.segments import Restart, clip, join
from hbm.stability import is_stable
from hbm.system import System

__all__ = ["frequency_response", "solve_frequencies", "build_problem",
           "resolve_options", "postprocess"]

#: The error estimate re-solves every ESTIMATE_STRIDE-th point (and the points around
#: turning points); the points between get the larger of their neighbours' estimates.
ESTIMATE_STRIDE = 4


def _check_range(fmin_hz, fmax_hz):
    problems = []
    for name, v in (("fmin_hz", fmin_hz), ("fmax_hz", fmax_hz)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)) \
                or not math.isfinite(v) or v <= 0:
            problems.append(f"`{name}` must be a finite frequency > 0 Hz, got {v!r}")
    if not problems and fmax_hz <= fmin_hz:
        problems.append(f"`fmax_hz` must be > `fmin_hz` = {fmin_hz}, got {fmax_hz}")
    if problems:
        raise ValueError("; ".join(problems))


def resolve_options(options, harmonics, n_samples) -> tuple[int, int | None,
                                                            HBMOptions]:
    """``(H, n_samples, options)``: explicit arguments over ``options`` (default
    :class:`HBMOptions`)."""
    if options is None:
        options = HBMOptions()
    elif not isinstance(options, HBMOptions):
        raise TypeError(f"`options` must be hbm.HBMOptions, got "
                        f"{type(options).__name__}")
    H = options.harmonics if harmonics is None else harmonics
    N = options.n_samples if n_samples is None else n_samples
    return H, N, options


class _Problem:
    """Scaled residual ``fun(y) -> (R, J)`` of a HarmonicBalance (NLvib's Dscale)."""

    def __init__(self, hb: HarmonicBalance, fmin_hz: float, fmax_hz: float):
        self.hb = hb
        sysm = hb.system
        grid = np.linspace(fmin_hz, fmax_hz, 41)
        amp = np.abs(linear_frf(sysm, grid, stuck=False)).max(axis=0)
        amp = np.maximum(amp, np.abs(linear_frf(sysm, grid, stuck=True)).max(axis=0))
        top = float(amp.max()) if np.all(np.isfinite(amp)) and amp.max() > 0 else 1.0
        amp = np.where(np.isfinite(amp) & (amp > 1e-9 * top), amp, top)
        self.dof_scale = amp
        self.xs = np.tile(amp, hb.m)
        self.ws = 2.0 * np.pi * (fmax_hz - fmin_hz)
        rs = max(np.linalg.norm(hb.excitation(2 * np.pi * fmin_hz)),
                 np.linalg.norm(hb.excitation(2 * np.pi * fmax_hz)))
        self.rs = rs if rs > 0 else 1.0
        self.n_eval = 0
        self.f_ends = (float(fmin_hz), float(fmax_hz))

    def x_of(self, y):
        return self.xs * y[:-1], self.ws * y[-1]

    def y_of(self, X, omega):
        return np.append(X / self.xs, omega / self.ws)

    def __call__(self, y):
        self.n_eval += 1
        X, w = self.x_of(y)
        R, J, Jw = self.hb.residual(X, w)
        Jy = np.empty((R.size, R.size + 1))
        Jy[:, :-1] = J * self.xs
        Jy[:, -1] = Jw * self.ws
        return R / self.rs, Jy / self.rs

    def linear_guess(self, freq_hz: float, stuck: bool) -> np.ndarray:
        Q = linear_frf(self.hb.system, [freq_hz], stuck=stuck)[0]
        X = np.zeros((self.hb.m, self.hb.n))
        if self.hb.static is not None:
            X[0] = self.hb.static.q  # about the static working point
        X[1] = Q.imag
        X[2] = Q.real
        return self.y_of(X.ravel(), 2 * np.pi * freq_hz)


def _lam_to_hz(message: str, prob: _Problem) -> str:
    """Continuation messages speak of the scaled parameter; users of frequencies."""
    return re.sub(r"lam = ([-+0-9.eE]+)",
                  lambda m: f"{float(m.group(1)) * prob.ws / (2 * np.pi):.6g} Hz",
                  message)


def build_problem(system: System, fmin_hz: float, fmax_hz: float, harmonics: int = 7,
                  n_samples: int | None = None, closed_form: bool | None = None,
                  sliders=None):
    """The scaled problem used by the drivers (for tests and custom continuation).

    ``sliders`` (n_elements, 3), m: slider positions the AFT march starts from."""
    hb = HarmonicBalance(system, harmonics, n_samples, closed_form, sliders)
    return _Problem(hb, fmin_hz, fmax_hz)


class StartSolution(NamedTuple):
    """The first point of a curve: ``y`` (None if not found), the Newton iterations
    spent and why it failed ("" on success)."""

    y: np.ndarray | None
    n_newton: int
    message: str


def _start(prob: _Problem, freq_hz: float, settings) -> StartSolution:
    """First solution at ``freq_hz``: Newton from the free and the stuck linear
    solutions, with more iterations than a continuation step (damped Newton can
    need many from a linear guess far from a strongly nonlinear solution)."""
    n = prob.hb.size
    msg = ""
    total = 0
    start = dataclasses.replace(settings, max_newton=max(4 * settings.max_newton, 50))
    for stuck in (False, True):
        y0 = prob.linear_guess(freq_hz, stuck)
        y, ok, its, msg = newton(prob, y0, start, fixed=n)
        total += its
        if ok:
            return StartSolution(y, total, "")
    # load stepping: raise the excitation from a small fraction to 1, each Newton
    # started from the previous solution scaled up (halving the increment on failure)
    hb = prob.hb
    try:
        mu, dmu = 0.0, 0.125
        y = prob.linear_guess(freq_hz, False) * 0.0
        y[-1] = 2 * np.pi * freq_hz / prob.ws
        while mu < 1.0:
            target = min(1.0, mu + dmu)
            hb.exc_scale = target
            guess = y.copy()
            if mu > 0:
                guess[:-1] *= target / mu
            else:
                guess = prob.linear_guess(freq_hz, False)
                guess[:-1] *= target
            y_new, ok, its, msg = newton(prob, guess, start, fixed=n)
            total += its
            if ok:
                y, mu = y_new, target
                dmu = min(2 * dmu, 0.25)
            else:
                dmu *= 0.5
                if dmu < 1e-3:
                    return StartSolution(None, total,
                                         f"load stepping stalled at {mu:.3g} ({msg})")
    finally:
        hb.exc_scale = 1.0
    return StartSolution(y, total, "")


def _stability(prob: _Problem, ys, br: Branch, stride: int):
    """Hill stability along the branch.

    The eigenvalue problem is solved at every ``stride``-th point, at both ends and
    on both sides of every sign change of ``det J`` (folds, branch points: a real
    Floquet exponent crosses zero there); where two of these points have different
    verdicts, also at every ``stride // 4``-th point of that interval and of its
    two neighbours (changes cluster). Between two evaluated points with the same
    verdict, and no sign change of ``det J``, the verdict is carried over; where the
    verdicts differ the change is located by bisection (a complex pair crossing,
    which leaves ``det J`` alone); where ``det J`` changes sign every point between
    them is evaluated. ``stride = 1`` evaluates every point.
    """
    hb = prob.hb
    npts = len(ys)
    stable = np.ones(npts, dtype=bool)
    fmr = np.full(npts, np.nan)
    jac = []
    sign = np.empty(npts)
    for i, y in enumerate(ys):
        X, w = prob.x_of(y)
        if i < len(br.jacobian):
            J = br.jacobian[i][:, :-1] * (prob.rs / prob.xs)
        else:
            J = hb.residual(X, w)[1]
        jac.append((J, w))
        sign[i] = np.linalg.slogdet(J)[0]
    done = np.zeros(npts, dtype=bool)

    def evaluate(i):
        if not done[i]:
            J, w = jac[i]
            try:
                stable[i], fmr[i] = is_stable(hb, J, w)
            except (np.linalg.LinAlgError, ValueError):
                stable[i], fmr[i] = True, np.nan
            done[i] = True

    def bisect(a, b):
        """Verdicts at a < b known, det J of one sign on [a, b]."""
        while b - a >= 2:
            if stable[a] == stable[b]:
                stable[a + 1:b] = stable[a]
                return
            c = (a + b) // 2
            evaluate(c)
            bisect(a, c)
            a = c

    key = set(range(0, npts, stride)) | {npts - 1}
    for i in range(1, npts):
        if sign[i] != sign[i - 1]:
            key |= {i - 1, i}
    for i in sorted(key):
        evaluate(i)
    keys = sorted(key)
    fine = max(1, stride // 4)
    if fine < stride:
        # near a change of verdict (in that interval and its neighbours) changes
        # cluster (short islands of instability): evaluate every `fine`-th point there
        extra = set()
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
    return stable, fmr


def _point_quantities(prob: _Problem, y):
    """``(freq_hz, X (m, n), amplitude (n,), transmissibility)`` of a point."""
    hb = prob.hb
    sysm = hb.system
    tr, exc = sysm.transmissibility, sysm.excitation
    X, w = prob.x_of(y)
    f = w / (2 * np.pi)
    for fe in prob.f_ends:  # undo the round-off of the scaling at the ends
        if abs(f - fe) <= 1e-12 * fe:
            f = fe
    Xr = X.reshape(hb.m, hb.n)
    amp = np.hypot(Xr[1], Xr[2])
    if tr.kind == "force":
        fc, fs = hb.axis_force_fundamental(X, w, tr.forces)
        den = exc.scalar_amplitude(w)
        trans = math.hypot(fc, fs) / den if den > 0 else np.nan
    else:
        den = amp[tr.reference] if tr.reference is not None else \
            exc.scalar_amplitude(w)
        trans = amp[tr.dof] / den if den > 0 else np.nan
    return f, Xr, amp, trans


def _amplitude_fn(prob: _Problem):
    """``y -> (a (n,), da/dy (n, len(y)))``: fundamental amplitudes of the DOFs."""
    n = prob.hb.n

    def amplitude(y):
        X = prob.xs * y[:-1]
        c, s = X[n:2 * n], X[2 * n:3 * n]
        a = np.hypot(c, s)
        d = np.zeros((n, y.size))
        safe = np.where(a > 0, a, 1.0)
        idx = np.arange(n)
        d[idx, n + idx] = c / safe * prob.xs[n + idx]
        d[idx, 2 * n + idx] = s / safe * prob.xs[2 * n + idx]
        return a, d
    return amplitude


def _chord_error_fn(prob: _Problem, tol: float, floor: np.ndarray | None):
    """``chord_error(y0, t0, y1, t1)``: largest error of the straight chord between two
    points in a DOF's amplitude, relative to ``tol`` times that DOF's running peak
    (at least ``floor``). The curve's midpoint is the cubic Hermite interpolant's;
    the error is measured at fixed frequency, or normal to the chord (x10) where the
    chord is steep (near folds)."""
    amplitude = _amplitude_fn(prob)
    top = np.zeros(prob.hb.n) if floor is None else np.array(floor, float)

    def chord_error(y0, t0, y1, t1):
        h = float(np.linalg.norm(y1 - y0))
        ym = 0.5 * (y0 + y1) + h * (t0 - t1) / 8.0
        a0, a1, am = amplitude(y0)[0], amplitude(y1)[0], amplitude(ym)[0]
        np.maximum(top, np.maximum(a0, a1), out=top)
        ref = np.where(top > 0, top, 1.0)
        da, dl = (a1 - a0) / ref, y1[-1] - y0[-1]
        ea, el = (am - 0.5 * (a0 + a1)) / ref, ym[-1] - 0.5 * (y0[-1] + y1[-1])
        with np.errstate(divide="ignore", invalid="ignore"):
            vertical = np.abs(ea - np.where(dl != 0, da / dl, 0.0) * el)
            normal = np.abs(ea * dl - el * da) / np.hypot(dl, da)
        err = np.where(np.isfinite(vertical), np.minimum(vertical, 10 * normal), normal)
        return float(np.nanmax(err)) / tol if err.size else 0.0
    return chord_error


def _to_hz(prob: _Problem):
    return lambda lam: float(lam * prob.ws / (2 * np.pi))


def _marked(prob: _Problem, ev: CurveEvent, n_peak: int) -> MarkedPoint:
    f, Xr, amp, trans = _point_quantities(prob, ev.y)
    peak = prob.hb.peak_abs(Xr.ravel(), n_peak)
    dof = None if ev.dof is None else prob.hb.system.dof_names[ev.dof]
    return MarkedPoint(ev.kind.value, float(ev.freq_hz), dof, ev.index, amp, peak,
                       float(trans), ev.converged, ev.interior)


def _events(prob: _Problem, br: Branch, opts: HBMOptions, turning, located):
    """Located folds and per-DOF peaks (empty without tangents); ``located``: folds
    already located on a finer re-trace, by turning-point index."""
    if not br.tangent or len(br.tangent) != len(br.y):
        return [], []
    settings = opts.continuation_settings()
    folds = []
    if len(turning):
        todo = Branch(y=br.y, tangent=br.tangent,
                      turning_points=[i for i in turning if i not in located])
        found = {e.index: e for e in locate_folds(prob, todo, settings, _to_hz(prob))}
        folds = [located.get(i) or found[i] for i in turning]
    peaks = locate_peaks(prob, br, settings, _to_hz(prob), _amplitude_fn(prob),
                         prob.hb.n)
    return ([_marked(prob, e, opts.n_peak) for e in folds],
            [_marked(prob, e, opts.n_peak) for e in peaks])


def postprocess(prob: _Problem, ys, opts: HBMOptions, br: Branch,
                turning, located=None) -> FrequencyResponse:
    """The :class:`FrequencyResponse` of the scaled points ``ys`` of ``prob``, with
    its folds (``located``: those already located on a finer re-trace) and peaks."""
    hb = prob.hb
    sysm = hb.system
    n, m, H = hb.n, hb.m, hb.H
    npts = len(ys)
    freq = np.empty(npts)
    coef = np.empty((npts, n, m))
    amp = np.empty((npts, n))
    peak = np.empty((npts, n))
    trans = np.empty(npts)
    stable = np.ones(npts, dtype=bool)
    fmr = np.full(npts, np.nan)
    for i, y in enumerate(ys):
        freq[i], Xr, amp[i], trans[i] = _point_quantities(prob, y)
        coef[i] = Xr.T
    if npts:
        peak[:] = hb.peak_abs(coef.transpose(0, 2, 1).reshape(npts, m * n),
                              opts.n_peak)
    if opts.stability and npts:
        stable[:], fmr[:] = _stability(prob, ys, br, opts.stability_stride)
    folds, peaks = _events(prob, br, opts, turning, located or {})
    return FrequencyResponse(
        turning_freq_hz=np.array([e.freq_hz for e in folds], dtype=float),
        freq_hz=freq, coefficients=coef, amplitude=amp, peak=peak,
        transmissibility=trans, stable=stable,
        turning_points=np.asarray(turning, dtype=int), success=br.success,
        status=br.status, message=br.message, n_newton=br.n_newton,
        n_steps=br.n_steps, dof_names=tuple(sysm.dof_names), harmonics=H,
        n_samples=0 if hb.closed_form else hb.n_samples, closed_form=hb.closed_form,
        floquet_max_real=fmr, newton_per_point=np.asarray(br.n_iter, dtype=int),
        system_name=sysm.name, folds=folds, peaks=peaks,
        transmissibility_label=_transmissibility_label(sysm))


def _transmissibility_label(sysm: System) -> str:
    """The transmissibility's definition (thesis eq. 4.1, 4.3) for a y label."""
    tr = sysm.transmissibility
    if tr.kind == "force":
        return ("force transmissibility [-]\n|F_mounts| / |F_exc| (fundamentals, "
                "eq. 4.1)")
    num = sysm.dof_names[tr.dof]
    den = (sysm.dof_names[tr.reference] if tr.reference is not None
           else "base input")
    return (f"displacement transmissibility [-]\n|{num}| / |{den}| (fundamentals, "
            f"eq. 4.3)")


def frequency_response(system: System, fmin_hz: float, fmax_hz: float, *,
                       harmonics: int | None = None, n_samples: int | None = None,
                       closed_form: bool | None = None,
                       options: HBMOptions | None = None,
                       progress: bool = False) -> FrequencyResponse:
    """Steady-state frequency-response curve by harmonic balance and arc length.

    Parameters
    ----------
    system : System
        The model (:mod:`hbm.systems` builds the thesis's three).
    fmin_hz, fmax_hz : float
        Frequency range, Hz, ``0 < fmin_hz < fmax_hz``.
    harmonics : int, optional
        Number of harmonics H, fixed. Default: ``options.harmonics`` (7), where the
        ``options.tol`` adaptation starts (it raises H and N until the estimated
        error is below ``tol / 2``, :mod:`hbm.error_estimate`).
    n_samples : int, optional
        AFT samples per period, fixed (default ``max(64, 8H)`` rounded to a power of
        2, raised by ``tol``); doubled up to ``options.refine_samples`` times when the
        continuation stalls, dead-ends at a kink of the sampled residual or finds no
        start.
    closed_form : bool, optional
        H = 1 closed forms (default: when H == 1 and every law has one).
    options : HBMOptions, optional
    progress : bool
        Show a tqdm progress bar on stderr over frequency.

    Returns
    -------
    FrequencyResponse
        ``success`` False (with the branch so far and ``message``) if the
        continuation stalled, also after refining the samples. With its error
        estimates, located folds and peaks; ``tol_met`` and ``message`` say whether
        the tolerance was met and, if not, why.

    Raises
    ------
    ValueError, TypeError
        Invalid input (before any work).

    References
    ----------
    Thesis eq. 3.51 (residual), 3.53-3.54 (Newton), 3.55-3.56 (tangent predictor),
    3.57-3.65 (arc length), 3.66 (step adaptation).

    Examples
    --------
    >>> from fmu_src.mount_law import AxisParameters, MountParameters
    >>> from hbm.systems import sdof
    >>> ax = AxisParameters(law="linear", friction=True, n0=20.0)
    >>> s = sdof(70.0, MountParameters(axial=ax), excitation="force", amplitude=40.0)
    >>> r = frequency_response(s, 2.0, 15.0, harmonics=1)
    >>> bool(r.success), r.freq_hz[0], r.freq_hz[-1]
    (True, 2.0, 15.0)
    """
    _check_range(fmin_hz, fmax_hz)
    H, N, opts = resolve_options(options, harmonics, n_samples)
    pin_h = harmonics is not None or closed_form is True
    pin_n = n_samples is not None
    floor, raised = None, []
    while True:
        result = _curve(system, fmin_hz, fmax_hz, H, N, closed_form, opts, progress,
                        floor)
        if opts.tol is None or not result.success:
            break
        trunc, samp = _nanmax(result.error_truncation), _nanmax(result.error_sampling)
        goal = 0.5 * opts.tol
        if trunc + samp <= goal:
            result.tol_met = True
            break
        H_new, N_new, why = _next_resolution(result, trunc, samp, goal, opts, pin_h,
                                             pin_n)
        if H_new is None:
            result.tol_met = False
            result.message += (f"; the error estimate {trunc + samp:.2g} of peak "
                               f"exceeds tol/2 = {goal:.2g} and {why}")
            break
        raised.append(f"H = {result.harmonics}, N = {result.n_samples}: estimate "
                      f"{trunc + samp:.2g}")
        floor = np.nanmax(result.amplitude, axis=0)
        H, N = H_new, N_new
    if raised:
        result.message += (f"; H and N raised to {result.harmonics}, "
                           f"{result.n_samples} for tol = {opts.tol:g} (from "
                           + "; ".join(raised) + ")")
    return result


def _nanmax(a) -> float:
    a = np.asarray(a, float)
    a = a[np.isfinite(a)]
    return float(a.max()) if a.size else float("nan")


def _curve(system, fmin_hz, fmax_hz, H, N, closed_form, opts, progress, floor
           ) -> FrequencyResponse:
    """One curve at (H, N), restarted past stalls (``opts.max_restarts``)."""
    if opts.max_restarts == 0:
        return _refined(system, fmin_hz, fmax_hz, H, N, closed_form, opts, progress,
                        floor)
    # Restarts: a new segment past the highest frequency reached, clipped to the band
    f0, parts, restarts = float(fmin_hz), [], []
    while True:
        fr = _refined(system, f0, fmax_hz, H, N, closed_form, opts, progress, floor)
        parts.append(clip(fr, float(fmin_hz), float(fmax_hz)))
        top = float(np.max(fr.freq_hz)) if len(fr.freq_hz) else f0
        if fr.success or top >= fmax_hz * (1 - 1e-9) or \
                len(restarts) >= opts.max_restarts:
            break
        f_next = max(top, f0) * opts.restart_factor
        if f_next >= fmax_hz:
            break
        restarts.append(Restart(f_next, fr.message))
        f0 = f_next
    return join(parts, restarts, float(fmax_hz))


def _next_resolution(result: FrequencyResponse, trunc: float, samp: float,
                     goal: float, opts: HBMOptions, pin_h: bool, pin_n: bool):
    """``(H, N, "")`` to trace next so the error estimate falls below ``goal``
    (truncation ~ H^-1.5, sampling ~ N^-2), or ``(None, None, why not)``."""
    if not (math.isfinite(trunc) and math.isfinite(samp)):
        return None, None, "the estimate failed at some points"
    H = result.harmonics
    N = result.n_samples if not result.closed_form else default_n_samples(H)
    H_new, N_new = H, N
    if trunc > 0.5 * goal and not pin_h:
        want = math.ceil(H * (trunc / (0.5 * goal)) ** (1 / 1.5))
        H_new = min(opts.max_harmonics, max(H + 2, min(want, 2 * H + 1)))
        if pin_n:
            H_new = max(H, min(H_new, (N - 1) // 2))  # N > 2H stays true
    if samp > 0.5 * goal and not pin_n:
        N_new = N << max(1, math.ceil(0.5 * math.log2(samp / (0.5 * goal))))
    if H_new != H and not pin_n:
        # the sampling error depends on N (where the kinks fall), hardly on N / H
        N_new = max(N_new, default_n_samples(H_new))
    N_new = min(N_new, opts.max_samples)
    if N_new <= 2 * H_new:
        N_new = N
    if H_new == H and N_new <= N:
        if pin_h and pin_n:
            why = f"H = {H} and N = {N} were fixed by the caller"
        elif pin_h and trunc > samp:
            why = f"H = {H} was fixed by the caller (truncation {trunc:.2g})"
        else:
            why = (f"H = {H}, N = {N} are at the caps max_harmonics = "
                   f"{opts.max_harmonics}, max_samples = {opts.max_samples} "
                   f"(truncation {trunc:.2g}, sampling {samp:.2g})")
        return None, None, why
    return H_new, N_new, ""


def _refined(system: System, fmin_hz: float, fmax_hz: float, H: int, N, closed_form,
             opts: HBMOptions, progress: bool, floor=None) -> FrequencyResponse:
    """One curve from ``fmin_hz`` to ``fmax_hz`` with its error estimates; traced
    again with twice the AFT samples (at most ``opts.refine_samples`` times) when it
    dead-ends or stalls at a kink of the sampled residual (the kinks shrink with more
    samples) or finds no start (then also with a 4x smaller first step)."""
    prob = build_problem(system, fmin_hz, fmax_hz, H, N, closed_form)
    result, br = _trace(prob, fmin_hz, fmax_hz, opts, progress, floor)
    history = []
    refine = 0
    while (not result.success and result.status in (Status.STEP_TOO_SMALL,
                                                    Status.RETRACED, Status.NO_START)
           and not prob.hb.closed_form and refine < opts.refine_samples):
        refine += 1
        history.append(f"with {prob.hb.n_samples} AFT samples {result.message}")
        if result.status is Status.NO_START:
            opts = dataclasses.replace(opts, ds_initial=max(opts.ds_initial / 4,
                                                            opts.ds_min))
        prob = build_problem(system, fmin_hz, fmax_hz, H, 2 * prob.hb.n_samples,
                             closed_form)
        result, br = _trace(prob, fmin_hz, fmax_hz, opts, progress, floor)
    if history:
        first = any("no solution at fmin" in h for h in history)
        result.message += (f" (AFT samples raised to {prob.hb.n_samples}"
                           + (f", first step {opts.ds_initial:g}" if first else "")
                           + ": " + "; ".join(history) + ")")
    _estimate(system, fmin_hz, fmax_hz, prob, br, opts, result)
    return result


def _estimate(system, fmin_hz, fmax_hz, prob, br, opts, result) -> None:
    """Error estimates of the traced points into ``result`` (if wanted).

    Re-solved at every ``ESTIMATE_STRIDE``-th point, at the ends and around the
    turning points; a point in between gets the larger estimate of the two re-solved
    points around it (a per-segment estimate)."""
    if not (opts.error_estimate or opts.tol is not None) or not br.y:
        return

    def make(H, N, cf):
        return build_problem(system, fmin_hz, fmax_hz, H, N, cf)

    npts = len(br.y)
    pts = sorted(set(range(0, npts, ESTIMATE_STRIDE)) | {npts - 1}
                 | {j for i in br.turning_points for j in (i - 1, i)})
    est = estimate_errors(prob, br.y, br.tangent, make, opts.continuation_settings(),
                          opts.n_peak, pts)
    for arr in (est.truncation, est.sampling):
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if b - a > 1:
                arr[a + 1:b] = np.maximum(arr[a], arr[b])  # NaN if either failed
    result.set_errors(est)


def _trace(prob: _Problem, fmin_hz: float, fmax_hz: float, opts: HBMOptions,
           progress: bool, floor=None):
    """One continuation of ``prob`` from ``fmin_hz`` to ``fmax_hz`` (steps within the
    chord tolerance with ``opts.tol``), spurious turning points merged. Returns
    ``(FrequencyResponse, Branch)``."""
    H = prob.hb.H
    settings = opts.continuation_settings()
    chord = None if opts.tol is None else _chord_error_fn(prob, 0.5 * opts.tol, floor)
    bar = None
    if progress:
        from tqdm import tqdm
        desc = f"HBM H={H}"
        if not prob.hb.closed_form:
            desc += f" N={prob.hb.n_samples}"
        bar = tqdm(total=round(fmax_hz - fmin_hz, 6), unit="Hz", file=sys.stderr,
                   desc=desc, bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} Hz "
                   "[{elapsed}<{remaining}]")
    try:
        y0, its0, msg = _start(prob, fmin_hz, settings)
        if y0 is None:
            br = Branch(status=Status.NO_START,
                        message=f"no solution at fmin = {fmin_hz} Hz ({msg})",
                        n_newton=its0)
            return postprocess(prob, [], opts, br, []), br
        done = [fmin_hz]

        def callback(lam):
            if bar is not None:
                f = min(lam * prob.ws / (2 * np.pi), fmax_hz)
                if f > done[0]:
                    bar.update(f - done[0])
                    done[0] = f

        lam_end = 2 * np.pi * fmax_hz / prob.ws
        br = continue_branch(prob, y0, lam_end, settings,
                             lam_start=2 * np.pi * fmin_hz / prob.ws, callback=callback,
                             chord_error=chord)
        br.n_newton += its0
        br.message = _lam_to_hz(br.message, prob)
        if br.n_iter:
            br.n_iter[0] = its0
    except KeyboardInterrupt as exc:
        # the points traced before the interrupt, for the caller to write
        br = getattr(exc, "branch", None)
        if br is not None and br.y:
            br.message = (f"interrupted after {len(br.y)} points at "
                          f"{br.y[-1][-1] * prob.ws / (2 * np.pi):.6g} Hz")
            exc.partial_result = postprocess(prob, br.y, opts, br,
                                             br.turning_points)
        raise
    finally:
        if bar is not None:
            bar.close()
    zz = _merge_zigzags(prob, br, opts)
    result = postprocess(prob, br.y, opts, br, br.turning_points, zz.folds)
    result.turning_points_merged = zz.merged
    if zz.refined:
        result.message += "; " + "; ".join(
            f"{f0:.4g}-{f1:.4g} Hz re-traced with more AFT samples ({k} points: "
            f"zigzags of the sampled residual)" for f0, f1, k in zz.refined)
    return result, br


def _merge_zigzags(prob: _Problem, br: Branch, opts: HBMOptions):
    """Merge turning-point clusters that vanish with ``opts.zigzag_refine`` (then its
    square) times the samples."""
    fines = []
    if not prob.hb.closed_form and opts.zigzag_refine > 1 and \
            len(br.turning_points) >= 2:
        for level in (1, 2):
            N = prob.hb.n_samples * opts.zigzag_refine ** level
            if N > max(opts.max_samples, 4 * prob.hb.n_samples):
                break
            fine = build_problem(prob.hb.system, *prob.f_ends, prob.hb.H, N, False)
            fine.xs, fine.ws, fine.rs = prob.xs, prob.ws, prob.rs  # same unknowns
            fines.append(fine)
    return merge_spurious_pairs(br, fines, opts.continuation_settings(),
                                opts.zigzag_span, _to_hz(prob))


def solve_frequencies(system: System, freqs_hz, *, harmonics: int | None = None,
                      n_samples: int | None = None, closed_form: bool | None = None,
                      options: HBMOptions | None = None,
                      progress: bool = False) -> FrequencyResponse:
    """Harmonic-balance solutions at given frequencies (natural parametrisation).

    Each frequency is solved by Newton (eq. 3.53) from the tangent prediction
    (eq. 3.55-3.56) of the previous solution; the first from the linear FRF. Does not
    follow folds: on a fold the prediction may land on another branch. Stops at the
    first failure and returns the points so far with ``success=False``.

    Parameters
    ----------
    freqs_hz : array_like, shape (n_freq,)
        Frequencies, Hz (> 0).

    Other parameters as :func:`frequency_response`.
    """
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError(f"`freqs_hz` must be a non-empty 1-D array of finite "
                         f"frequencies > 0 Hz, got {freqs_hz!r}")
    H, N, opts = resolve_options(options, harmonics, n_samples)
    fmin, fmax = float(f.min()), float(f.max())
    if fmax == fmin:
        fmax = fmin * 1.5
    prob = build_problem(system, fmin, fmax, H, N, closed_form)
    settings = opts.continuation_settings()
    n = prob.hb.size
    br = Branch()
    ys = []
    iterator = f
    if progress:
        from tqdm import tqdm
        iterator = tqdm(f, unit="freq", file=sys.stderr, desc=f"HBM H={H}")
    y_prev = None
    dy = None
    for fi in iterator:
        lam = 2 * np.pi * fi / prob.ws
        guesses = []
        if y_prev is not None:
            if dy is not None:
                guesses.append(y_prev + dy * (lam - y_prev[-1]))
            g = y_prev.copy()
            g[-1] = lam
            guesses.append(g)
        guesses += [prob.linear_guess(fi, False), prob.linear_guess(fi, True)]
        ok = False
        for g in guesses:
            y, ok, its, msg = newton(prob, g, settings, fixed=n)
            br.n_newton += its
            br.n_steps += 1
            if ok:
                break
        if not ok:
            br.status = Status.NO_CONVERGENCE
            br.message = f"no convergence at {fi:.6g} Hz ({msg})"
            break
        ys.append(y)
        br.n_iter.append(its)
        # tangent dX/dlam = -J_x^{-1} J_lam (eq. 3.56)
        _, J = prob(y)
        br.jacobian.append(J)
        try:
            dx = np.linalg.solve(J[:, :n], -J[:, n])
            dy = np.append(dx, 1.0)
        except np.linalg.LinAlgError:
            dy = None
        y_prev = y
    else:
        br.success, br.status = True, Status.DONE
        br.message = "solved at every frequency"
    result = postprocess(prob, ys, opts, br, [])
    if opts.error_estimate:
        _estimate(system, fmin, fmax, prob, br, opts, result)
    return result
