"""Alternating frequency-time (AFT) evaluation of the mount nonlinearities.

Harmonic coefficients ``U`` (static, cos 1, sin 1, ..., cos H, sin H) of each axis
deflection are sampled at ``N`` equidistant phases ``theta_n = 2 pi n / N`` of one
period (``u = E U``), the nonlinear remainder of the mount law is evaluated there
(:mod:`hbm.elements`), and projected back (``F = P f``, the discrete Fourier transform
truncated to H harmonics; ``P E = I`` for ``N > 2H``). The Jacobian follows by the chain
rule through the law's tangent at each sample (``dF/dU = P diag(df/du) E``); for the
Jenkins element a stuck sample depends on the last slip sample too (see
:func:`hbm.elements.jenkins_periodic`). The Jenkins march is vectorised over samples,
elements and batches (:mod:`hbm.friction_march`). The inclined element of Ch. 5 is
marched by :mod:`hbm.inclined`, its Jacobian carried through the march.

The nonlinear remainders are rate independent (the viscous part ``c v`` is linear and
handled in the frequency domain), so the AFT needs no velocities and its result does
not depend on ``omega``.

References: thesis Sec. 3.1 (Fourier approximation, eq. 3.8-3.10); Cameron and Griffin
(1989) for AFT; NLvib (Krack and Gross 2019) for the sampled Jacobian.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from drymount.hbm.elements import NonlinearAxes, elastic_remainder, jenkins_periodic
from drymount.hbm.friction_march import _chosen, c_in_auto, jenkins_aft, jenkins_march
from drymount.hbm.generic_march import generic_aft
from drymount.hbm.inclined import inclined_aft

__all__ = ["FourierBasis", "default_n_samples", "aft_forces", "HARMONIC_FROM"]

#: AFT samples from which the Jacobians are built in harmonic form
#: (:meth:`FourierBasis.gram`): 14x cheaper than the dense product at H = 7,
#: N = 1024, no gain at N = 64. Below it the dense products are kept: the two agree
#: to round-off (5e-16 of the norm), but a round-off change of the Jacobian moves the
#: continuation's points on the kinked residual of a sampled nonsmooth law
#: (docs/performance.md, "The 6-DOF curve").
HARMONIC_FROM = 512


def default_n_samples(harmonics: int) -> int:
    """``max(64, 8 H)`` rounded up to a power of two."""
    n = max(64, 8 * harmonics)
    return 1 << (n - 1).bit_length()


class FourierBasis:
    """Real Fourier basis of H harmonics sampled at N phases.

    Attributes
    ----------
    H, N : int
    E : ndarray, shape (N, 2H+1)
        ``E[n] = [1, cos th_n, sin th_n, ..., cos H th_n, sin H th_n]``.
    P : ndarray, shape (2H+1, N)
        Projection onto the coefficients (``P E = I``).
    D : ndarray, shape (2H+1, 2H+1)
        Derivative with respect to ``theta`` in coefficient space
        (``d/dtheta (E U) = E D U``).
    """

    def __init__(self, harmonics: int, n_samples: int):
        H, N = int(harmonics), int(n_samples)
        if N <= 2 * H:
            raise ValueError(f"`n_samples` must be > 2 * harmonics = {2 * H}, got {N}")
        self.H, self.N = H, N
        theta = 2.0 * np.pi * np.arange(N) / N
        m = 2 * H + 1
        E = np.empty((N, m))
        E[:, 0] = 1.0
        D = np.zeros((m, m))
        for k in range(1, H + 1):
            E[:, 2 * k - 1] = np.cos(k * theta)
            E[:, 2 * k] = np.sin(k * theta)
            D[2 * k, 2 * k - 1] = -k  # d/dth(c cos) = -k c sin
            D[2 * k - 1, 2 * k] = k   # d/dth(s sin) = k s cos
        P = E.T * (2.0 / N)
        P[0] *= 0.5
        self.E, self.P, self.D = E, P, D
        self.theta = theta
        self._gram = None
        self._cum_p = None

    def cumulative_projection(self) -> np.ndarray:
        """``C[n] = sum_{j < n} P[:, j]``, shape (N + 1, 2H+1) (sums of ``P`` over
        runs of samples as differences of two rows)."""
        if self._cum_p is None:
            cum = np.zeros((self.N + 1, self.P.shape[0]))
            np.cumsum(self.P.T, axis=0, out=cum[1:])
            self._cum_p = cum
        return self._cum_p

    def gram(self, kt: np.ndarray) -> np.ndarray:
        """``P diag(kt[:, c]) E`` for each column ``c`` of ``kt``, in harmonic form.

        ``kt`` has shape (..., N, C) (C weights sampled at the N phases); returns
        (..., C, 2H+1, 2H+1), C-contiguous. The entry ``(h, g)`` is ``sum_n P[h, n]
        kt_n E[n, g]``, and a product of two basis functions of harmonics ``a``,
        ``b`` is a sum of basis functions of harmonics ``a + b`` and ``|a - b|``
        (``cos a cos b = (cos(a-b) + cos(a+b)) / 2`` etc.). So the matrix is a
        fixed linear map of the 4H+1 Fourier sums of ``kt`` up to harmonic 2H: one
        product with the (4H+1, N) basis ``E2^T`` and one with the (4H+1, m^2) map
        ``G`` (Toeplitz plus Hankel structure), O(N H + H^3) per column instead of
        the dense O(N H^2). Exact up to round-off (tested against the dense
        product).
        """
        if self._gram is None:
            self._gram = _gram_maps(self.H, self.theta)
        E2t, G = self._gram
        m = self.E.shape[1]
        sums = np.swapaxes(E2t @ kt, -1, -2)  # (..., C, 4H+1)
        return (sums @ G).reshape(*sums.shape[:-1], m, m)


def _gram_maps(H: int, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two factors of :meth:`FourierBasis.gram`: ``E2^T`` (4H+1, N), the basis
    up to harmonic 2H at ``theta``, and ``G`` (4H+1, m^2) with the row scales of
    ``P`` (1/N for the static row, 2/N otherwise)."""
    N, m, m2 = theta.size, 2 * H + 1, 4 * H + 1
    E2 = np.empty((N, m2))
    E2[:, 0] = 1.0
    for k in range(1, 2 * H + 1):
        E2[:, 2 * k - 1] = np.cos(k * theta)
        E2[:, 2 * k] = np.sin(k * theta)
    # basis index j -> (harmonic, is_sine); index 0 is cos 0 = 1
    harm = [0] + [k for k in range(1, H + 1) for _ in (0, 1)]
    sine = [False] + [s for _ in range(1, H + 1) for s in (False, True)]
    G = np.zeros((m2, m, m))

    def add(h, g, k, is_sine, w):
        if is_sine:
            if k == 0:
                return  # sin 0 = 0
            w, k = (w, k) if k > 0 else (-w, -k)  # sin(-x) = -sin x
            G[2 * k, h, g] += w
        else:
            k = abs(k)
            G[0 if k == 0 else 2 * k - 1, h, g] += w

    for h in range(m):
        a, sa = harm[h], sine[h]
        scale = (1.0 if h == 0 else 2.0) / N
        for g in range(m):
            b, sb = harm[g], sine[g]
            w = 0.5 * scale
            if not sa and not sb:    # cos a cos b
                add(h, g, a - b, False, w)
                add(h, g, a + b, False, w)
            elif sa and sb:          # sin a sin b
                add(h, g, a - b, False, w)
                add(h, g, a + b, False, -w)
            elif not sa:             # cos a sin b = (sin(a+b) - sin(a-b)) / 2
                add(h, g, a + b, True, w)
                add(h, g, a - b, True, -w)
            else:                    # sin a cos b = (sin(a+b) + sin(a-b)) / 2
                add(h, g, a + b, True, w)
                add(h, g, a - b, True, w)
    return np.ascontiguousarray(E2.T), G.reshape(m2, m * m)


