"""Newton solver and pseudo-arclength continuation (thesis Sec. 3.2, eq. 3.53-3.66).

The continuation sees only ``fun(y) -> (R, J)`` with ``y = [x, lam]`` (n + 1 scaled
unknowns, the last one the continuation parameter) and ``J = dR/dy`` of shape
(n, n + 1), as in NLvib's ``solve_and_continue``:

- tangent predictor: ``t`` spans the null space of ``J`` (eq. 3.55-3.56 generalised to
  arc length), oriented along the previous tangent;
- pseudo-arclength corrector: Newton on ``[R(y); t . (y - y_pred)] = 0`` (the linearised
  form of the thesis's sphere, eq. 3.58-3.65, which is robust through folds);
- step adaptation on the Newton iteration count, ``s_k = s_{k-1} sqrt(n_norm / n_iter)``
  (eq. 3.66), with the step halved when the corrector fails, and shrunk where the
  angle between successive tangents exceeds ``max_angle`` (curvature: peaks, folds);
- turning points: sign changes of ``d lam / ds``;
- nonsmooth corners (the AFT residual is piecewise smooth: a sample crossing a knee
  or switching between stick and slip): when the corrector fails at a small step,
  the tangent of the piece beyond the kink is tried in both directions, which
  continues a branch that turns sharply at the kink (a corner fold);
- Newton with backtracking on the residual norm (kinks can make full steps cycle).

A stalled continuation returns the branch traced so far with ``success = False`` and
the reason; it never raises once the work has started.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import NamedTuple

import numpy as np
from scipy.linalg import lapack

__all__ = ["ContinuationSettings", "Branch", "Status", "NewtonResult", "newton",
           "continue_branch"]


class Status(Enum):
    """How a continuation or a set of Newton solves ended (``Branch.status``,
    ``FrequencyResponse.status``)."""

    DONE = "done"                           # reached the end / solved everywhere
    STEP_TOO_SMALL = "step_too_small"       # step size fell below ds_min
    TOO_MANY_STEPS = "too_many_steps"       # max_steps reached
    TURNED_BACK = "turned_back"             # left the range below its start
    EVALUATION_FAILED = "evaluation_failed"  # non-finite residual, no tangent
    NO_START = "no_start"                   # no solution at the first frequency
    RETRACED = "retraced"                   # the branch turned back onto itself
    NO_CONVERGENCE = "no_convergence"       # Newton failed at a given frequency
    INTERRUPTED = "interrupted"             # KeyboardInterrupt (the branch so far is
    #                                         carried by the exception, see
    #                                         continue_branch)


@dataclass(frozen=True)
class ContinuationSettings:
    """Settings in scaled units. The user-facing defaults are those of
    :class:`hbm.options.HBMOptions` (the one source; it builds these); the last three
    are internal to the corrector."""

    ds_initial: float
    ds_min: float
    ds_max: float
    n_norm: int
    max_newton: int
    tol_residual: float
    tol_step: float
    max_steps: int
    max_growth: float
    max_angle: float
    min_damping: float = 1.0 / 64
    corner_ds: float = 1e-3
    max_correction: float = 1.0


class NewtonResult(NamedTuple):
    """Result of :func:`newton`: the last iterate, whether it converged, the
    iterations used and why it did not converge (empty when it did)."""

    y: np.ndarray
    converged: bool
    n_iter: int
    message: str


@dataclass
class Branch:
    """Points of a traced branch (scaled unknowns).

    Attributes
    ----------
    y : list of ndarray, each (n + 1,)
    tangent : list of ndarray, each (n + 1,)
    jacobian : list of ndarray, each (n, n + 1)
        ``dR/dy`` at each point (reused for stability).
    det_sign : list of float
        Sign of ``det dR/dx`` (the first n columns of ``jacobian``) at each point,
        from the factorization of the tangent's solve (:func:`_tangent`; 0 singular,
        NaN unknown); the stability schedule's real-exponent crossings.
    n_iter : list of int
        Newton iterations of each point.
    turning_points : list of int
        Indices ``i`` such that ``d lam / ds`` changes sign between points i-1 and i.
    success, status, message, n_newton, n_steps
        ``status``: a :class:`Status` (``RETRACED``: retraced points are dropped).
    """

    y: list = field(default_factory=list)
    tangent: list = field(default_factory=list)
    jacobian: list = field(default_factory=list)
    det_sign: list = field(default_factory=list)
    n_iter: list = field(default_factory=list)
    turning_points: list = field(default_factory=list)
    success: bool = False
    status: Status = Status.DONE
    message: str = ""
    n_newton: int = 0
    n_steps: int = 0


def _norm(a):
    return float(np.sqrt(np.dot(a, a)))


def newton(fun: Callable, y0: np.ndarray, settings: ContinuationSettings,
           fixed: int | None = None, tangent: np.ndarray | None = None,
           y_pred: np.ndarray | None = None, jacobian_at_root: bool = True):
    """Newton iterations for ``R(y) = 0`` closed by one extra equation.

    With ``fixed`` = index, that unknown is held (natural parametrisation, eq. 3.53);
    with ``tangent`` and ``y_pred`` the pseudo-arclength equation
    ``tangent . (y - y_pred) = 0`` (the linearised form of the thesis's sphere,
    eq. 3.58-3.65) closes the system.

    ``jacobian_at_root`` False (a caller that keeps only the root) with a ``fun``
    that has ``residual_only(y)``: a trial point reached by a step within
    ``tol_step`` is evaluated without its Jacobian first; if it converges, none is
    made (the re-solves of the error estimate: about half an evaluation saved each),
    else it is evaluated in full. The same iterates and root, bit for bit.

    Returns a :class:`NewtonResult` ``(y, converged, n_iter, message)``.
    """
    y = np.array(y0, dtype=float)
    last = np.inf
    closure = _Closure.of(y.size - 1, fixed, tangent, y_pred)
    r_only = None if jacobian_at_root else getattr(fun, "residual_only", None)
    R, J, msg = _evaluate(fun, y)
    if R is None:
        return NewtonResult(y, False, 0, msg)
    r = _norm(R)
    for it in range(settings.max_newton + 1):
        if r <= settings.tol_residual and last <= settings.tol_step:
            return NewtonResult(y, True, it, "")
        if it == settings.max_newton:
            break
        try:
            step = closure.step(y, R, J)
        except np.linalg.LinAlgError:
            return NewtonResult(y, False, it, "singular Jacobian")
        trial = _damped(fun, r_only, y, R, step, closure, settings)
        if trial.R is None:
            return NewtonResult(y, False, it + 1, trial.message)
        if trial.J is None:   # converged without its Jacobian
            return NewtonResult(trial.y, True, it + 1, "")
        y, R, J = trial.y, trial.R, trial.J
        r = _norm(R)
        last = trial.size
    return NewtonResult(y, False, settings.max_newton, (
        f"no convergence in {settings.max_newton} iterations (residual {r:.3g})"))


def _evaluate(fun: Callable, y: np.ndarray):
    """``(R, J, message)`` of ``fun(y)``; R and J None (and why) where the evaluation
    failed or its residual is not finite."""
    try:
        R, J = fun(y)
    except (FloatingPointError, ValueError, np.linalg.LinAlgError) as exc:
        return None, None, f"evaluation failed: {exc}"
    if not np.all(np.isfinite(R)):
        return None, None, "non-finite residual"
    return R, J, ""


def _evaluate_residual(r_only: Callable, y: np.ndarray):
    """``(R, message)`` of ``r_only(y)`` (the residual alone), as :func:`_evaluate`."""
    try:
        R = r_only(y)
    except (FloatingPointError, ValueError, np.linalg.LinAlgError) as exc:
        return None, f"evaluation failed: {exc}"
    if not np.all(np.isfinite(R)):
        return None, "non-finite residual"
    return R, ""


class _Closure(NamedTuple):
    """The equation that closes Newton's system (:func:`newton`): unknown ``fixed``
    held (``keep``: the others), or ``tangent . (y - y_pred) = 0``."""

    fixed: int | None
    keep: np.ndarray | None
    tangent: np.ndarray | None
    y_pred: np.ndarray | None

    @classmethod
    def of(cls, n: int, fixed, tangent, y_pred) -> _Closure:
        keep = None
        if fixed is not None:
            keep = np.ones(n + 1, bool)
            keep[fixed] = False
        return cls(fixed, keep, tangent, y_pred)

    def value(self, y: np.ndarray) -> float:
        """The arc-length equation's value at ``y``."""
        return float(np.dot(self.tangent, y - self.y_pred))

    def merit(self, y: np.ndarray, R: np.ndarray) -> float:
        """``|R|^2`` plus the arc-length equation squared."""
        g = 0.0 if self.fixed is not None else self.value(y)
        return float(np.dot(R, R)) + g * g

    def step(self, y: np.ndarray, R: np.ndarray, J: np.ndarray) -> np.ndarray:
        """The full Newton step at ``y`` (raises ``LinAlgError`` if singular)."""
        if self.fixed is not None:
            step = np.zeros(y.size)
            step[self.keep] = np.linalg.solve(J[:, self.keep], -R)
            return step
        A = np.vstack([J, self.tangent])
        b = np.append(-R, -self.value(y))
        return np.linalg.solve(A, b)


