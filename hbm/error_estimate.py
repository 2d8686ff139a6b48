"""Per-point error estimates of a harmonic-balance curve: truncation and sampling.

At every point of a curve computed with H harmonics and N AFT samples the solution is
re-solved at the same frequency (Newton, from the point itself)

- with ``2N`` samples and H harmonics: the change is the **sampling** error (the
  aliasing of the sampled nonsmooth law; zero with the H = 1 closed forms), and
- with ``2N`` samples and ``max(2H, H + 2)`` harmonics: the further change is the
  **truncation** error (the harmonics above H that the curve leaves out; ``H + 2``
  so that the odd-only response of a symmetric law at H = 1 sees its 3rd harmonic).

The re-solve moves normal to the branch (the pseudo-arclength corrector from the
point, along its tangent): the error is the distance between the curves, which stays
meaningful where the curve is steep or folds (a fixed-frequency comparison there
turns a tiny shift in frequency into a large one in amplitude). It is measured on the
quantities of the CSV, each DOF's fundamental amplitude and ``max |q(t)|`` relative to
that quantity's largest value on the curve, combined with the frequency shift
relative to ``fmax - fmin`` (``hypot``); the largest over the quantities is reported.
Without tangents (:func:`hbm.solve_frequencies`) the re-solve is at fixed frequency.
The true error of an algebraically converging expansion (``H^-1.5..2``) is 1.3-1.6
times the change to ``2H`` (Richardson), which :data:`RICHARDSON` applies.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drymount.hbm.continuation import ContinuationSettings, newton
from drymount.hbm.result import finite_max

__all__ = ["ErrorEstimate", "estimate_errors", "curve_quantities", "RICHARDSON",
           "probe_errors", "curve_scale"]

#: Factor from the change between H and 2H harmonics (N and 2N samples) to the error
#: of the H (N) solution, for convergence like ``H^-p`` with p about 1.5:
#: ``1 / (1 - 2^-1.5)``.
RICHARDSON = 1.0 / (1.0 - 2.0 ** -1.5)


@dataclass
class ErrorEstimate:
    """Estimated errors of each curve point, relative to the curve's peak.

    Attributes
    ----------
    truncation : ndarray, shape (n_points,)
        Error from the harmonics above H (NaN where the re-solve failed).
    sampling : ndarray, shape (n_points,)
        Error from the N AFT samples (0 with closed forms).
    harmonics_ref, n_samples_ref : int
        Resolution of the reference solves (2H, 2N).
    """

    truncation: np.ndarray
    sampling: np.ndarray
    harmonics_ref: int
    n_samples_ref: int

    @property
    def total(self) -> np.ndarray:
        return self.truncation + self.sampling

    def max(self) -> tuple[float, float]:
        """Largest ``(truncation, sampling)`` over the points (NaN-aware)."""
        return finite_max(self.truncation), finite_max(self.sampling)

    def summary(self) -> str:
        t, s = self.max()
        failed = int(np.sum(~np.isfinite(self.truncation)))
        out = (f"error estimate (relative to peak): truncation {t:.2g}, sampling "
               f"{s:.2g} (references H = {self.harmonics_ref}, "
               f"N = {self.n_samples_ref})")
        if failed:
            out += f"; {failed} point(s) could not be re-solved"
        return out


def curve_quantities(hb, X: np.ndarray, n_peak: int) -> np.ndarray:
    """Fundamental amplitude and ``max |q(t)|`` of each DOF, shape (2 n_dof,)."""
    Xr = X.reshape(hb.m, hb.n)
    amp = np.hypot(Xr[1], Xr[2])
    return np.concatenate([amp, hb.peak_abs(X, n_peak)])


def _pad(X: np.ndarray, hb, hb_ref) -> np.ndarray:
    """Coefficients of ``hb`` (H harmonics) as those of ``hb_ref`` (as many or more
    harmonics: a solution is never cut down to fewer)."""
    if hb_ref.m < hb.m:
        raise ValueError(f"cannot pad a solution of H = {hb.H} harmonics into one of "
                         f"H = {hb_ref.H}: the reference must not have fewer")
    out = np.zeros((hb_ref.m, hb_ref.n))
    out[:hb.m] = X.reshape(hb.m, hb.n)
    return out.ravel()


def _resolve(prob_ref, X_guess, omega, t_dir, settings):
    """The point of ``prob_ref``'s branch nearest to ``(X_guess, omega)``: Newton on
    the hyperplane normal to the branch direction ``t_dir`` (unscaled coefficients,
    omega), or at fixed omega without a direction (or if that fails). Returns
    ``(X, omega)`` or None."""
    n = prob_ref.hb.size
    y0 = prob_ref.y_of(X_guess, omega)
    if t_dir is not None:
        t = np.append(t_dir[0] / prob_ref.xs, t_dir[1] / prob_ref.ws)
        t /= np.linalg.norm(t)
        y, ok, _, _ = newton(prob_ref, y0, settings, tangent=t, y_pred=y0,
                             jacobian_at_root=False)
        if ok:
            return prob_ref.x_of(y)
    y, ok, _, _ = newton(prob_ref, y0, settings, fixed=n, jacobian_at_root=False)
    return prob_ref.x_of(y) if ok else None


def estimate_errors(prob, ys: list, tangents: list, make_problem: Callable,
                    settings: ContinuationSettings, n_peak: int,
                    points=None, scale=None) -> ErrorEstimate:
    """Truncation and sampling errors of the curve points ``ys`` of ``prob``.

    ``make_problem(H, N, closed_form)`` builds the problem at another resolution over
    the same frequency range. ``tangents`` are the branch tangents of the points
    (scaled), used near folds. ``points``: indices to estimate (default all; the
    others are NaN). Every re-solve starts from the point itself: a warm start from
    the previous point's correction (as once here) can reach a farther crossing of
    the normal plane with the slightly zigzagging branch of a sampled nonsmooth
    residual, and over-estimated the friction case of tests/test_hbm_accuracy.py up
    to 9.5x at single points (now 1.5-2.5x). ``scale``: the largest value of each
    quantity (:func:`curve_quantities`) the errors are relative to (default: over
    ``ys`` and the re-solves).
    """
    hb = prob.hb
    H = hb.H
    N2 = 2 * hb.n_samples if not hb.closed_form else max(64, 16 * H)
    samp_prob = None if hb.closed_form else make_problem(H, N2, False)
    H2 = max(2 * H, H + 2)  # H + 2: odd-only responses (symmetric laws) need it
    N2 = max(N2, 4 * H2)
    ref_prob = make_problem(H2, N2, False)
    st = dataclasses.replace(settings, max_newton=max(settings.max_newton, 20))
    npts = len(ys)
    idx = list(range(npts)) if points is None else sorted(points)
    X0 = np.full((npts, hb.size), np.nan)
    Xs = np.full((npts, hb.size), np.nan)
    Xr = np.full((npts, ref_prob.hb.size), np.nan)
    W = np.full((npts, 3), np.nan)  # omega of the point, the 2N and the 2H solve
    for i in idx:
        X, w = prob.x_of(ys[i])
        X0[i], W[i] = X, w
        t = tangents[i] if i < len(tangents) else None
        t_x = None if t is None else (t[:-1] * prob.xs, t[-1] * prob.ws)
        Xs[i] = X
        if samp_prob is not None:
            new = _resolve(samp_prob, X, w, t_x, st)
            if new is None:
                Xs[i] = np.nan
                continue
            Xs[i], W[i, 1] = new
        Xp = _pad(Xs[i], hb, ref_prob.hb)
        t_ref = None if t_x is None else (_pad(t_x[0], hb, ref_prob.hb), t_x[1])
        new = _resolve(ref_prob, Xp, W[i, 1], t_ref, st)
        if new is not None:
            Xr[i], W[i, 2] = new
    e_trunc, e_samp = np.full(npts, np.nan), np.full(npts, np.nan)
    ok = [i for i in idx if np.isfinite(X0[i, 0])]
    if ok:
        base = _quantities(hb, X0[ok], n_peak)
        samp = _quantities(hb, Xs[ok], n_peak)
        ref = _quantities(ref_prob.hb, Xr[ok], n_peak)
        # relative to the largest value of each quantity on the whole curve
        if scale is None:
            every = _quantities(hb, np.array([prob.x_of(y)[0] for y in ys]), n_peak)
            scale = np.nanmax(np.vstack([every, base, samp, ref]), axis=0)
            scale = np.where(scale > 0, scale, 1.0)
        span = 2 * np.pi * (prob.f_ends[1] - prob.f_ends[0])
        dw_s = np.abs(W[ok, 1] - W[ok, 0])[:, None] / span
        dw_r = np.abs(W[ok, 2] - W[ok, 1])[:, None] / span
        e_samp[ok] = RICHARDSON * np.max(np.hypot((samp - base) / scale, dw_s), axis=1)
        e_trunc[ok] = RICHARDSON * np.max(np.hypot((ref - samp) / scale, dw_r), axis=1)

    if hb.closed_form:
        e_samp[np.isfinite(X0[:, 0])] = 0.0
    return ErrorEstimate(e_trunc, e_samp, H2, N2)


def _quantities(hb, X: np.ndarray, n_peak: int) -> np.ndarray:
    """:func:`curve_quantities` of P solutions (P, m n) at once; NaN rows stay NaN."""
    good = np.all(np.isfinite(X), axis=1)
    out = np.full((X.shape[0], 2 * hb.n), np.nan)
    if np.any(good):
        Xg = X[good]
        Xr = Xg.reshape(-1, hb.m, hb.n)
        out[good, :hb.n] = np.hypot(Xr[:, 1], Xr[:, 2])
        out[good, hb.n:] = hb.peak_abs(Xg, n_peak)
    return out


def curve_scale(prob, ys: list, n_peak: int) -> np.ndarray:
    """The largest value of each :func:`curve_quantities` over the points ``ys``."""
    q = _quantities(prob.hb, np.array([prob.x_of(y)[0] for y in ys]), n_peak)
    top = np.nanmax(q, axis=0)
    return np.where(top > 0, top, 1.0)


def probe_errors(prob, ys: list, tangents: list, points, make_problem: Callable,
                 settings: ContinuationSettings, n_peak: int, H: int, N: int,
                 scale: np.ndarray) -> ErrorEstimate | None:
    """Error estimates the curve of ``prob`` would have at ``H`` harmonics and ``N``
    samples, at its points ``points`` only (relative to ``scale``,
    :func:`curve_scale` of the curve): each point is re-solved at (H, N) on the
    plane normal to the branch and estimated there like a curve point. Cheap (a few
    points instead of a curve); tells the ``tol`` adaptation which resolution a
    whole curve needs. None if no point could be re-solved."""
    hb = prob.hb
    new = make_problem(H, N, False)
    st = dataclasses.replace(settings, max_newton=max(settings.max_newton, 20))
    ys1, ts1 = [], []
    for i in points:
        X, w = prob.x_of(ys[i])
        t = tangents[i]
        tx = _pad(t[:-1] * prob.xs, hb, new.hb)
        got = _resolve(new, _pad(X, hb, new.hb), w, (tx, t[-1] * prob.ws), st)
        if got is None:
            continue
        ys1.append(new.y_of(*got))
        t1 = np.append(tx / new.xs, t[-1] * prob.ws / new.ws)
        ts1.append(t1 / np.linalg.norm(t1))
    if not ys1:
        return None
    return estimate_errors(new, ys1, ts1, make_problem, settings, n_peak, scale=scale)