@dataclass(frozen=True)
class _Plan:
    """What :func:`aft_forces` needs of a :class:`NonlinearAxes`, prepared once."""

    friction: np.ndarray  # indices of the Jenkins axes
    all_friction: bool  # every axis has one (no gather needed)
    kf: np.ndarray
    fs: np.ndarray
    w_start: np.ndarray
    elastic: bool  # some axis has a nonlinear elastic remainder
    #: the compiled path's law code and parameters per axis (:func:`_law_codes`);
    #: None where a law has no compiled form
    codes: tuple | None = None
    friction_i8: np.ndarray | None = None  # ``friction`` as int64 (compiled path)


_PLANS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

#: laws the compiled AFT samples (hbm.friction_march_numba.aft_samples) evaluate:
#: name -> (code, parameters): 1 the gap law (dk, delta, delta_neg), 2 cubic (kc)
_COMPILED_LAWS = {
    "linear": (0, lambda ax: (0.0, 0.0, 0.0)),
    "piecewise": (1, lambda ax: (ax.k2 - ax.k1, ax.delta, ax.delta)),
    "piecewise_asym": (1, lambda ax: (ax.k2 - ax.k1, ax.delta, ax.delta_neg)),
    "cubic": (2, lambda ax: (ax.kc, 0.0, 0.0)),
}


