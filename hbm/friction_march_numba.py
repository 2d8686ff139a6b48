"""Compiled (numba) kernels of the Jenkins march and its AFT Jacobian (optional).

Imported by :mod:`hbm.friction_march` only when numba is installed (the ``fast`` extra:
``pip install drymount[fast]``) and the compiled march pays (:mod:`hbm.march_choice`).
The march is the algorithm of
:func:`hbm.elements.jenkins_periodic` (the scalar return map of
:func:`fmu_src.mount_law.jenkins_update`) with the same floating-point operations in the
same order, compiled, so it gives the same numbers bit for bit
(``tests/test_hbm_friction_march.py``). Compiled once per machine (``cache=True``):
:func:`warm` compiles every kernel for the arrays the AFT passes, which
:mod:`hbm.march_choice` runs in a background process where the cache is cold.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["march", "jacobian_samples", "march_and_samples", "warm", "aft_samples",
           "slip_memory"]


@njit(cache=True)
def _column(u, kf, fs, w_start, force, stuck, last_slip):  # pragma: no cover - jit
    n = u.shape[0]
    eps = fs / kf
    i_max = 0
    i_min = 0
    for i in range(1, n):
        if u[i] > u[i_max]:
            i_max = i
        if u[i] < u[i_min]:
            i_min = i
    if u[i_max] - u[i_min] > 2.0 * eps:
        start = i_max
        w = u[i_max] - eps
        last = i_max
    else:
        start = 0
        w = w_start
        last = -1
        for i in range(n):
            trial = kf * (u[i] - w)
            if trial > fs:
                w = u[i] - fs / kf
                last = i
            elif trial < -fs:
                w = u[i] + fs / kf
                last = i
    for j in range(n):
        i = start + j
        if i >= n:
            i -= n
        trial = kf * (u[i] - w)
        if trial > fs:
            force[i] = fs
            w = u[i] - fs / kf
            last = i
            stuck[i] = False
        elif trial < -fs:
            force[i] = -fs
            w = u[i] + fs / kf
            last = i
            stuck[i] = False
        else:
            force[i] = trial
            stuck[i] = True
        last_slip[i] = last


@njit(cache=True)
def _march(u, kf, fs, w_start, force, stuck, last_slip):  # pragma: no cover - jit
    nb, _, C = u.shape
    for b in range(nb):
        for c in range(C):
            _column(u[b, :, c], kf[c], fs[c], w_start[c], force[b, :, c],
                    stuck[b, :, c], last_slip[b, :, c])


def march(u: np.ndarray, kf: np.ndarray, fs: np.ndarray, w_start: np.ndarray):
    """``(force, stuck, last_slip)`` of the periodic march of ``u`` (nb, N, C)."""
    force = np.empty_like(u)
    stuck = np.empty(u.shape, dtype=np.bool_)
    last = np.empty(u.shape, dtype=np.int64)
    _march(u, kf, fs, w_start, force, stuck, last)
    return force, stuck, last


@njit(cache=True)
def _samples(E, kf, stuck, last, Z):  # pragma: no cover - jit
    nb, N, C = stuck.shape
    m = E.shape[1]
    for b in range(nb):
        for c in range(C):
            k = kf[c]
            for n in range(N):
                if stuck[b, n, c]:
                    for g in range(m):
                        Z[b, c, n, g] = k * E[n, g]
                    j = last[b, n, c]
                    if j >= 0:
                        for g in range(m):
                            Z[b, c, n, g] -= k * E[j, g]
                else:
                    for g in range(m):
                        Z[b, c, n, g] = 0.0


def jacobian_samples(E: np.ndarray, kf: np.ndarray, stuck: np.ndarray,
                     last: np.ndarray) -> np.ndarray:
    """``Z`` (nb, C, N, m) with ``dF = P Z``.

    See :func:`hbm.friction_march.jenkins_jacobian`.
    """
    nb, N, C = stuck.shape
    Z = np.empty((nb, C, N, E.shape[1]))
    _samples(E, kf, stuck, last, Z)
    return Z


@njit(cache=True)
def _march_samples(u, kf, fs, w_start, E, force, stuck, last, Z):  # pragma: no cover
    _march(u, kf, fs, w_start, force, stuck, last)
    _samples(E, kf, stuck, last, Z)


def march_and_samples(u: np.ndarray, kf: np.ndarray, fs: np.ndarray,
                      w_start: np.ndarray, E: np.ndarray):
    """``(force, Z)``: :func:`march` and :func:`jacobian_samples` in one call."""
    nb, N, C = u.shape
    force = np.empty_like(u)
    stuck = np.empty(u.shape, dtype=np.bool_)
    last = np.empty(u.shape, dtype=np.int64)
    Z = np.empty((nb, C, N, E.shape[1]))
    _march_samples(u, kf, fs, w_start, E, force, stuck, last, Z)
    return force, Z


def warm() -> None:
    """Compile (or load from the cache) every kernel for the AFT's argument types:
    float64 C-ordered motions (nb, N, C) and bases (N, m)."""
    u = np.linspace(-1e-3, 1e-3, 2 * 8 * 2).reshape(2, 8, 2)
    kf, fs, w0 = np.full(2, 6e4), np.full(2, 20.0), np.zeros(2)
    E = np.ones((8, 3))
    _, stuck, last = march(u, kf, fs, w0)
    jacobian_samples(E, kf, stuck, last)
    march_and_samples(u, kf, fs, w0, E)
    code = np.array([LAW_GAP, LAW_CUBIC], dtype=np.int64)
    fr = np.array([0, 1], dtype=np.int64)
    f, kt, st, la = aft_samples(u, code, kf, fs, w0, fr, kf, fs, w0)
    slip_memory(np.zeros((2, 2, 3, 3)), st, la, fr, kf, np.zeros((9, 3)), E)


# -------------------------------------------------------------------------------------
# The harmonic-form AFT of hbm.aft in two compiled calls (issue 27): the sampled
# elastic remainders, the Jenkins march and the sums of the tangent, then the slip
# memory's rank-one terms; the same floating-point operations in the same order as
# the NumPy code they replace (hbm.laws, hbm.aft._aft_harmonic,
# hbm.aft._subtract_slip_memory), so the same numbers bit for bit
# (tests/test_hbm_aft_fused.py).
# -------------------------------------------------------------------------------------
#: law codes of :func:`aft_samples`: no remainder, the gap law of hbm.laws (piecewise,
#: piecewise_asym), the cubic law
LAW_NONE, LAW_GAP, LAW_CUBIC = 0, 1, 2


@njit(cache=True)
def _aft_samples(u, code, p1, p2, p3, fr, kf, fs, w_start, f, kt, stuck, last,
                 force, cstuck, clast, col):  # pragma: no cover - jit
    nb, N, n_ax = u.shape
    for b in range(nb):
        for a in range(n_ax):
            c = code[a]
            if c == 1:    # hbm.laws._gap_remainder: dk, delta, delta_neg
                dk, dl, dn = p1[a], p2[a], p3[a]
                for n in range(N):
                    x = u[b, n, a]
                    hi = x > dl
                    lo = x < -dn
                    s1 = x - dl if hi else 0.0
                    s2 = x + dn if lo else 0.0
                    f[b, n, a] = dk * (s1 + s2)
                    kt[b, n, a] = dk * (1.0 if (hi or lo) else 0.0)
            elif c == 2:  # hbm.laws._cubic_remainder: kc
                kc = p1[a]
                k3 = 3.0 * kc
                for n in range(N):
                    x = u[b, n, a]
                    f[b, n, a] = kc * x * x * x
                    kt[b, n, a] = k3 * x * x
            else:
                for n in range(N):
                    f[b, n, a] = 0.0
                    kt[b, n, a] = 0.0
        for j in range(fr.shape[0]):
            a = fr[j]
            for n in range(N):
                col[n] = u[b, n, a]
            _column(col, kf[j], fs[j], w_start[j], force, cstuck, clast)
            k = kf[j]
            for n in range(N):
                f[b, n, a] += force[n]
                kt[b, n, a] += k if cstuck[n] else 0.0
                stuck[b, n, j] = cstuck[n]
                last[b, n, j] = clast[n]


def aft_samples(u: np.ndarray, code: np.ndarray, p1: np.ndarray, p2: np.ndarray,
                p3: np.ndarray, fr: np.ndarray, kf: np.ndarray, fs: np.ndarray,
                w_start: np.ndarray):
    """``(f, kt, stuck, last)`` of the samples ``u`` (nb, N, n_ax): every axis's
    elastic remainder (law ``code[a]`` with parameters ``p1..p3[a]``) plus the
    Jenkins force of the friction axes ``fr`` (parameters ``kf``, ``fs``,
    ``w_start`` per friction axis), the tangent ``kt`` plus ``kf`` where stuck, and
    the march's flags of the friction axes (nb, N, len(fr))."""
    nb, N, n_ax = u.shape
    C = fr.shape[0]
    f = np.empty_like(u)
    kt = np.empty_like(u)
    stuck = np.empty((nb, N, C), dtype=np.bool_)
    last = np.empty((nb, N, C), dtype=np.int64)
    _aft_samples(u, code, p1, p2, p3, fr, kf, fs, w_start, f, kt, stuck, last,
                 np.empty(N), np.empty(N, dtype=np.bool_), np.empty(N, dtype=np.int64),
                 np.empty(N))
    return f, kt, stuck, last