class _Trial(NamedTuple):
    """The point a damped step reached: R None if it failed (``message``: why), J
    None if it converged without its Jacobian; ``size``: the step's length."""

    y: np.ndarray
    R: np.ndarray | None
    J: np.ndarray | None
    size: float
    message: str = ""


def _damped(fun: Callable, r_only: Callable | None, y: np.ndarray, R: np.ndarray,
            step: np.ndarray, closure: _Closure, settings: ContinuationSettings
            ) -> _Trial:
    """Backtracking on |R|^2 (+ the arc-length equation squared) along ``step``: the
    residual of the AFT is only piecewise smooth (knees, stick-slip switches at
    samples), and full Newton steps can cycle between two pieces around a kink. A
    trial within ``tol_step`` is evaluated without its Jacobian first when
    ``r_only`` is given (:func:`newton`'s ``jacobian_at_root``)."""
    phi0 = closure.merit(y, R)
    alpha = 1.0
    size = _norm(step)
    while True:
        y_try = y + alpha * step
        if r_only is not None and alpha * size <= settings.tol_step:
            (R_try, msg), J_try = _evaluate_residual(r_only, y_try), None
        else:
            R_try, J_try, msg = _evaluate(fun, y_try)
        descent = R_try is not None and (
            closure.merit(y_try, R_try) <= (1 - 1e-4 * alpha) * phi0)
        if R_try is not None and (descent or alpha <= settings.min_damping):
            if J_try is not None:
                return _Trial(y_try, R_try, J_try, alpha * size)
            if _norm(R_try) <= settings.tol_residual:  # converged: no Jacobian
                return _Trial(y_try, R_try, None, alpha * size)
            R_try, J_try, msg = _evaluate(fun, y_try)  # it goes on: its Jacobian
            if R_try is not None:
                return _Trial(y_try, R_try, J_try, alpha * size)
        if R_try is None and alpha <= settings.min_damping:
            return _Trial(y, None, None, alpha * size, msg)
        alpha *= 0.5


