"""How far the ``tol`` adaptation of :func:`hbm.frequency_response` raises H and N.

After a curve misses the tolerance, :func:`next_resolution` gives the next (H, N) by a
rule (truncation ~ H^-1.5, sampling ~ N^-2, at most doubling H), and for systems of
more than ``MULTI_DOF`` DOF :func:`probe` refines that guess by trying resolutions at a
few points of the curve in hand before a whole curve is traced.
"""

from __future__ import annotations

import math

import numpy as np

from drymount.hbm.aft import default_n_samples
from drymount.hbm.error_estimate import curve_scale, probe_errors
from drymount.hbm.options import ADAPTIVE_MAX_HARMONICS, MULTI_DOF, HBMOptions
from drymount.hbm.problem import build_problem
from drymount.hbm.result import FrequencyResponse, finite_max

__all__ = ["next_resolution", "probe", "first_samples", "PROBE_POINTS", "PROBE_SPREAD",
           "MAX_PROBES", "PROBE_MARGIN", "FIRST_SAMPLES_PER_HARMONIC"]

#: AFT samples per harmonic of the ``tol`` adaptation's first curve for systems of
#: more than MULTI_DOF DOF (:func:`first_samples`; the default elsewhere is 8). That
#: curve is mostly traced only for its error estimate, and its sampled residual's
#: kinks (a stick-slip switch or a knee moving from one sample to the next, on every
#: nonlinear axis) set its cost: on six_dof_halved at H = 5 the curve took 730 points
#: and 2625 Newton iterations at N = 64, 660 and 1851 at N = 128 (2.56 s against
#: 1.38 s CPU); six_dof_original 6.1 s -> 3.3 s, six_dof_lambda12 11.7 s -> 5.8 s.
FIRST_SAMPLES_PER_HARMONIC = 16

#: Before ``tol`` makes a whole curve be traced at a higher resolution, that
#: resolution is tried at the PROBE_POINTS points with the largest estimates (half by
#: truncation, half by sampling), each DOF's largest amplitude, the turning points
#: and PROBE_SPREAD points spread over the curve: re-solved there and estimated like
#: curve points.
#: The errors of two resolutions give the decay rates (``H^-p``, ``N^-q``), from
#: which the smallest H and N expected to meet the tolerance are predicted and probed
#: in turn (at most MAX_PROBES probes per raise). The next whole curve then has its
#: own full estimate, which decides. Only for systems of more than MULTI_DOF DOF: a
#: curve of a small system costs about as much as the probes, and their margin made
#: sdof_microslip take N = 256 where the curve at 128 meets the tolerance (7.0 s
#: instead of 3.5 s).
PROBE_POINTS = 8
PROBE_SPREAD = 16
MAX_PROBES = 3
#: The whole curve's largest estimate exceeded the probes' by up to 3x (measured on
#: six_dof_halved and six_dof_original with the worst points only: the worst points
#: move between resolutions), so a probe has to meet the goal / PROBE_MARGIN.
PROBE_MARGIN = 2.0


def first_samples(n_dof: int, harmonics: int) -> int | None:
    """AFT samples of the ``tol`` adaptation's first curve when the caller chose
    none: ``max(64, 16 H)`` rounded up to a power of two for systems of more than
    ``MULTI_DOF`` DOF (:data:`FIRST_SAMPLES_PER_HARMONIC`), None (the default of
    :func:`hbm.aft.default_n_samples`) for smaller ones, whose curves are cheap."""
    if n_dof <= MULTI_DOF:
        return None
    n = max(64, FIRST_SAMPLES_PER_HARMONIC * harmonics)
    return 1 << (n - 1).bit_length()


def next_resolution(result: FrequencyResponse, trunc: float, samp: float,
                     goal: float, opts: HBMOptions, pin_h: bool, pin_n: bool,
                     cap: int):
    """``(H, N, "")`` to trace next so the error estimate falls below ``goal``
    (truncation ~ H^-1.5, sampling ~ N^-2), or ``(None, None, why not)``."""
    if not (math.isfinite(trunc) and math.isfinite(samp)):
        return None, None, "the estimate failed at some points"
    H = result.harmonics
    N = result.n_samples if not result.closed_form else default_n_samples(H)
    H_new, N_new = H, N
    if trunc > 0.5 * goal and not pin_h:
        want = math.ceil(H * (trunc / (0.5 * goal)) ** (1 / 1.5))
        # never above the cap, never below the curve's own H (a curve started above
        # the cap stays where it is)
        H_new = max(H, min(cap, max(H + 2, min(want, 2 * H + 1))))
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
            default = (" (the default for systems of more than 3 DOF; set "
                       "max_harmonics to raise it)"
                       if opts.max_harmonics is None and cap < ADAPTIVE_MAX_HARMONICS
                       else "")
            why = (f"H = {H}, N = {N} are at the caps max_harmonics = {cap}"
                   f"{default}, max_samples = {opts.max_samples} "
                   f"(truncation {trunc:.2g}, sampling {samp:.2g})")
        return None, None, why
    return H_new, N_new, ""