def _law_codes(ax: NonlinearAxes) -> tuple | None:
    """``(code, p1, p2, p3)`` arrays per axis for the compiled samples, or None."""
    if any(name not in _COMPILED_LAWS for name in ax.law):
        return None
    n = ax.n
    code = np.zeros(n, dtype=np.int64)
    p = np.zeros((3, n))
    for name in dict.fromkeys(ax.law):
        mask = np.array([law == name for law in ax.law])
        c, params = _COMPILED_LAWS[name]
        code[mask] = c
        for i, v in enumerate(params(ax)):
            p[i, mask] = np.broadcast_to(v, (n,))[mask]
    return (code, p[0].copy(), p[1].copy(), p[2].copy())


def _plan(ax: NonlinearAxes) -> _Plan:
    plan = _PLANS.get(ax)
    if plan is None:
        fr = ax.friction
        plan = _Plan(fr, bool(np.array_equal(fr, np.arange(ax.n))),
                     np.ascontiguousarray(ax.kf[fr]), np.ascontiguousarray(ax.fs[fr]),
                     np.ascontiguousarray(ax.w_start[fr], dtype=float),
                     any(law.remainder is not None and bool(np.any(mask))
                         for law, mask in ax.groups), _law_codes(ax),
                     fr.astype(np.int64))
        _PLANS[ax] = plan
    return plan


def aft_forces(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis,
               jacobian: bool = True, omega: float | None = None
               ) -> tuple[np.ndarray, np.ndarray | None]:
    """Fourier coefficients of the nonlinear remainders by AFT, with the Jacobian.

    Parameters
    ----------
    U : ndarray, shape (..., 2H+1, n_ax)
        Deflection coefficients of each axis, m (leading axes: any batch, e.g.
        several frequency points, evaluated in one pass).
    ax : NonlinearAxes
    basis : FourierBasis
    jacobian : bool
    omega : float or None
        Frequency, rad/s: the generic march of a rate-dependent element needs it.

    Returns
    -------
    F : ndarray, shape (..., 2H+1, n_ax)
        Force coefficients, N.
    dF : ndarray, shape (..., n_ax, 2H+1, 2H+1) or None
        ``dF[..., a, h, g] = dF[..., h, a] / dU[..., g, a]``.
    """
    F, dF = _aft_jenkins(U, ax, basis, jacobian)
    if ax.inclined:   # the inclined element's march (hbm.inclined), added per axis
        for a, Fa, dFa in inclined_aft(basis.E @ U, ax, basis, jacobian):
            F[..., a] += Fa
            if jacobian:
                dF[..., a, :, :] += dFa
    if ax.generic:    # elements without a fast form: their own step (generic_march)
        flat = U.reshape(-1, *U.shape[-2:])
        Fb, dFb = F.reshape(flat.shape), None
        if jacobian:
            dFb = dF.reshape(flat.shape[0], *dF.shape[-3:])
        for a, p in ax.generic:
            for b in range(flat.shape[0]):
                Fa, dFa = generic_aft(flat[b, :, a], p, float(ax.w_start[a]), basis,
                                      omega, jacobian, ax.start_state(a))
                Fb[b, :, a] += Fa
                if jacobian:
                    dFb[b, a] += dFa
    return F, dF