class _Polyline(NamedTuple):
    """The vertices ``a`` of a polyline, its segments ``d`` and their squared
    lengths ``dd``, and for the screen of :func:`_distance_to_polyline` each
    segment's start ``a0 = a[:-1]`` with ``a0 . d`` (``ad``) and ``|a0|^2`` (``aa``),
    and the largest ``|a|^2`` (``scale``) (:func:`_polyline`)."""

    a: np.ndarray
    d: np.ndarray
    dd: np.ndarray
    ad: np.ndarray
    aa: np.ndarray
    scale: float


def _polyline(pts: list) -> _Polyline:
    a = np.asarray(pts)
    a0 = a[:-1]
    d = a[1:] - a0
    aa = np.einsum("ij,ij->i", a, a)
    return _Polyline(a, d, np.einsum("ij,ij->i", d, d), np.einsum("ij,ij->i", a0, d),
                     aa[:-1], float(aa.max()))


def _distance_to_polyline(p: np.ndarray, pts: list, with_segment: bool = False,
                          geometry: _Polyline | None = None):
    """Distance of ``p`` to the polyline through ``pts`` (one point: to that point);
    with ``with_segment`` also the length of the nearest segment (0 when the last
    point is nearest). The first nearest segment wins. ``geometry``: ``pts``'s
    :func:`_polyline`, if the caller keeps it.

    A screen measures all segments at once by two matrix-vector products, the
    squared distance expanded as ``|p - a0|^2 - 2 s (p - a0) . d + s^2 dd``; the
    few within its round-off of the nearest are measured again one by one
    (:func:`_segment_distance`), so that the answer, ties included (a vertex nearest,
    shared by two segments), is that of a loop over the segments, bit for bit. The
    screen's error: the expansion's, below ``1e-13 (|p|^2 + max |a|^2)`` for the
    vectors here, and that of its ``s``, which enters squared (the distance is
    stationary in ``s`` at the nearest point, and at a clipped end its slope is
    itself round-off); the margin is ``1e-10 (|p|^2 + max |a|^2)`` above
    ``1e-9`` of the nearest.
    """
    best = _norm(p - pts[-1])
    seg = 0.0
    if len(pts) < 2:
        return (best, seg) if with_segment else best
    g = _polyline(pts) if geometry is None else geometry
    pp = float(np.dot(p, p))
    pd = g.d @ p - g.ad        # (p - a0) . d
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(g.dd == 0.0, 0.0, np.clip(pd / g.dd, 0, 1))
    dist = pp - 2.0 * (g.a[:-1] @ p) + g.aa - s * (2.0 * pd - s * g.dd)
    near = dist.min()
    margin = 1e-9 * abs(near) + 1e-10 * (pp + g.scale)
    for i in np.flatnonzero(dist <= near + margin):
        dist_i, dd_i = _segment_distance(p, pts[i], pts[i + 1])
        if dist_i < best:
            best, seg = dist_i, math.sqrt(dd_i)
    return (best, seg) if with_segment else best


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray):
    """Distance of ``p`` to the segment from ``a`` to ``b``, and its squared length."""
    d = b - a
    dd = float(np.dot(d, d))
    s = 0.0 if dd == 0.0 else min(1.0, max(0.0, float(np.dot(p - a, d)) / dd))
    return _norm(p - a - s * d), dd


