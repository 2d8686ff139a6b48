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

from drymount.hbm.continuation import (Branch, ContinuationSettings, continue_branch,
                                       newton, tangent_at)
from drymount.hbm.roots import brentq

__all__ = ["FREQ_TOL_HZ", "EventKind", "CurveEvent", "locate_folds", "locate_peaks",
           "locate_maximum", "merge_spurious_pairs", "ZigzagReport"]

#: Tolerance of the located fold and peak frequencies, Hz.
FREQ_TOL_HZ = 1e-6
#: Bisection tolerance on the arc, relative to the arc's chord: an arc spans less
#: than 1 Hz, so the located frequency is within 1e-8 Hz of the root, 100x inside
#: FREQ_TOL_HZ (1e-13 took 1.6 times as long on six_dof_halved as 1e-9; 1e-9 took
#: 2-5 % more of the 17 presets' default curves than 1e-8, whose events it located
#: the same to 1.4e-10 relative).
ARC_TOL = 1e-8
#: Where the sign change is a jump of the sampled (AFT) residual (a stick-slip
#: transition crossing a sample point), not a root, the bisection stops once the
#: bracket is this small relative to the chord (within 1e-7 Hz, 10x inside
#: FREQ_TOL_HZ; to 1e-9 a jump took about 35 re-solves instead of 25) ...
JUMP_TOL = 1e-7
#: ... and the slope of ``g`` across the bracket exceeds the arc's mean slope this
#: many times (at a root of a smooth ``g`` it is of the mean's order; across a jump
#: it grows as 1 / bracket, to about 1e7 times the mean at ``JUMP_TOL``).
JUMP_SLOPE = 1e4


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
        self.settings = dataclasses.replace(
            settings, max_newton=max(settings.max_newton, 30))
        self.cache = {}

    def guess(self, s: float) -> np.ndarray:
        """Cubic Hermite interpolant at chord parameter ``s`` between the nearest
        points solved on either side (the arc's ends until the bisection has solved
        points inside: its error shrinks as the fourth power of their distance, so
        the re-solves of a narrowing bracket start next to their solution)."""
        lo, hi = (0.0, self.y_a, self.t_a), (self.h, self.y_b, self.t_b)
        for sk, p in self.cache.items():
            if p is not None and lo[0] < sk < s:
                lo = (sk, *p)
            elif p is not None and s < sk < hi[0]:
                hi = (sk, *p)
        x = (s - lo[0]) / (hi[0] - lo[0])
        span = float(np.linalg.norm(hi[1] - lo[1]))
        h00, h10 = 2 * x**3 - 3 * x**2 + 1, x**3 - 2 * x**2 + x
        h01, h11 = -2 * x**3 + 3 * x**2, x**3 - x**2
        return (h00 * lo[1] + h10 * span * lo[2] + h01 * hi[1]
                + h11 * span * hi[2])

    def point(self, s: float):
        """``(y, tangent)`` at chord parameter ``s``; None if the re-solve failed."""
        if s in self.cache:
            return self.cache[s]
        if s == 0.0 or s == self.h:
            y = self.y_a if s == 0.0 else self.y_b
            out = (y, tangent_at(self.prob(y)[1], self.d))
        else:
            y_plane = self.y_a + s * self.d
            y, ok, _, _ = newton(self.prob, self.guess(s), self.settings,
                                 tangent=self.d, y_pred=y_plane)
            out = (y, tangent_at(self.prob(y)[1], self.d)) if ok else None
        if out is not None and out[1] is None:
            out = None
        self.cache[s] = out
        return out


def _bisect(arc: _Arc, g: Callable, to_hz: Callable, s_tol: float):
    """Root of ``g(y, t)`` on the arc (Brent, then a last check of the frequency
    spread of the bracket). Returns ``(s, converged)``."""
    values = {}   # g at the ends is asked for here and again by brentq: once each
    bracket = [0.0, arc.h]   # the sign change, narrowed with every Brent point

    def sign_fun(s):
        if s not in values:
            p = arc.point(s)
            if p is None:
                raise _ReSolveFailed
            values[s] = g(*p)
            if len(values) > 2:
                _narrow(bracket, values, s, arc.h)
        return values[s]

    g0, g1 = sign_fun(0.0), sign_fun(arc.h)
    if g0 == 0.0:
        return 0.0, True
    if g1 == 0.0:
        return arc.h, True
    if g0 * g1 > 0:
        raise _ReSolveFailed
    try:
        s = brentq(sign_fun, 0.0, arc.h, xtol=s_tol, rtol=4 * np.finfo(float).eps,
                   maxiter=200)
    except _AtJump as jump:
        s = jump.s
    return s, True