@njit(cache=True)
def _slip_memory(dF, stuck, last, fr, kf, cum, E):  # pragma: no cover - jit
    nb, N, C = stuck.shape
    m = E.shape[1]
    for b in range(nb):
        for j in range(C):
            a = fr[j]
            k = kf[j]
            n = 0
            while n < N:
                if not (stuck[b, n, j] and last[b, n, j] >= 0):
                    n += 1
                    continue
                # a run: consecutive samples stuck after the same last slip
                lst = last[b, n, j]
                n0 = n
                n += 1
                while n < N and stuck[b, n, j] and last[b, n, j] == lst:
                    n += 1
                n1 = n - 1
                for h in range(m):
                    p = (cum[n1 + 1, h] - cum[n0, h]) * k
                    for g in range(m):
                        dF[b, a, h, g] -= p * E[lst, g]


def slip_memory(dF: np.ndarray, stuck: np.ndarray, last: np.ndarray, fr: np.ndarray,
                kf: np.ndarray, cum: np.ndarray, E: np.ndarray) -> None:
    """Subtract in place the Jenkins slip memory from ``dF`` (nb, n_ax, m, m), as
    :func:`hbm.aft._subtract_slip_memory` (``stuck``, ``last``: (nb, N, C) of the
    friction axes ``fr``; ``cum``: the cumulative projection (N + 1, m))."""
    _slip_memory(dF, stuck, last, fr, kf, cum, E)
