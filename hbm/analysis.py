"""Frequency-response curves by harmonic balance: the user-facing drivers.

- :func:`frequency_response`: arc-length continuation from ``fmin`` to ``fmax``
  (thesis Sec. 3.2, eq. 3.57-3.66), through folds, with turning points and stability.
- :func:`solve_frequencies`: Newton at given frequencies, each started from the tangent
  prediction of the previous solution (eq. 3.53-3.56); for validation.

Both return a :class:`hbm.result.FrequencyResponse`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import sys

import numpy as np

from drymount.hbm.continuation import Branch, Status, continue_branch, newton
from drymount.hbm.error_estimate import estimate_errors
from drymount.hbm.folds import merge_spurious_pairs
from drymount.hbm.options import MULTI_DOF, HBMOptions
from drymount.hbm.postprocess import postprocess
from drymount.hbm.problem import (
    _check_range,
    _chord_error_fn,
    _lam_to_hz,
    _Problem,
    _start,
    _to_hz,
    build_problem,
    resolve_options,
)
from drymount.hbm.resolution import first_samples, next_resolution, probe
from drymount.hbm.result import FrequencyResponse, finite_max
from drymount.hbm.segments import Restart, clip, join
from drymount.hbm.system import System

__all__ = ["frequency_response", "solve_frequencies"]

#: The error estimate re-solves every ESTIMATE_STRIDE-th point (and the points around
#: turning points); the points between get the larger of their neighbours' estimates.
#: Long curves (the 6-DOF presets: about 500 points) get a larger stride, so that
#: about MAX_ESTIMATED points are re-solved.
ESTIMATE_STRIDE = 4
MAX_ESTIMATED = 48

@dataclasses.dataclass
class _Level:
    """What traced one curve, kept to probe other resolutions and to finish it."""

    prob: _Problem
    br: Branch
    located: dict
    light: bool


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
        2, for more than 3 DOF with ``tol`` ``max(64, 16H)``
        (:func:`hbm.resolution.first_samples`), raised by ``tol``); doubled up to
        ``options.refine_samples`` times when the continuation stalls, dead-ends at
        a kink of the sampled residual or finds no start.
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
    >>> from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    >>> from drymount.hbm.systems import sdof
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
    if N is None and opts.tol is not None and closed_form is not True:
        N = first_samples(system.n_dof, H)  # None: the default
    # curves traced only to estimate their error skip stability and events; the last
    # one gets them (_finish)
    light = opts.tol is not None and opts.max_restarts == 0
    floor, raised, result = None, [], None
    while True:
        try:
            result = _curve(system, fmin_hz, fmax_hz, H, N, closed_form, opts,
                            progress, floor, light)
        except Exception as exc:  # a failure at a raised resolution: keep the last
            _attach_partial(exc, result, opts)  # whole curve for the caller to write
            raise
        if opts.tol is None or not result.success:
            break
        trunc = finite_max(result.error_truncation)
        samp = finite_max(result.error_sampling)
        goal = 0.5 * opts.tol
        if trunc + samp <= goal:
            result.tol_met = True
            break
        cap = opts.harmonics_cap(system.n_dof)
        H_new, N_new, why = next_resolution(result, trunc, samp, goal, opts, pin_h,
                                             pin_n, cap)
        probes = []
        if H_new is not None and system.n_dof > MULTI_DOF:  # where curves are costly
            try:
                H_new, N_new, probes = probe(system, fmin_hz, fmax_hz, result, H_new,
                                              N_new, goal, opts, pin_h, pin_n, cap)
            except Exception as exc:
                _attach_partial(exc, result, opts)
                raise
        if H_new is None:
            result.tol_met = False
            result.message += (f"; the error estimate {trunc + samp:.2g} of peak "
                               f"exceeds tol/2 = {goal:.2g} and {why}")
            break
        raised.append(f"H = {result.harmonics}, N = {result.n_samples}: estimate "
                      f"{trunc + samp:.2g}" + (" (probes, truncation + sampling at "
                                              "a few points: " + ", ".join(probes)
                                              + ")" if probes else ""))
        floor = np.nanmax(result.amplitude, axis=0)
        H, N = H_new, N_new
    if raised:
        result.message += (f"; H and N raised to {result.harmonics}, "
                           f"{result.n_samples} for tol = {opts.tol:g} (from "
                           + "; ".join(raised) + ")")
    return _finish(result, opts)


def _attach_partial(exc: Exception, result: FrequencyResponse | None,
                    opts: HBMOptions) -> None:
    """Give ``exc`` the last whole curve (``partial_result``, what the CLI writes
    marked partial) unless it carries one already."""
    if result is None or getattr(exc, "partial_result", None) is not None:
        return
    with contextlib.suppress(Exception):  # the original error is what matters
        result.message += (f"; stopped while raising H and N: "
                           f"{type(exc).__name__}: {exc}")
        exc.partial_result = _finish(result, opts)


def _finish(result: FrequencyResponse, opts: HBMOptions) -> FrequencyResponse:
    """The curve with stability and located folds and peaks, if it was traced
    without them (a light level)."""
    level = result.__dict__.pop("_level", None)
    if level is None or not level.light:
        return result
    full = postprocess(level.prob, level.br.y, opts, level.br,
                       level.br.turning_points, level.located)
    for name in ("message", "error_truncation", "error_sampling", "error_reference",
                 "tol_met", "turning_points_merged", "samples_per_point"):
        setattr(full, name, getattr(result, name))
    return full


def _curve(system, fmin_hz, fmax_hz, H, N, closed_form, opts, progress, floor,
           light=False) -> FrequencyResponse:
    """One curve at (H, N), restarted past stalls (``opts.max_restarts``); ``light``
    (only without restarts): without stability and events, for :func:`_finish`."""
    if opts.max_restarts == 0:
        return _refined(system, fmin_hz, fmax_hz, H, N, closed_form, opts, progress,
                        floor, light)
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


def _refined(system: System, fmin_hz: float, fmax_hz: float, H: int, N, closed_form,
             opts: HBMOptions, progress: bool, floor=None, light=False
             ) -> FrequencyResponse:
    """One curve from ``fmin_hz`` to ``fmax_hz`` with its error estimates; traced
    again with twice the AFT samples (at most ``opts.refine_samples`` times) when it
    dead-ends or stalls at a kink of the sampled residual (the kinks shrink with more
    samples) or finds no start (then also with a 4x smaller first step)."""
    prob = build_problem(system, fmin_hz, fmax_hz, H, N, closed_form)
    result, br = _trace(prob, fmin_hz, fmax_hz, opts, progress, floor, light)
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
        result, br = _trace(prob, fmin_hz, fmax_hz, opts, progress, floor, light)
    if history:
        first = any("no solution at fmin" in h for h in history)
        result.message += (f" (AFT samples raised to {prob.hb.n_samples}"
                           + (f", first step {opts.ds_initial:g}" if first else "")
                           + ": " + "; ".join(history) + ")")
    _estimate(system, fmin_hz, fmax_hz, prob, br, opts, result)
    return result


def _estimate(system, fmin_hz, fmax_hz, prob, br, opts, result) -> None:
    """Error estimates of the traced points into ``result`` (if wanted).

    Re-solved at every ``ESTIMATE_STRIDE``-th point (fewer on long curves,
    ``MAX_ESTIMATED``), at the ends and around the
    turning points; a point in between gets the larger estimate of the two re-solved
    points around it (a per-segment estimate)."""
    if not (opts.error_estimate or opts.tol is not None) or not br.y:
        return

    def make(H, N, cf):
        return build_problem(system, fmin_hz, fmax_hz, H, N, cf)

    npts = len(br.y)
    stride = max(ESTIMATE_STRIDE, math.ceil(npts / MAX_ESTIMATED))
    pts = sorted(set(range(0, npts, stride)) | {npts - 1}
                 | {j for i in br.turning_points for j in (i - 1, i)})
    est = estimate_errors(prob, br.y, br.tangent, make, opts.continuation_settings(),
                          opts.n_peak, pts)
    for arr in (est.truncation, est.sampling):
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if b - a > 1:
                arr[a + 1:b] = np.maximum(arr[a], arr[b])  # NaN if either failed
    result.set_errors(est)


def _trace(prob: _Problem, fmin_hz: float, fmax_hz: float, opts: HBMOptions,
           progress: bool, floor=None, light=False):
    """One continuation of ``prob`` from ``fmin_hz`` to ``fmax_hz`` (steps within the
    chord tolerance with ``opts.tol``), spurious turning points merged. Returns
    ``(FrequencyResponse, Branch)``; the result keeps what traced it (``_level``),
    and ``light`` leaves out stability and located folds and peaks."""
    settings = opts.continuation_settings()
    chord = None if opts.tol is None else _chord_error_fn(prob, 0.5 * opts.tol, floor)
    bar = _frequency_bar(prob, fmin_hz, fmax_hz) if progress else None
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
        if bar is not None and br.status is Status.DONE:  # full, not short by the
            bar.update(bar.total - bar.n)                  # round-off of its steps
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
    return _traced_result(prob, br, opts, light), br


def _frequency_bar(prob: _Problem, fmin_hz: float, fmax_hz: float):
    """The progress bar of :func:`_trace` (tqdm on stderr, in Hz)."""
    from tqdm import tqdm
    desc = f"HBM H={prob.hb.H}"
    if not prob.hb.closed_form:
        desc += f" N={prob.hb.n_samples}"
    return tqdm(total=round(fmax_hz - fmin_hz, 6), unit="Hz", file=sys.stderr,
                desc=desc, bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} Hz "
                "[{elapsed}<{remaining}]")


def _traced_result(prob: _Problem, br: Branch, opts: HBMOptions, light: bool):
    """The curve of the traced branch ``br``: spurious turning points merged, then
    post-processed (without stability, folds and peaks if ``light``)."""
    zz = _merge_zigzags(prob, br, opts)
    post = dataclasses.replace(opts, stability=False) if light else opts
    result = postprocess(prob, br.y, post, br, br.turning_points, zz.folds,
                         events=not light)
    result._level = _Level(prob, br, zz.folds, light)
    result.turning_points_merged = zz.merged
    if zz.fine_points:
        result.samples_per_point = np.full(result.n_points, prob.hb.n_samples)
        for i, j in zz.fine_points.items():
            result.samples_per_point[i] = zz.fine_samples[j]
    if zz.refined:
        result.message += "; " + "; ".join(
            f"{f0:.4g}-{f1:.4g} Hz re-traced with more AFT samples ({k} points: "
            f"zigzags of the sampled residual)" for f0, f1, k in zz.refined)
    return result


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
    rep = merge_spurious_pairs(br, fines, opts.continuation_settings(),
                               opts.zigzag_span, _to_hz(prob))
    rep.fine_samples = [fine.hb.n_samples for fine in fines]
    return rep


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