def _aft_jenkins(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis,
                 jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`aft_forces` of the elastic remainders and the Jenkins elements: the
    Jacobian in harmonic form from :data:`HARMONIC_FROM` samples on
    (:func:`_aft_harmonic`), by the dense products below (:func:`_aft_dense`)."""
    if _has_slider_banks(ax):   # micro-slip or non-symmetric sliders: per slider
        return _aft_banks(U, ax, basis, jacobian)
    if jacobian and basis.N >= HARMONIC_FROM:
        return _aft_harmonic(U, ax, basis)
    return _aft_dense(U, ax, basis, jacobian)


def _samples(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis):
    """The plan of ``ax``, the deflection samples ``u = E U`` (..., N, n_ax) and the
    elastic remainder's force and tangent there (None, None without one)."""
    plan = _plan(ax)
    u = basis.E @ U
    if plan.elastic:
        return (plan, u, *elastic_remainder(u, ax))
    return plan, u, None, None


def _aft_harmonic(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis
                  ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_aft_jenkins` with the Jacobian in harmonic form: ``P diag(kt) E``
    with ``kt`` the elastic tangent plus ``kf`` at every stuck sample
    (:meth:`FourierBasis.gram`), minus the slip memory of the Jenkins elements
    (:func:`_subtract_slip_memory`). Equal to the dense products to round-off."""
    P = basis.P
    plan = _plan(ax)
    if plan.codes is not None and plan.friction.size:
        backend = _chosen(None, U.size // U.shape[-2] * basis.N)
        if backend in ("numba", "c"):
            return _aft_harmonic_compiled(U, plan, basis, backend)
    plan, u, f, kt = _samples(U, ax, basis)
    if f is None:
        f = np.zeros_like(u)
    march = None
    if plan.friction.size:
        # the Jenkins elements, all at once (hbm.friction_march: equal to the scalar
        # march of hbm.elements.jenkins_periodic, without a per-sample Python loop)
        fr = plan.friction
        march = jenkins_march(u if plan.all_friction else u[..., fr], plan.kf,
                              plan.fs, plan.w_start)
        f[..., fr] += march.force
    F = P @ f
    if kt is None:
        kt = np.zeros_like(u)
    if march is not None:
        kt[..., plan.friction] += plan.kf * march.stuck
    dF = basis.gram(kt)
    if march is not None:
        _subtract_slip_memory(dF, march, plan, basis)
    return F, dF


def _aft_harmonic_compiled(U: np.ndarray, plan: _Plan, basis: FourierBasis,
                           backend: str = "numba") -> tuple[np.ndarray, np.ndarray]:
    """:func:`_aft_harmonic` with the samples (elastic remainders, Jenkins march, the
    tangent's sums) and the slip memory compiled
    (:func:`hbm.friction_march_numba.aft_samples`, ``slip_memory``; with ``backend``
    "c" the same kernels in C, :mod:`hbm.aft_native`): the same operations in the
    same order, the same numbers."""
    if backend == "c":
        from drymount.hbm import aft_native
        return _aft_harmonic_native(U, plan, basis, aft_native)
    import drymount.hbm.friction_march_numba as nb

    u = basis.E @ U
    u3 = u.reshape(-1, *u.shape[-2:])
    code, p1, p2, p3 = plan.codes
    f, kt, stuck, last = nb.aft_samples(u3, code, p1, p2, p3, plan.friction_i8,
                                        plan.kf, plan.fs, plan.w_start)
    F = basis.P @ f.reshape(u.shape)
    dF = basis.gram(kt.reshape(u.shape))
    nb.slip_memory(dF.reshape(-1, *dF.shape[-3:]), stuck, last, plan.friction_i8,
                   plan.kf, basis.cumulative_projection(), basis.E)
    return F, dF


def _aft_harmonic_native(U: np.ndarray, plan: _Plan, basis: FourierBasis, native
                         ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_aft_harmonic_compiled` through the C kernels bound once to ``plan``
    and ``basis`` (:func:`hbm.aft_native.bound`): the same numbers."""
    shape = (*U.shape[:-2], basis.N, U.shape[-1])
    kern = native.bound(plan, basis, U.size // (U.shape[-2] * U.shape[-1]),
                        U.shape[-1])
    f, kt, _, _ = kern.samples(U, basis.E)
    F = basis.P @ f.reshape(shape)
    dF = basis.gram(kt.reshape(shape))
    kern.slip_memory(dF.reshape(-1, *dF.shape[-3:]))
    return F, dF


def _aft_dense(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis,
               jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`_aft_jenkins` by the dense products ``P diag(kt) E`` and ``P Z``
    (:func:`hbm.friction_march.jenkins_aft`)."""
    E, P = basis.E, basis.P
    plan, u, f, kt = _samples(U, ax, basis)
    dF_fr = None
    if plan.friction.size:
        fr = plan.friction
        if jacobian and c_in_auto():   # the C kernels bound to the plan
            ff, dF_fr = _jenkins_native(u, plan, basis)
        else:
            ff, dF_fr = jenkins_aft(u if plan.all_friction else u[..., fr], plan.kf,
                                    plan.fs, plan.w_start, E, P, jacobian)
        if f is None and plan.all_friction:
            f = ff
        else:
            if f is None:
                f = np.zeros_like(u)
            f[..., fr] += ff
    if f is None:  # no remainder at all (e.g. a linear axis without friction)
        f = np.zeros_like(u)
    F = P @ f
    if not jacobian:
        return F, None
    fr = plan.friction
    if kt is not None:
        # dF[a] = P diag(kt[:, a]) E, plus the Jenkins part
        dF = (P * np.swapaxes(kt, -1, -2)[..., None, :]) @ E
        if dF_fr is not None:
            dF[..., fr, :, :] += dF_fr
    elif plan.all_friction and dF_fr is not None:
        dF = dF_fr
    else:
        dF = np.zeros((*U.shape[:-2], ax.n, *P.shape[:1], E.shape[1]))
        if dF_fr is not None:
            dF[..., fr, :, :] = dF_fr
    return F, dF


def _jenkins_native(u: np.ndarray, plan: _Plan, basis: FourierBasis):
    """:func:`hbm.friction_march.jenkins_aft` of the friction columns of ``u`` (...,
    N, n_ax) through the C kernels bound to ``plan`` and ``basis``: the same
    numbers (the march and ``Z`` of :mod:`hbm.aft_native`, ``dF = P Z``)."""
    from drymount.hbm import aft_native

    u3 = u.reshape(-1, *u.shape[-2:])
    kern = aft_native.bound(plan, basis, *u3.shape[::2])
    force, Z = kern.march_samples(u3 if plan.all_friction else u3[..., plan.friction])
    dF = basis.P @ Z
    C = plan.friction.size
    return (force.reshape(*u.shape[:-1], C),
            dF.reshape(*u.shape[:-2], *dF.shape[-3:]))


def _subtract_slip_memory(dF: np.ndarray, march, plan: _Plan,
                          basis: FourierBasis) -> None:
    """Subtract, in place, the Jenkins elements' dependence on the last slip.

    A stuck sample ``n`` with a last slip ``l = last_slip[n] >= 0`` has
    ``df_n = kf (du_n - du_l)``; the second part adds ``-kf P[:, n] E[l]`` to
    ``dF``. All samples of one stick run share ``l``, so a run contributes the
    rank-one ``-kf (sum_run P[:, n]) E[l]``, the sum a difference of cumulative
    sums of ``P``: O(runs H^2) instead of the dense O(N H^2).

    ``dF`` has shape (..., n_ax, m, m); ``march`` is of the friction axes
    ``plan.friction`` with shape (..., N, C).
    """
    stuck = np.swapaxes(march.stuck, -1, -2)  # (..., C, N)
    last = np.swapaxes(march.last_slip, -1, -2)
    C, N = stuck.shape[-2:]
    idx = np.flatnonzero(stuck & (last >= 0))  # flat (batch, C, N) order
    if not idx.size:
        return
    lst = last.reshape(-1)[idx]
    n = idx % N
    new = np.empty(idx.size, dtype=bool)
    new[0] = True
    new[1:] = (idx[1:] != idx[:-1] + 1) | (lst[1:] != lst[:-1]) | (n[1:] == 0)
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], idx.size) - 1
    cum = basis.cumulative_projection()  # (N + 1, m)
    col = idx[starts] // N  # flat (batch, C) column of each run
    p_sum = (cum[n[ends] + 1] - cum[n[starts]]) * plan.kf[col % C][:, None]
    m = dF.shape[-1]
    flat = dF.view()
    flat.shape = (-1, m, m)  # a view (raises rather than copy)
    target = (col // C) * dF.shape[-3] + plan.friction[col % C]
    np.subtract.at(flat, target, p_sum[:, :, None] * basis.E[lst[starts]][:, None, :])


def _has_slider_banks(ax: NonlinearAxes) -> bool:
    """Whether an axis has more than one slider or a non-symmetric one (the
    vectorised march of :mod:`hbm.friction_march` takes one symmetric slider)."""
    return not all(len(b) <= 1 and (not b or b[0][1] == b[0][2]) for b in ax.banks)


def _aft_banks(U: np.ndarray, ax: NonlinearAxes, basis: FourierBasis,
               jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`aft_forces` marching every slider of each axis's bank with the scalar
    :func:`hbm.elements.jenkins_periodic` (batches one by one)."""
    if U.ndim > 2:
        batch = U.reshape(-1, *U.shape[-2:])
        parts = [_aft_banks(u, ax, basis, jacobian) for u in batch]
        F = np.stack([p[0] for p in parts]).reshape(*U.shape[:-2], *parts[0][0].shape)
        if not jacobian:
            return F, None
        dF = np.stack([p[1] for p in parts]).reshape(*U.shape[:-2], *parts[0][1].shape)
        return F, dF
    E, P = basis.E, basis.P
    u = E @ U  # (N, n_ax)
    f, kt = elastic_remainder(u, ax)
    fr = ax.friction
    corr = []
    for a in fr:
        # each slider of the axis's bank (one for macro-slip, several for micro-slip)
        start = ax.start_floats(a)
        for i, (k, fs_pos, fs_neg) in enumerate(ax.banks[a]):
            # slider i from its own start (a state not relaxed: hbm.static's lowered
            # reading), else from the common w_start
            w0 = start[i] if start is not None and len(start) == len(ax.banks[a]) \
                else ax.w_start[a]
            ff, stuck, last = jenkins_periodic(u[:, a], k, fs_pos, w0, fs_neg)
            f[:, a] += ff
            if jacobian:
                kt[:, a] += np.where(stuck, k, 0.0)
                # stuck after a slip: w = u[last] -+ eps depends on X too
                sel = np.flatnonzero(stuck & (last >= 0))
                corr.append((a, k, sel, last[sel]))
    F = P @ f
    if not jacobian:
        return F, None
    # dF[a] = P diag(kt[:, a]) E  (- kf P[:, sel] E[last[sel]] for Jenkins)
    dF = np.matmul(P[None, :, :] * kt.T[:, None, :], E)
    for a, k, sel, last in corr:
        if sel.size:
            dF[a] -= k * (P[:, sel] @ E[last])
    return F, dF