def _probe_points(result: FrequencyResponse) -> list[int]:
    """The points with the largest truncation and sampling estimates (half each),
    each DOF's largest amplitude and the turning points (where the errors of a
    finer resolution concentrate)."""
    picked = [int(i) for i in np.argmax(result.amplitude, axis=0)] if \
        result.n_points else []
    picked += [int(i) for i in result.turning_points]
    # and points spread over the whole curve
    picked += [int(i) for i in np.linspace(0, result.n_points - 1, PROBE_SPREAD)]
    for e in (result.error_truncation, result.error_sampling):
        e = np.where(np.isfinite(e), e, -np.inf)
        seen = set()
        for i in np.argsort(-e, kind="stable"):
            if len(seen) >= PROBE_POINTS // 2 or not np.isfinite(e[i]):
                break
            if e[i] in seen or int(i) in picked:  # interpolated copies of a point
                continue
            seen.add(e[i])
            picked.append(int(i))
    return sorted(set(picked))


def _fit_level(x0, e0, x1, e1, target, lo, hi, default_rate):
    """Smallest x in [lo, hi] with error below ``target`` for errors ``e0`` at x0 and
    ``e1`` at x1 decaying like ``x^-p`` (p fitted from the two, else
    ``default_rate``)."""
    lo = min(lo, hi)  # the cap wins over the floor (a curve already at the cap)
    if not (np.isfinite(e1) and e1 > 0):
        return max(lo, min(x1, hi))
    x = x1 * (e1 / target) ** (1.0 / _rate(x0, e0, x1, e1, default_rate))
    return int(max(lo, min(math.ceil(x - 1e-9), hi)))


def _rate(x0, e0, x1, e1, default_rate) -> float:
    """Decay rate p of errors ``e ~ x^-p`` through (x0, e0) and (x1, e1) (clipped to
    0.5..8), or ``default_rate`` if they do not decay."""
    if x1 > x0 and np.isfinite(e0) and np.isfinite(e1) and e0 > e1 > 0:
        return float(np.clip(math.log(e0 / e1) / math.log(x1 / x0), 0.5, 8.0))
    return default_rate


def probe(system, fmin_hz, fmax_hz, result, H1, N1, goal, opts, pin_h, pin_n, cap):
    """``(H, N, notes)``: the resolution to trace next, predicted from probes at a few
    points of ``result`` (PROBE_POINTS, MAX_PROBES); ``(H1, N1)`` (the rule of
    :func:`_next_resolution`) is the first probe. Without the curve's branch (a
    curve of restarted segments) ``(H1, N1, [])``. No probe and no prediction is
    above ``cap`` or below the curve's own H (a probe starts from the curve's
    points, which are padded to the probe's H, never truncated)."""
    level = getattr(result, "_level", None)
    pts = _probe_points(result)
    if level is None or not pts or not level.br.tangent:
        return H1, N1, []

    def make(H, N, cf):
        return build_problem(system, fmin_hz, fmax_hz, H, N, cf)

    H0 = result.harmonics
    N0 = result.n_samples if not result.closed_form else default_n_samples(H0)
    if H1 < H0:
        raise ValueError(f"a probe at H = {H1} below the curve's H = {H0}")
    t0 = finite_max(result.error_truncation[pts])
    s0 = finite_max(result.error_sampling[pts]) if not result.closed_form else np.nan
    scale = curve_scale(level.prob, level.br.y, opts.n_peak)
    settings = opts.continuation_settings()
    half = 0.5 * goal / PROBE_MARGIN  # truncation target
    tried, best, notes = {}, None, []
    H, N = H1, N1
    for _ in range(MAX_PROBES):
        est = probe_errors(level.prob, level.br.y, level.br.tangent, pts, make,
                           settings, opts.n_peak, H, N, scale)
        if est is None:
            break
        t, s_ = est.max()
        tried[(H, N)] = (t, s_)
        notes.append(f"H = {H}, N = {N}: {t:.2g} + {s_:.2g}")
        if PROBE_MARGIN * (t + s_) <= goal and (best is None or
                                                _cost(H, N) < _cost(*best)):
            best = (H, N)
        # the next candidate from the decay between the curve and this probe
        H_next = H if pin_h else _fit_level(H0, t0, H, t, half, H0 + (t0 > half),
                                            max(cap, H0), 1.5)
        N_next = N
        if not pin_n:
            # sampling need not be far below the truncation left at the cap
            t_left = t * (H / H_next) ** _rate(H0, t0, H, t, 1.5)
            n_min = _pow2(max(default_n_samples(H_next), 2 * H_next + 2))
            n_fit = _fit_level(N0, s0, N, s_, max(half, 0.25 * t_left),
                               n_min, opts.max_samples, 2.0)
            N_next = min(max(_pow2(n_fit), n_min),
                         max(opts.max_samples, 2 * H_next + 2))
        if (H_next, N_next) in tried or (best is not None and
                                         _cost(H_next, N_next) >= _cost(*best)):
            break
        H, N = H_next, N_next
    else:
        H_next, N_next = H, N
    if best is None:  # no probe met it: the last prediction (capped)
        best = (H_next, N_next)
    if best[0] <= H0 and best[1] <= N0:  # never the curve's own resolution again
        best = (H1, N1)
    return best[0], best[1], notes


def _pow2(n: int) -> int:
    """The smallest power of two >= n."""
    return 1 << (max(int(n), 1) - 1).bit_length()


def _cost(H: int, N: int) -> float:
    """Relative cost of a curve at H harmonics and N samples (Jacobian ~ H^2, AFT
    ~ N H)."""
    return H * H + N * H / 8
