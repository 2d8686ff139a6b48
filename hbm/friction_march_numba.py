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

__all__ = ["march", "jacobian_samples", "march_and_samples", "warm"]


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
