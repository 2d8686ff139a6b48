"""Exact long-time integration of a piecewise-linear oscillator at many frequencies at
once (an independent reference for the folds of harmonic balance; tests only).

``m x'' + c x' + f(x) = F sin(omega t)`` with ``f(x) = k1 x`` for ``|x| <= delta`` and
``k1 x + (k2 - k1) (x -+ delta)`` beyond the knees (the symmetric piecewise law of
``fmu_src.mount_law``, written here again from its formula). Inside one linear region
the solution is known in closed form: a constant and harmonic particular solution plus
the damped free vibration, whose transition matrix over a time ``tau`` is

    Phi(tau) = exp(-a tau) [[cos b tau + a/b sin b tau,  sin b tau / b],
                            [-w0^2 sin b tau / b,        cos b tau - a/b sin b tau]]

(``a = c / 2m``, ``w0^2 = k / m``, ``b = sqrt(w0^2 - a^2)``). The march takes fixed
steps of ``T / steps_per_period``; a step that ends in another region is cut at the
knee crossing, located by Newton on the closed-form ``x(tau)`` to rounding, and
continued from there in the new region. So the trajectory is exact to rounding (no
truncation error of a time-stepping formula), whatever the step; a step may cross both
knees in turn. A step can only miss a knee crossed and crossed back inside it, i.e.
where the motion turns within a step of the knee (an extremum within about
``(pi / steps)^2 / 2`` of the amplitude of ``delta``): the tests' decisions do not
depend on such motions (upper branch: amplitudes of several ``delta``; lower: below
``delta / 4``; they are met only in passing, during a fall).

All frequencies advance together as arrays (one Python loop over the steps).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

__all__ = ["PiecewiseOscillator", "March", "march", "Outcome", "classify",
           "FoldBracket", "fold_by_integration"]


@dataclass(frozen=True)
class PiecewiseOscillator:
    m: float
    c: float
    k1: float
    k2: float
    delta: float
    force: float

    def region(self, x):
        """-1 below ``-delta``, 0 between the knees, +1 above ``delta``."""
        return np.where(x > self.delta, 1, np.where(x < -self.delta, -1, 0))


@dataclass
class March:
    """Result of :func:`march`.

    Attributes
    ----------
    peak : ndarray, shape (n_periods, n_freq)
        ``max |x|`` at the step points of each period (m).
    state : ndarray, shape (n_freq, 2)
        ``(x, dx/dt)`` at the end, at a whole number of periods (phase 0).
    crossings : int
        Knee crossings located in the whole march.
    """

    peak: np.ndarray
    state: np.ndarray
    crossings: int


class _Regions:
    """Closed-form data of the three linear regions at every frequency."""

    def __init__(self, osc: PiecewiseOscillator, omega: np.ndarray):
        k = np.array([osc.k2, osc.k1, osc.k2])[:, None]        # regions -1, 0, +1
        off = np.array([osc.k2 - osc.k1, 0.0, -(osc.k2 - osc.k1)])[:, None] * osc.delta
        self.a = osc.c / (2 * osc.m)
        self.w02 = np.broadcast_to(k / osc.m, (3, omega.size))
        self.b = np.sqrt(self.w02 - self.a**2)
        # particular solution x_p = s0 + P sin(wt) + Q cos(wt) of m x'' + c x' + k x
        # + off = F sin(wt)
        det = (k - osc.m * omega**2) ** 2 + (osc.c * omega) ** 2
        self.P = osc.force * (k - osc.m * omega**2) / det
        self.Q = -osc.force * osc.c * omega / det
        self.s0 = np.broadcast_to(-off / k, (3, omega.size))
        self.omega = omega

    def particular(self, r, cols, t):
        """``(x_p, v_p)`` of region index ``r`` (0..2) at times t for columns cols."""
        w = self.omega[cols]
        s, c = np.sin(w * t), np.cos(w * t)
        P, Q = self.P[r, cols], self.Q[r, cols]
        return self.s0[r, cols] + P * s + Q * c, w * (P * c - Q * s)

    def free(self, r, cols, tau, x, v):
        """Free vibration of region r from ``(x, v)`` over ``tau``."""
        b, w02 = self.b[r, cols], self.w02[r, cols]
        e = np.exp(-self.a * tau)
        sn, cs = np.sin(b * tau), np.cos(b * tau)
        x1 = e * ((cs + self.a / b * sn) * x + sn / b * v)
        v1 = e * (-w02 * sn / b * x + (cs - self.a / b * sn) * v)
        return x1, v1

    def advance(self, r, cols, t, tau, x, v):
        """State at ``t + tau`` in region r, from ``(x, v)`` at t."""
        xp, vp = self.particular(r, cols, t)
        xh, vh = self.free(r, cols, tau, x - xp, v - vp)
        xq, vq = self.particular(r, cols, t + tau)
        return xh + xq, vh + vq


def _crossing(reg: _Regions, osc, r, cols, t, h, x, v, x_end):
    """Time into the step at which the motion from (x, v) in region r reaches the
    knee towards ``x_end`` (Newton on the closed form, from the linear guess)."""
    level = np.where(x_end > x, np.where(r == 0, -osc.delta, osc.delta),
                     np.where(r == 2, osc.delta, -osc.delta))
    tau = h * np.clip((level - x) / (x_end - x), 0.0, 1.0)
    xp, vp = reg.particular(r, cols, t)
    xh, vh = x - xp, v - vp
    for _ in range(40):
        xf, vf = reg.free(r, cols, tau, xh, vh)
        xq, vq = reg.particular(r, cols, t + tau)
        d = (xf + xq - level) / (vf + vq)
        tau = np.clip(tau - d, 0.0, h)
        if np.all(np.abs(d) <= 1e-15 * h):
            break
    return tau


def march(osc: PiecewiseOscillator, freq_hz, state0, n_periods: int,
          steps_per_period: int = 32) -> March:
    """Integrate from ``state0`` (shape (n_freq, 2): x, dx/dt at t = 0) for
    ``n_periods`` periods at each frequency of ``freq_hz``."""
    f = np.asarray(freq_hz, float)
    reg = _Regions(osc, 2 * np.pi * f)
    n, K = f.size, steps_per_period
    h = 1.0 / (f * K)
    allc = np.arange(n)
    # one step in region r from step point k is affine: z' = A_r z + b_{r,k}
    A = np.empty((3, 4, n))
    b = np.empty((3, K, 2, n))
    for r in range(3):
        rr = np.full(n, r)
        for j, (x0, v0) in enumerate(((1.0, 0.0), (0.0, 1.0))):
            A[r, 2 * j], A[r, 2 * j + 1] = reg.free(rr, allc, h, np.full(n, x0),
                                                    np.full(n, v0))
        for k in range(K):
            b[r, k] = reg.advance(rr, allc, k * h, h, np.zeros(n), np.zeros(n))
    # flat per-region tables: entry r * n + i is region r at frequency i
    Axx, Avx, Axv, Avv = (A[:, j].ravel() for j in range(4))
    bx = [b[:, k, 0].ravel() for k in range(K)]
    bv = [b[:, k, 1].ravel() for k in range(K)]
    x, v = state0[:, 0].astype(float).copy(), state0[:, 1].astype(float).copy()
    r = osc.region(x) + 1
    peak = np.zeros((n_periods, n))
    crossings = 0
    for p in range(n_periods):
        pk = np.abs(x)
        for k in range(K):
            i = r * n + allc
            x1 = Axx.take(i) * x + Axv.take(i) * v + bx[k].take(i)
            v1 = Avx.take(i) * x + Avv.take(i) * v + bv[k].take(i)
            cols = np.flatnonzero(osc.region(x1) + 1 != r)
            t0 = k * h
            x0, v0, left = x.copy(), v.copy(), h.copy()
            while cols.size:  # cut at the knee, go on in the next region
                crossings += cols.size
                rr, tc, hc = r[cols], t0[cols], left[cols]
                tau = _crossing(reg, osc, rr, cols, tc, hc, x0[cols], v0[cols],
                                x1[cols])
                xc, vc = reg.advance(rr, cols, tc, tau, x0[cols], v0[cols])
                rn = rr + np.where(x1[cols] > x0[cols], 1, -1)
                x1[cols], v1[cols] = reg.advance(rn, cols, tc + tau, hc - tau, xc, vc)
                r[cols] = rn
                x0[cols], v0[cols], t0[cols], left[cols] = xc, vc, tc + tau, hc - tau
                # the rest of the step may cross the other knee too
                cols = cols[osc.region(x1[cols]) + 1 != rn]
            x, v = x1, v1
            np.maximum(pk, np.abs(x), out=pk)
        peak[p] = pk
    return March(peak, np.column_stack([x, v]), crossings)


class Outcome(enum.Enum):
    """What a long-time integration started on the upper branch did."""

    STAYED = "stayed"      # converged to a periodic motion on the upper branch
    FELL = "fell"          # jumped down to the lower branch
    UNDECIDED = "undecided"


#: A motion fell when one period's ``max |x|`` is below this fraction of the upper
#: branch's (the lower branch near the upper fold is at 2 % of it).
FELL_BELOW = 0.5
#: A motion that did not fall stayed when its last period's ``max |x|`` changed by
#: less than this fraction of the upper branch's from the period before.
#: Passing the ghost of the fold at a frequency mu above it, the motion changes by at
#: least about 5e-4 * mu / Hz per period (measured 6e-4..5e-3 * mu for mu = 1e-5..1e-3
#: Hz), so a falling motion can pass for one that stayed only for mu < ~2e-7 Hz.
STAYED_CHANGE = 1e-10


def classify(m: March, peak_upper: float) -> list[Outcome]:
    """The outcome of each frequency of ``m`` (``peak_upper``: ``max |x|`` of the
    upper branch near the fold)."""
    out = []
    for j in range(m.peak.shape[1]):
        p = m.peak[:, j]
        if np.any(p < FELL_BELOW * peak_upper):
            out.append(Outcome.FELL)
        elif abs(p[-1] - p[-2]) < STAYED_CHANGE * peak_upper:
            out.append(Outcome.STAYED)
        else:
            out.append(Outcome.UNDECIDED)
    return out


@dataclass
class FoldBracket:
    """Frequencies (Hz) between which long-time integrations change from staying on
    the upper branch (``lo``) to falling (``hi``), and how they were found."""

    lo: float
    hi: float
    stages: list  # (frequencies, outcomes, periods integrated) per refinement


def _stage(osc, f, state0, max_periods: int, steps: int, peak_upper, chunk=200):
    """Integrate the frequencies ``f`` in chunks of periods until the switch from
    stayed to fell is decided (at most one undecided frequency between the last
    that stayed and the first that fell) or ``max_periods``. Returns
    ``(outcomes, periods, peak_upper)``."""
    state = np.tile(np.asarray(state0, float), (f.size, 1))
    peaks = []
    done = 0
    while True:
        m = march(osc, f, state, min(chunk, max_periods - done), steps)
        state, done = m.state, done + m.peak.shape[0]
        peaks.append(m.peak)
        if peak_upper is None:  # the first period's max |x| from the upper branch
            peak_upper = float(np.median(m.peak[0]))
        out = classify(March(np.vstack(peaks), state, 0), peak_upper)
        stayed = [i for i, o in enumerate(out) if o is Outcome.STAYED]
        fell = [i for i, o in enumerate(out) if o is Outcome.FELL]
        decided = stayed and fell and min(fell) - max(stayed) <= 2 and all(
            o is not Outcome.UNDECIDED for o in out[:max(stayed)] + out[min(fell):])
        if decided or done >= max_periods:
            return out, done, peak_upper


def fold_by_integration(osc: PiecewiseOscillator, state0, f_lo: float, f_hi: float,
                        width: float, n_freq: int = 11,
                        steps_per_period: int = 16) -> FoldBracket:
    """Bracket the upper fold (jump down) of ``osc`` by long-time integrations.

    ``n_freq`` frequencies spanning ``[f_lo, f_hi]`` are integrated at once, each from
    ``state0`` (x, dx/dt at t = 0 on the upper branch, below the fold); the bracket
    becomes the last that stayed and the first that fell, and is spanned again until
    it is at most ``width`` wide (the last stage with a spacing of ``width / 2``, so
    one undecided frequency next to the fold still leaves a bracket of ``width``).

    Why this finds the fold: near it the slow motion is one-dimensional,
    ``x' = mu + x^2`` (mu: distance above the fold). Below it (mu < 0) an upper-branch
    state converges to the stable periodic motion; above it there is none and the
    motion drifts past the fold's ghost and falls, after about ``20 / sqrt(mu / Hz)``
    periods here (measured 407, 1571, 4650 periods at 1e-3, 1e-4, 2e-5 Hz). The start
    state only changes how long that takes. A stage integrates until the switch is
    decided, at most ``80 / sqrt(spacing / Hz)`` periods. Raises AssertionError if
    the outcomes are not ordered (stayed below fell), none stayed or fell, or the
    bracket did not shrink.
    """
    peak_upper = None
    stages = []
    lo, hi = f_lo, f_hi
    while True:
        n = n_freq
        if (hi - lo) / (n - 1) < 5 * width:  # last stage: spacing width / 2
            n = max(n, int(np.ceil(2 * (hi - lo) / width)) + 1)
        f = np.linspace(lo, hi, n)
        cap = int(max(400, 80 / np.sqrt(f[1] - f[0])))
        out, periods, peak_upper = _stage(osc, f, state0, cap, steps_per_period,
                                          peak_upper)
        stages.append((f, out, periods))
        stayed = [i for i, o in enumerate(out) if o is Outcome.STAYED]
        fell = [i for i, o in enumerate(out) if o is Outcome.FELL]
        assert stayed and fell and max(stayed) < min(fell), (f, out)
        assert f[min(fell)] - f[max(stayed)] < 0.5 * (hi - lo), \
            ("the bracket did not shrink (undecided motions)", f, out)
        lo, hi = f[max(stayed)], f[min(fell)]
        if hi - lo <= width:
            return FoldBracket(float(lo), float(hi), stages)