def _corner_step(fun: Callable, y: np.ndarray, t: np.ndarray, ds: float,
                 settings: ContinuationSettings, history: list):
    """Continue past a kink of a piecewise-smooth residual.

    The predictor ``y + ds t`` lies beyond the kink; the null vector ``tB`` of the
    Jacobian there is the branch direction on that piece. The branch continues along
    ``+tB`` (a corner) or ``-tB`` (a corner fold, where it turns back in the
    parameter); each is corrected on its pseudo-arclength plane, and a point back on
    the old branch (within ``0.1 ds`` of the polyline through the last points
    ``history``, or behind ``y`` on the line of ``t``) is rejected.

    Returns ``(y_new, n_iter, direction)``; ``direction`` is None on failure.
    """
    its_total = 0
    try:
        _, J = fun(y + ds * t)
        tB = tangent_at(J, t)
    except (FloatingPointError, ValueError, np.linalg.LinAlgError):
        return y, 0, None
    if tB is None:
        return y, 0, None
    for sgn in (1.0, -1.0):
        d = sgn * tB
        y_p = y + ds * d
        y_c, ok, its, _ = newton(fun, y_p, settings, tangent=d, y_pred=y_p)
        its_total += its
        if not ok or _norm(y_c - y_p) > settings.max_correction * ds:
            continue
        step = y_c - y
        along = float(np.dot(step, t))
        perp = _norm(step - along * t)
        if (along < 0.0 and perp < 0.05 * abs(along)) or \
                _distance_to_polyline(y_c, history) < 0.1 * ds:
            continue  # back on the old branch
        return y_c, its_total, d
    return y, its_total, None


class _Tangent(NamedTuple):
    """A unit tangent and the sign of ``det dR/dx`` at its point."""

    t: np.ndarray
    det_sign: float


