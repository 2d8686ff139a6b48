"""Exact folds and resonance peaks of a traced branch, and spurious turning points.

A continuation only brackets a fold (``d lam / ds`` changes sign between two points)
or a resonance peak (``d a_j / ds`` changes sign). Both are located here by bisection
(Brent's method) on the arc between the two points: a point of the branch at chord
parameter ``s`` is the solution of ``R(y) = 0`` on the hyperplane
``d . (y - y_a) = s`` (``d`` the unit chord, a Newton re-solve from the cubic Hermite
guess), and the sign of the wanted derivative is read from the tangent there. The
located frequency is the extremum of ``lam`` (a fold) or the frequency where ``a_j``
is extremal (a peak), to ``FREQ_TOL_HZ``.

The sampled (AFT) residual of a nonsmooth law is only piecewise smooth: where the
branch crosses a kink the continuation can zigzag, and every zigzag is a pair of
turning points that does not exist in the continuous problem.
:func:`merge_spurious_pairs` re-traces the stretch of each closely spaced pair with
more samples and keeps the pair only if it persists.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from hbm.continuation import Branch, ContinuationSettings, continue_branch, newton, \
    tangent_at

__all__ = ["FREQ_TOL_HZ", "EventKind", "CurveEvent", "locate_folds", "locate_peaks",
           "merge_spurious_pairs", "ZigzagReport"]

#: Tolerance of the located fold and peak frequencies, Hz.
FREQ_TOL_HZ = 1e-6


class EventKind(enum.Enum):
    """What a :class:`CurveEvent` marks."""

    FOLD = "fold"
    PEAK = "peak"


@dataclass(frozen=True)
class CurveEvent:
    """A located fold or peak of a frequency-response curve.

    Attributes
    ----------
    kind : EventKind
    freq_hz : float
        Frequency of the fold (the extremum of the frequency along the arc) or of the
        peak (the extremum of ``dof``'s fundamental amplitude along the arc), Hz.
    index : int
        The event lies on the arc between curve points ``index - 1`` and ``index``
        (``index`` = the peak point itself when the extremum is at an end).
    y : ndarray
        The solution there (scaled unknowns of the problem that traced the curve).
    dof : int or None
        DOF index of a peak; None for a fold.
    converged : bool
        Whether the frequency is known to ``FREQ_TOL_HZ`` (False: the bracket did not
        shrink, e.g. a Newton re-solve failed; ``freq_hz`` is then the best point).
    interior : bool
        False for a peak at an end of the computed range (not an extremum).
    """

    kind: EventKind
    freq_hz: float
    index: int
    y: np.ndarray
    dof: int | None = None
    converged: bool = True
    interior: bool = True


class _Arc:
    """Points of the branch between ``y_a`` and ``y_b`` by chord parameter."""

    def __init__(self, prob: Callable, y_a, y_b, t_a, t_b, settings):
        self.prob = prob
        self.y_a, self.y_b = np.asarray(y_a, float), np.asarray(y_b, float)
        self.h = float(np.linalg.norm(self.y_b - self.y_a))
        self.d = (self.y_b - self.y_a) / self.h
        self.t_a, self.t_b = t_a, t_b
        self.settings = dataclasses.replace(settings, max_newton=max(settings.max_newton,
                                                                     30))
        self.cache = {}

    def guess(self, s: float) -> np.ndarray:
        """Cubic Hermite interpolant at chord parameter ``s``."""
        x = s / self.h
        h00, h10 = 2 * x**3 - 3 * x**2 + 1, x**3 - 2 * x**2 + x
        h01, h11 = -2 * x**3 + 3 * x**2, x**3 - x**2
        return (h00 * self.y_a + h10 * self.h * self.t_a + h01 * self.y_b
                + h11 * self.h * self.t_b)

    def point(self, s: float):
        """``(y, tangent)`` at chord parameter ``s``; None if the re-solve failed."""
        if s in self.cache:
            return self.cache[s]
        if s == 0.0 or s == self.h:
            y = self.y_a if s == 0.0 else self.y_b
            out = (y, tangent_at(self.prob(y)[1], self.d))
        else:
            y_plane = self.y_a + s * self.d
            y, ok, _, _ = newton(self.prob, self.guess(s), self.settings, tangent=self.d,
                                 y_pred=y_plane)
            out = (y, tangent_at(self.prob(y)[1], self.d)) if ok else None
        if out is not None and out[1] is None:
            out = None
        self.cache[s] = out
        return out


def _bisect(arc: _Arc, g: Callable, to_hz: Callable, s_tol: float):
    """Root of ``g(y, t)`` on the arc (Brent, then a last check of the frequency
    spread of the bracket). Returns ``(s, converged)``."""
    failed = []

    def sign_fun(s):
        p = arc.point(s)
        if p is None:
            failed.append(s)
            raise _ReSolveFailed
        return g(*p)

    g0, g1 = sign_fun(0.0), sign_fun(arc.h)
    if g0 == 0.0:
        return 0.0, True
    if g1 == 0.0:
        return arc.h, True
    if g0 * g1 > 0:
        raise _ReSolveFailed
    s = brentq(sign_fun, 0.0, arc.h, xtol=s_tol, rtol=4 * np.finfo(float).eps,
               maxiter=200)
    return s, True


class _ReSolveFailed(Exception):
    pass


def _locate(prob, br: Branch, i: int, g: Callable, to_hz: Callable,
            settings: ContinuationSettings, s_tol: float):
    """Root of ``g`` on the arc between points ``i - 1`` and ``i``; returns
    ``(y, converged)`` (the better end point if the bisection failed)."""
    arc = _Arc(prob, br.y[i - 1], br.y[i], br.tangent[i - 1], br.tangent[i], settings)
    try:
        s, ok = _bisect(arc, g, to_hz, s_tol * arc.h)
    except (_ReSolveFailed, ValueError, RuntimeError):
        return None, False
    p = arc.point(s)
    if p is None:
        return None, False
    return p[0], ok


def locate_folds(prob, br: Branch, settings: ContinuationSettings,
                 to_hz: Callable) -> list[CurveEvent]:
    """The fold at every turning point of ``br`` (between points i-1 and i).

    ``to_hz(lam)`` converts the continuation parameter to Hz. The fold is where the
    lam component of the tangent changes sign; a corner fold (the tangent jumps at a
    kink of the sampled residual) is found as the kink. Falls back to the cubic Hermite
    estimate (``converged=False``) when a re-solve fails.
    """
    out = []
    for i in br.turning_points:
        y, ok = _locate(prob, br, i, lambda y, t: t[-1], to_hz, settings, 1e-13)
        if y is None:
            y, ok = _hermite_fold(br, i), False
        out.append(CurveEvent(EventKind.FOLD, float(to_hz(y[-1])), int(i), y,
                              converged=ok))
    return out


def _hermite_fold(br: Branch, i: int) -> np.ndarray:
    """Extremum of lam on the cubic Hermite interpolant between points i-1 and i."""
    y0, y1 = br.y[i - 1], br.y[i]
    arc_h = float(np.linalg.norm(y1 - y0))
    xs = np.linspace(0.0, 1.0, 201)
    t0, t1 = br.tangent[i - 1], br.tangent[i]
    pts = [(2 * x**3 - 3 * x**2 + 1) * y0 + (x**3 - 2 * x**2 + x) * arc_h * t0
           + (-2 * x**3 + 3 * x**2) * y1 + (x**3 - x**2) * arc_h * t1 for x in xs]
    lam = np.array([p[-1] for p in pts])
    k = int(np.argmax(lam)) if t0[-1] > 0 else int(np.argmin(lam))
    return pts[k]


def locate_peaks(prob, br: Branch, settings: ContinuationSettings, to_hz: Callable,
                 amplitude: Callable, n_dof: int) -> list[CurveEvent]:
    """The resonance peak (largest fundamental amplitude) of each DOF along ``br``.

    ``amplitude(y) -> (a (n_dof,), da_dy (n_dof, len(y)))``. The largest point is
    found first; the extremum is then located on the arc on the side where
    ``da/ds`` changes sign. A maximum at the first or last point is reported with
    ``interior=False``.
    """
    npts = len(br.y)
    if npts == 0:
        return []
    amps = np.array([amplitude(y)[0] for y in br.y])
    out = []
    for j in range(n_dof):
        k = int(np.argmax(amps[:, j]))
        slope = [float(amplitude(br.y[i])[1][j] @ br.tangent[i]) for i in
                 range(max(k - 1, 0), min(k + 2, npts))]
        base = max(k - 1, 0)
        y_best, idx, ok, interior = br.y[k], k, True, 0 < k < npts - 1
        for a, b in ((k - 1, k), (k, k + 1)):
            if a < 0 or b >= npts:
                continue
            if slope[a - base] > 0 >= slope[b - base]:
                def g(y, t, j=j):
                    return float(amplitude(y)[1][j] @ t)
                y, conv = _locate(prob, br, b, g, to_hz, settings, 1e-13)
                if y is not None and amplitude(y)[0][j] >= amps[k, j] * (1 - 1e-12):
                    y_best, idx, ok, interior = y, b, conv, True
                elif y is None:
                    ok = False
                break
        out.append(CurveEvent(EventKind.PEAK, float(to_hz(y_best[-1])), int(idx),
                              y_best, dof=j, converged=ok, interior=interior))
    return out


# -------------------------------------------------------------------------------------
# spurious turning points of the sampled residual
# -------------------------------------------------------------------------------------
@dataclass
class ZigzagReport:
    """What :func:`merge_spurious_pairs` did.

    Attributes
    ----------
    before : int
        Turning points of the traced branch.
    merged : int
        Pairs removed (each did not persist with ``refine`` times more samples).
    kept : int
        Candidate pairs that persisted (physical folds).
    removed_points : int
        Curve points of the merged zigzags dropped (their stretch went backwards).
    """

    before: int = 0
    merged: int = 0
    kept: int = 0
    removed_points: int = 0


def _pair_persists(fine: Callable, br: Branch, i1: int, i2: int,
                   settings: ContinuationSettings) -> bool:
    """Re-trace the stretch around turning points i1 < i2 with the finer problem
    ``fine`` (same scaled unknowns) and say whether it still turns twice."""
    a = max(i1 - 2, 0)
    b = min(i2 + 1, len(br.y) - 1)
    seg = br.y[a:b + 1]
    lam_top = max(y[-1] for y in seg)
    lam_bot = min(y[-1] for y in seg)
    span = max(lam_top - lam_bot, 1e-12)
    h = min(float(np.linalg.norm(q - p)) for p, q in zip(seg[:-1], seg[1:]))
    t0 = br.tangent[a]
    y0, ok, _, _ = newton(fine, br.y[a], settings, tangent=t0, y_pred=br.y[a])
    if not ok:
        return True  # cannot tell: keep the pair
    local = dataclasses.replace(settings, ds_initial=max(h, 10 * settings.ds_min),
                                ds_max=max(2 * h, 10 * settings.ds_min),
                                max_steps=400)
    sub = continue_branch(fine, y0, lam_top + 0.5 * span, local,
                          lam_start=lam_bot - 2 * span, tangent0=t0)
    if not sub.success:
        return True
    return len(sub.turning_points) >= 2


def merge_spurious_pairs(br: Branch, fine: Callable | None,
                         settings: ContinuationSettings, max_span: float
                         ) -> ZigzagReport:
    """Drop turning-point pairs of ``br`` that vanish with more samples (in place).

    A candidate is two consecutive turning points whose backward stretch spans less
    than ``max_span`` in lam. ``fine`` is the same problem with more AFT samples
    (None: keep everything). A merged pair's points that went backwards in lam are
    removed from the branch, so the frequencies stay monotonic across it.
    """
    rep = ZigzagReport(before=len(br.turning_points))
    if fine is None or len(br.turning_points) < 2:
        return rep
    tps = list(br.turning_points)
    drop_tp, drop_pts = set(), set()
    k = 0
    while k + 1 < len(tps):
        i1, i2 = tps[k], tps[k + 1]
        lam = [br.y[i][-1] for i in range(i1 - 1, i2 + 1)]
        if max(lam) - min(lam) >= max_span or _pair_persists(fine, br, i1, i2, settings):
            if max(lam) - min(lam) < max_span:
                rep.kept += 1
            k += 1
            continue
        rep.merged += 1
        drop_tp |= {i1, i2}
        ref = br.y[i1 - 1][-1]
        forward = br.tangent[i1 - 1][-1] > 0
        j = i1
        while j < len(br.y) and ((br.y[j][-1] <= ref) if forward else
                                 (br.y[j][-1] >= ref)):
            drop_pts.add(j)
            j += 1
        k += 2
    if not drop_tp:
        return rep
    keep = [i for i in range(len(br.y)) if i not in drop_pts]
    new_index = {old: new for new, old in enumerate(keep)}
    remaining = []
    for tp in br.turning_points:
        if tp in drop_tp:
            continue
        # a kept turning point's index moves with the dropped points before it
        j = tp
        while j < len(br.y) and j not in new_index:
            j += 1
        if j < len(br.y):
            remaining.append(new_index[j])
    br.y = [br.y[i] for i in keep]
    br.tangent = [br.tangent[i] for i in keep]
    br.jacobian = [br.jacobian[i] for i in keep]
    br.n_iter = [br.n_iter[i] for i in keep]
    br.turning_points = remaining
    rep.removed_points = len(drop_pts)
    return rep