def _narrow(bracket: list, values: dict, s: float, h: float) -> None:
    """Put the new point ``s`` (inside the bracket, as Brent's points are) on the
    side of its sign; raise :class:`_AtJump` with the end of smaller ``|g|`` (the
    point Brent would return) once the bracket holds a jump of ``g`` to
    ``JUMP_TOL``."""
    bracket[0 if np.sign(values[s]) == np.sign(values[0.0]) else 1] = s
    lo, hi = bracket
    g_lo, g_hi = values[lo], values[hi]
    mean = abs(values[h] - values[0.0]) / h
    if hi - lo <= JUMP_TOL * h and abs(g_hi - g_lo) > JUMP_SLOPE * mean * (hi - lo):
        raise _AtJump(lo if abs(g_lo) <= abs(g_hi) else hi)


class _AtJump(Exception):
    """The bracket holds a jump of ``g`` (``s``: the point to return)."""

    def __init__(self, s: float):
        super().__init__(s)
        self.s = s


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
        y, ok = _locate(prob, br, i, lambda y, t: t[-1], to_hz, settings, ARC_TOL)
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
    if not br.y:
        return []
    amps = np.array([amplitude(y)[0] for y in br.y])
    out = []
    for j in range(n_dof):
        def slope(y, t, j=j):
            return float(amplitude(y)[1][j] @ t)
        out.append(locate_maximum(prob, br, settings, to_hz, amps[:, j], slope,
                                  lambda y, j=j: amplitude(y)[0][j], dof=j))
    return out