def _tangent(J: np.ndarray, previous: np.ndarray) -> _Tangent | None:
    """Unit null vector of ``J`` (n, n+1) oriented like ``previous``, from
    ``A t = e`` with ``A = [J; previous]``; and, from the same LU factors, the sign
    of ``det J_x`` (J without its last column): by Cramer's rule the last component
    of ``t`` is ``det J_x / det A``, so ``sign det J_x = sign(t_lam) sign(det A)``
    (no second factorization; 0 where ``t_lam`` is exactly 0)."""
    A = np.vstack([J, previous])
    b = np.zeros(A.shape[0])
    b[-1] = 1.0
    if not np.all(np.isfinite(A)):
        return None
    lu, piv, t, info = lapack.dgesv(A, b)
    if info != 0:
        return None
    nt = _norm(t)
    if not np.isfinite(nt) or nt == 0.0:
        return None
    swaps = np.count_nonzero(piv != np.arange(len(piv)))  # 0-based pivots
    det_a = (-1) ** swaps * np.prod(np.sign(np.diag(lu)))
    return _Tangent(t / nt, float(np.sign(t[-1]) * det_a))


def tangent_at(J: np.ndarray, previous: np.ndarray) -> np.ndarray | None:
    """Unit null vector of ``J`` (n, n+1) oriented like ``previous``."""
    tg = _tangent(J, previous)
    return None if tg is None else tg.t


def continue_branch(fun: Callable, y0: np.ndarray, lam_end: float,
                    settings: ContinuationSettings, lam_start: float | None = None,
                    callback: Callable | None = None,
                    tangent0: np.ndarray | None = None,
                    chord_error: Callable | None = None,
                    until: Callable | None = None) -> Branch:
    """:func:`_continue` on a new :class:`Branch`. An interrupt (KeyboardInterrupt)
    propagates with the points accepted so far as its ``branch`` attribute (status
    ``Status.INTERRUPTED``)."""
    br = Branch()
    try:
        return _continue(br, fun, y0, lam_end, settings, lam_start, callback,
                         tangent0, chord_error, until)
    except KeyboardInterrupt as exc:
        br.status, br.message = Status.INTERRUPTED, "interrupted"
        exc.branch = br
        raise


def _continue(br: Branch, fun: Callable, y0: np.ndarray, lam_end: float,
              settings: ContinuationSettings, lam_start: float | None = None,
              callback: Callable | None = None,
              tangent0: np.ndarray | None = None,
              chord_error: Callable | None = None,
              until: Callable | None = None) -> Branch:
    """Trace the solution branch of ``fun`` from a solution ``y0`` until ``lam_end``.

    Parameters
    ----------
    fun : callable
        ``fun(y) -> (R (n,), J (n, n+1))``, ``y = [x, lam]`` in scaled units.
    y0 : ndarray, shape (n + 1,)
        A converged solution (``R(y0) ~ 0``); the branch starts towards larger lam.
    lam_end : float
        The last point is corrected onto ``lam = lam_end``.
    settings : ContinuationSettings
    lam_start : float, optional
        Stop (``Status.TURNED_BACK``) if the branch returns below it.
    callback : callable, optional
        ``callback(lam)`` after every accepted point (progress bar).
    tangent0 : ndarray, optional
        Direction to start in (default: towards larger lam).
    chord_error : callable, optional
        ``chord_error(y0, t0, y1, t1) -> ratio``: the error of the straight chord
        between two consecutive points relative to the wanted tolerance. A step with
        a ratio above 1 is rejected and retried smaller (down to ``4 ds_min``), and
        the next step is sized for a ratio of about 0.6 (the chord error grows like
        the step squared).
    until : callable, optional
        ``until(y) -> bool``: stop successfully (``Status.DONE``) after the first
        accepted point for which it is true (local re-traces).

    Returns
    -------
    Branch
    """
    y = np.array(y0, dtype=float)
    t = _start(fun, y, br, tangent0)
    if t is None:
        return br
    ds = settings.ds_initial
    lam_span = abs(lam_end - y[-1])
    lam_low = (lam_start if lam_start is not None else y[-1]) - 0.05 * lam_span
    while True:
        if br.n_steps >= settings.max_steps:
            br.status = Status.TOO_MANY_STEPS
            br.message = f"stopped after max_steps = {settings.max_steps}"
            return br
        br.n_steps += 1
        step = _step(fun, y, t, ds, settings, br)
        if step.failure is not None:
            ds *= 0.5
            if ds < settings.ds_min:
                br.status = step.status
                br.message = (f"step size below ds_min = {settings.ds_min:g} at "
                              f"lam = {y[-1]:.6g} ({step.failure})"
                              if step.status is Status.STEP_TOO_SMALL
                              else step.failure)
                return br
            continue
        ratio = 0.0 if chord_error is None else chord_error(y, t, step.y, step.t)
        if ratio > 1.0 and ds > 4 * settings.ds_min:
            ds = max(ds * max(0.2, 0.8 / math.sqrt(ratio)), 2 * settings.ds_min)
            continue
        if step.y[-1] >= lam_end:
            step = _land(fun, y, step, t, lam_end, settings, br)
        y_new, t_new = step.y, step.t
        if t_new[-1] * t[-1] < 0.0:
            br.turning_points.append(len(br.y))
        br.y.append(y_new.copy())
        br.tangent.append(t_new)
        br.jacobian.append(step.J)
        br.det_sign.append(step.det_sign)
        br.n_iter.append(step.n_iter)
        if callback is not None:
            callback(y_new[-1])
        if y_new[-1] >= lam_end or (until is not None and until(y_new)):
            br.success = True
            br.status, br.message = Status.DONE, "reached the end of the range"
            return br
        if _retraced(br):
            return br
        if y_new[-1] < lam_low:
            br.status = Status.TURNED_BACK
            br.message = f"branch turned back below the start (lam = {y_new[-1]:.6g})"
            return br
        ds = _next_ds(ds, step.n_iter, t, t_new, settings, ratio)
        y, t = y_new, t_new


