"""The harmonic-balance problem of one system over a band: its scaled unknowns, the
start solution at a frequency, and the per-point quantities (amplitudes, chord error)
the drivers in :mod:`hbm.analysis` need (thesis eq. 3.51-3.56)."""

from __future__ import annotations

import dataclasses
import math
import re
from typing import NamedTuple

import numpy as np

from drymount.hbm.continuation import newton
from drymount.hbm.linear import linear_frf
from drymount.hbm.options import HBMOptions
from drymount.hbm.residual import HarmonicBalance
from drymount.hbm.system import System

__all__ = ["build_problem", "resolve_options", "StartSolution"]


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
        self._last = None  # (y, exc_scale, R, J) of the last evaluation
        self.f_ends = (float(fmin_hz), float(fmax_hz))

    def x_of(self, y):
        return self.xs * y[:-1], self.ws * y[-1]

    def y_of(self, X, omega):
        return np.append(X / self.xs, omega / self.ws)

    def __call__(self, y):
        # the continuation and the fold location ask again for the point the corrector
        # has just evaluated (its tangent): 20 % of the calls on a 6-DOF curve. The
        # last evaluation is kept and handed out again (copies: callers keep J)
        last = self._last
        if last is not None and last[1] == self.hb.exc_scale and \
                np.array_equal(last[0], y):
            return last[2].copy(), last[3].copy()
        R, Jy = self._evaluate(y)
        self._last = (np.array(y, dtype=float), self.hb.exc_scale, R, Jy)
        return R.copy(), Jy.copy()

    def residual_only(self, y):
        """The scaled residual of ``self(y)`` without its Jacobian (the same numbers:
        :meth:`HarmonicBalance.residual`'s ``R`` does not depend on ``jacobian``)."""
        last = self._last
        if last is not None and last[1] == self.hb.exc_scale and \
                np.array_equal(last[0], y):
            return last[2].copy()
        self.n_eval += 1
        X, w = self.x_of(y)
        return self.hb.residual(X, w, jacobian=False).R / self.rs

    def _evaluate(self, y):
        self.n_eval += 1
        X, w = self.x_of(y)
        R, J, Jw = self.hb.residual(X, w)
        Jy = np.empty((R.size, R.size + 1))
        np.multiply(J, self.xs, out=Jy[:, :-1])
        np.multiply(Jw, self.ws, out=Jy[:, -1])
        Jy /= self.rs  # in place: the same numbers as Jy / rs, one copy fewer
        return R / self.rs, Jy

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
    # started from the previous solution scaled up (halving the increment on failure);
    # the static load and the static rows stay (vibration about the working point)
    hb = prob.hb
    dyn = slice(hb.n, -1)   # the harmonic rows of y (the static rows come first)
    try:
        mu, dmu = 0.0, 0.125
        y = prob.linear_guess(freq_hz, False)
        y[dyn] = 0.0
        while mu < 1.0:
            target = min(1.0, mu + dmu)
            hb.exc_scale = target
            guess = y.copy()
            if mu > 0:
                guess[dyn] *= target / mu
            else:
                guess = prob.linear_guess(freq_hz, False)
                guess[dyn] *= target
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
    n = prob.hb.n
    xc, xs = prob.xs[n:2 * n], prob.xs[2 * n:3 * n]

    def amplitude(y):  # _amplitude_fn's amplitudes, without their derivative
        return np.hypot(xc * y[n:2 * n], xs * y[2 * n:3 * n])
    top = np.zeros(n) if floor is None else np.array(floor, float)

    def chord_error(y0, t0, y1, t1):
        h = float(np.linalg.norm(y1 - y0))
        ym = 0.5 * (y0 + y1) + h * (t0 - t1) / 8.0
        a0, a1, am = amplitude(y0), amplitude(y1), amplitude(ym)
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