def locate_maximum(prob, br: Branch, settings: ContinuationSettings,
                   to_hz: Callable, values, slope: Callable, value: Callable,
                   dof: int | None = None) -> CurveEvent:
    """The maximum along ``br`` of a quantity with ``values`` at the curve points,
    ``value(y)`` anywhere and derivative ``slope(y, t)`` along the unit tangent:
    located like a DOF's peak (:func:`locate_peaks`) on the arc next to the largest
    point where the slope changes sign."""
    npts = len(br.y)
    k = int(np.nanargmax(values))
    slopes = {i: slope(br.y[i], br.tangent[i])
              for i in range(max(k - 1, 0), min(k + 2, npts))}
    y_best, idx, ok, interior = br.y[k], k, True, 0 < k < npts - 1
    for a, b in ((k - 1, k), (k, k + 1)):
        if a < 0 or b >= npts:
            continue
        if slopes[a] > 0 >= slopes[b]:
            y, conv = _locate(prob, br, b, slope, to_hz, settings, ARC_TOL)
            if y is not None and value(y) >= values[k] * (1 - 1e-12):
                y_best, idx, ok, interior = y, b, conv, True
            elif y is None:
                ok = False
            break
    return CurveEvent(EventKind.PEAK, float(to_hz(y_best[-1])), int(idx), y_best,
                      dof=dof, converged=ok, interior=interior)


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
        Turning points removed (they vanished when the stretch was re-traced with
        more samples).
    kept : int
        Turning points of re-checked clusters that persisted.
    removed_points : int
        Curve points dropped (coarse points replaced minus re-traced points).
    folds : dict
        ``{turning-point index: CurveEvent}`` for folds located on a finer re-trace.
    refined : list of (f_start, f_end, points)
        Stretches of the curve replaced by a finer re-trace (in Hz with ``to_hz``).
    fine_points : dict
        ``{point index: index into fines}``: the points of the spliced curve that
        solve a finer problem (every other point solves the coarse one).
    """

    before: int = 0
    merged: int = 0
    kept: int = 0
    removed_points: int = 0
    folds: dict = dataclasses.field(default_factory=dict)
    refined: list = dataclasses.field(default_factory=list)
    fine_points: dict = dataclasses.field(default_factory=dict)


def _clusters(br: Branch, max_span: float) -> list[list[int]]:
    """Runs of consecutive turning points whose stretches each span < max_span."""
    tps = list(br.turning_points)
    out, cur = [], tps[:1]
    for a, b in zip(tps[:-1], tps[1:], strict=True):
        lam = [br.y[i][-1] for i in range(a - 1, b + 1)]
        if max(lam) - min(lam) < max_span:
            cur.append(b)
        else:
            out.append(cur)
            cur = [b]
    if cur:
        out.append(cur)
    return out


def _retrace(fine: Callable, br: Branch, a: int, b: int,
             settings: ContinuationSettings) -> Branch | None:
    """The branch of ``fine`` from point ``a`` of ``br`` until it passes point ``b``
    (the plane through it normal to the chord a-b); None if that failed."""
    d = br.y[b] - br.y[a]
    span = float(np.linalg.norm(d))
    d /= span
    y0, ok, _, _ = newton(fine, br.y[a], settings, tangent=br.tangent[a],
                          y_pred=br.y[a])
    if not ok:
        return None
    seg = br.y[a:b + 1]
    # the ordinary step sizes: tiny steps resolve (and turn at) every micro-kink
    local = dataclasses.replace(settings, ds_initial=max(min(settings.ds_initial,
                                                             span / 4),
                                                         10 * settings.ds_min),
                                max_steps=20 * (b - a) + 200)
    lam = [y[-1] for y in seg]
    width = max(lam) - min(lam)
    sub = continue_branch(
        fine, y0, max(lam) + 2 * width + 1.0, local, lam_start=min(lam) - 2 * width,
        tangent0=br.tangent[a], until=lambda y: float(d @ (y - br.y[b])) > 0.0)
    return sub if sub.success else None


def merge_spurious_pairs(br: Branch, fines: list, settings: ContinuationSettings,
                         max_span: float, to_hz: Callable | None = None
                         ) -> ZigzagReport:
    """Merge the zigzags of ``br`` that vanish with more samples (in place).

    Turning points closer than ``max_span`` in lam form clusters. Each cluster's
    stretch is re-traced with the finer problems ``fines`` in turn (the same problem
    with more AFT samples and the same scaled unknowns) until the re-trace has at most
    one turning point or the problems run out; if the re-trace has fewer turning
    points than the cluster, the stretch of the curve is replaced by it (its points
    are then at the finer sampling, its folds located on it). Otherwise the cluster
    is kept.
    """
    rep = ZigzagReport(before=len(br.turning_points))
    if not fines or len(br.turning_points) < 2:
        return rep
    npts = len(br.y)
    parts = []  # (a, b, sub, fine): replace points a+1..b by sub.y[1:]
    for cl in _clusters(br, max_span):
        if len(cl) < 2:
            continue
        a, b = max(cl[0] - 2, 0), min(cl[-1] + 1, npts - 1)
        best = None
        for j, fine in enumerate(fines):
            sub = _retrace(fine, br, a, b, settings)
            if sub is None:
                continue
            k = len(sub.turning_points)
            # fewer turns that connect like the stretch they replace (same parity)
            if k < len(cl) and (len(cl) - k) % 2 == 0 and \
                    (best is None or k < len(best[2].turning_points)):
                best = (a, b, sub, fine, j)
            if k <= 1:
                break
        if best is None:
            rep.kept += len(cl)  # persisted (or the re-trace failed)
            continue
        parts.append(best)
        rep.merged += len(cl) - len(best[2].turning_points)
    if parts:
        _splice(br, parts, settings, to_hz, rep)
    return rep


def _splice(br: Branch, parts: list, settings: ContinuationSettings,
            to_hz: Callable | None, rep: ZigzagReport) -> None:
    """Replace the stretches ``(a, b, sub, fine, j)`` of ``br`` (points a+1..b) by
    the re-traces ``sub`` of ``fines[j]`` (their folds located on them); in place,
    noted in ``rep``."""
    npts = len(br.y)
    y, tg, jac, dets, nit, tps, folds = [], [], [], [], [], [], {}
    start = 0
    old_tp = set(br.turning_points)

    def det_sign(b: Branch, i: int) -> float:
        return b.det_sign[i] if len(b.det_sign) == len(b.y) else np.nan

    def copy(lo, hi):  # coarse points lo..hi-1
        for i in range(lo, hi):
            if i in old_tp:
                tps.append(len(y))
            y.append(br.y[i])
            tg.append(br.tangent[i])
            jac.append(br.jacobian[i])
            dets.append(det_sign(br, i))
            nit.append(br.n_iter[i])

    for a, b, sub, fine, j in parts:
        copy(start, a + 1)  # sub point 0 is coarse point a
        located = {}
        if to_hz is not None and sub.turning_points:
            located = {e.index: e for e in locate_folds(fine, sub, settings, to_hz)}
        for k in range(1, len(sub.y)):
            if k in sub.turning_points:
                tps.append(len(y))
                if k in located:
                    folds[len(y)] = dataclasses.replace(located[k], index=len(y))
            rep.fine_points[len(y)] = j
            y.append(sub.y[k])
            tg.append(sub.tangent[k])
            jac.append(sub.jacobian[k])
            dets.append(det_sign(sub, k))
            nit.append(sub.n_iter[k])
        rep.removed_points += (b - a) - (len(sub.y) - 1)
        rep.refined.append((to_hz(br.y[a][-1]) if to_hz else br.y[a][-1],
                            to_hz(br.y[b][-1]) if to_hz else br.y[b][-1],
                            len(sub.y) - 1))
        start = b + 1
    copy(start, npts)
    br.y, br.tangent, br.jacobian, br.det_sign, br.n_iter = y, tg, jac, dets, nit
    br.turning_points = tps
    rep.folds = folds