def _start(fun: Callable, y: np.ndarray, br: Branch,
           direction: np.ndarray | None = None) -> np.ndarray | None:
    """Record the start point of the branch; its tangent towards larger lam (or along
    ``direction``), or None (``br`` says why)."""
    n = y.size - 1
    try:
        R, J = fun(y)
    except Exception as exc:  # noqa: BLE001 - work started: report, never raise
        br.status = Status.EVALUATION_FAILED
        br.message = f"evaluation failed at the start point: {exc}"
        return None
    e = np.zeros(n + 1)
    e[-1] = 1.0
    tg = _tangent(J, e if direction is None else direction)
    if tg is None:
        br.status = Status.EVALUATION_FAILED
        br.message = "singular Jacobian at the start point"
        return None
    br.y.append(y.copy())
    br.tangent.append(tg.t)
    br.jacobian.append(J)
    br.det_sign.append(tg.det_sign)
    br.n_iter.append(0)
    return tg.t


class _Step(NamedTuple):
    """One predictor-corrector step: the new point, its tangent and Jacobian, or why
    it failed (``failure`` is not None; ``status`` if the step size runs out)."""

    y: np.ndarray | None
    t: np.ndarray | None
    J: np.ndarray | None
    n_iter: int
    failure: str | None = None
    status: Status = Status.STEP_TOO_SMALL
    det_sign: float = math.nan  # of dR/dx at y (Branch.det_sign)


def _step(fun: Callable, y: np.ndarray, t: np.ndarray, ds: float,
          settings: ContinuationSettings, br: Branch) -> _Step:
    """Tangent predictor of length ``ds``, pseudo-arclength corrector, a corner step
    when the corrector fails at a small step; the tangent at the new point."""
    y_pred = y + ds * t
    y_new, ok, its, msg = newton(fun, y_pred, settings, tangent=t, y_pred=y_pred)
    br.n_newton += its
    if ok and _norm(y_new - y_pred) > settings.max_correction * ds:
        # converged far from the prediction: probably onto another branch
        ok, msg = False, "corrector jumped away from the prediction"
    corner = None
    if not ok and ds <= settings.corner_ds:
        y_c, its_c, corner = _corner_step(fun, y, t, ds, settings, br.y[-4:])
        br.n_newton += its_c
        if corner is not None:
            y_new, ok, its = y_c, True, its_c
    if not ok:
        return _Step(None, None, None, its, msg)
    try:
        R, J = fun(y_new)
        # after a corner the new piece's direction gives the orientation
        tg = _tangent(J, t if corner is None else corner)
    except Exception:  # noqa: BLE001
        tg = None
    if tg is None:
        return _Step(None, None, None, its, f"tangent failed at lam = {y_new[-1]:.6g}",
                     Status.EVALUATION_FAILED)
    return _Step(y_new, tg.t, J, its, det_sign=tg.det_sign)


def _land(fun: Callable, y, step: _Step, t, lam_end: float,
          settings: ContinuationSettings, br: Branch) -> _Step:
    """A step past ``lam_end``: land exactly on it by natural-parameter Newton from
    the secant; the landed point with its tangent, Jacobian and Newton iterations
    (``step`` itself if the landing fails)."""
    n = y.size - 1
    frac = (lam_end - y[-1]) / (step.y[-1] - y[-1])
    y_end = y + frac * (step.y - y)
    y_end[-1] = lam_end
    y_c, ok_end, its, _ = newton(fun, y_end, settings, fixed=n)
    br.n_newton += its
    if not ok_end:
        return step._replace(n_iter=its)
    try:
        J_end = fun(y_c)[1]
        tg = _tangent(J_end, t)
    except Exception:  # noqa: BLE001
        tg = None
    if tg is None:  # the step's tangent and Jacobian at the landed point
        return step._replace(y=y_c, n_iter=its)
    return _Step(y_c, tg.t, J_end, its, det_sign=tg.det_sign)


#: ``{id(branch): (old points, their _polyline)}`` of :func:`_retraced`
_RETRACE_POLYLINE: dict = {}


def _retraced(br: Branch) -> bool:
    """Whether the last point fell back onto the part traced before the last turning
    point; if so, the retraced points are dropped and ``br`` says so.

    A branch can turn back onto itself at a kink of the sampled nonsmooth problem or
    at a branch point of a symmetric system. "Onto": within 5 % of the nearest old
    chord (the chords' own error from the curvature), away from the fold (arc > 0.2
    scaled units), within 400 points of it.
    """
    if not br.turning_points or len(br.y) - br.turning_points[-1] > 400:
        return False
    k = br.turning_points[-1]
    old = br.y[max(0, k - 400):k - 2]
    if len(old) < 2 or _norm(br.y[-1] - br.y[k]) <= 0.2:
        return False
    # the old points do not change while the branch grows past turning point k:
    # their polyline is built once (kept with the points it was built from)
    kept = _RETRACE_POLYLINE.get(id(br))
    if kept is None or len(kept[0]) != len(old) or any(
            x is not y for x, y in zip(kept[0], old, strict=True)):
        kept = (old, _polyline(old))
        _RETRACE_POLYLINE.clear()   # one branch grows at a time
        _RETRACE_POLYLINE[id(br)] = kept
    dist, seg = _distance_to_polyline(br.y[-1], old, with_segment=True,
                                      geometry=kept[1])
    if not dist < 0.05 * seg + 1e-9:
        return False
    f_tp = br.y[k][-1]
    del br.y[k + 1:], br.tangent[k + 1:], br.jacobian[k + 1:], br.det_sign[k + 1:]
    del br.n_iter[k + 1:]
    br.turning_points.pop()
    br.status = Status.RETRACED
    br.message = (f"the branch turns back onto itself at lam = {f_tp:.6g} "
                  f"(a dead end of the sampled nonsmooth problem or a "
                  f"branch point; try more samples or harmonics)")
    return True


def _next_ds(ds: float, its: int, t: np.ndarray, t_new: np.ndarray,
             settings: ContinuationSettings, chord_ratio: float = 0.0) -> float:
    """Eq. 3.66 with bounded growth, plus a curvature limit: the angle between
    successive tangents should not exceed ``max_angle`` (resolves peaks and folds);
    with a chord error ``chord_ratio`` (relative to its tolerance) the step is sized
    for a ratio of about 0.6."""
    fac = np.sqrt(settings.n_norm / max(its, 1))
    angle = float(np.arccos(np.clip(np.dot(t, t_new), -1.0, 1.0)))
    if angle > 0.0:
        fac = min(fac, max(settings.max_angle / angle, 0.5))
    if chord_ratio > 0.0:
        fac = min(fac, max(0.2, math.sqrt(0.6 / chord_ratio)))
    ds = min(settings.ds_max, ds * min(fac, settings.max_growth))
    return max(ds, settings.ds_min)
