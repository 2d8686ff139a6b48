"""The eigenvalues of Hill's matrix nearest the origin, by shift-invert Arnoldi on the
LU factors of the harmonic-balance Jacobian ``J`` (no dense eigenvalue problem).

Hill's matrix (:func:`hbm.stability.hill_eigenvalues`) is the companion form

    A = [[0, I], [-Delta2^-1 J, -Delta2^-1 Delta1]],

so ``A [x; y] = [u; v]`` is solved by ``y = u``, ``J x = -(Delta2 v + Delta1 u)``: one
pair of triangular solves with the LU of ``J`` (size n (2H+1), half of A's). ARPACK
(``scipy.sparse.linalg.eigs``) finds the k eigenvalues of ``A^-1`` of largest modulus,
i.e. the k eigenvalues of A of smallest modulus; the Floquet exponents (the 2 n
eigenvalues of smallest imaginary part, which decide stability) are among them
unless an eigenvalue far from the imaginary axis has a small imaginary part.

:func:`central_eigenvalues` returns the k eigenvalues only when that is excluded in
the following sense, else None (the caller then solves the dense problem): every
eigenvalue not found has modulus >= R (the largest modulus found), so one that would
rank among the 2 n of smallest imaginary part (below c, the 2 n-th smallest found)
has a real part of modulus >= rho = sqrt(R^2 - c^2); the result is accepted when rho
is at least ``RHO_FACTOR`` times the largest real part (in modulus) of the 2 n
selected eigenvalues found and at least ``RHO_MIN * omega``. k starts at 2 n + 10 and
is raised once. This is an assumption on the spectrum (no isolated exponent that far
from the others), checked against the dense problem at every point of the 6-DOF
presets (docs/performance.md, tests/test_hbm_stability_fast.py).
"""

from __future__ import annotations

import weakref
from typing import NamedTuple

import numpy as np
import scipy.sparse.linalg as sla
from scipy.linalg import lapack
from scipy.sparse.linalg import ArpackError, ArpackNoConvergence

from drymount.hbm.residual import HarmonicBalance

__all__ = ["central_eigenvalues", "hill_parts", "lu_factors", "HillParts", "MIN_SIZE",
           "TOL", "TOL_TIGHT"]

#: Below this size of Hill's matrix the dense eigenvalue problem is cheaper.
MIN_SIZE = 120
#: Eigenvalues found beyond the 2 n selected, first and second try.
EXTRA = (10, 24)
#: Acceptance: rho >= RHO_FACTOR * max |Re| of the selected found, and >= RHO_MIN omega.
RHO_FACTOR = 2.0
RHO_MIN = 0.25
#: ARPACK's tolerance (Ritz residual relative to the Ritz value) of a first solve:
#: the eigenvalues come out far more accurate (measured 4e-15 of omega in the largest
#: real part on six_dof_halved, as at TOL_TIGHT) at 0.8x the cost;
#: :func:`hbm.stability.hill_verdict` solves again at TOL_TIGHT where the verdict's
#: margin is within ``GUARD * TOL`` of the eigenvalues' modulus.
TOL = 1e-6
TOL_TIGHT = 1e-10


def lu_factors(J: np.ndarray):
    """LAPACK's ``getrf`` of J: ``(lu, piv)`` with 0-based pivots, or None when J is
    not finite or exactly singular."""
    lu, piv, info = lapack.dgetrf(J)
    if info != 0 or not np.all(np.isfinite(lu)):
        return None
    return lu, piv


class HillParts(NamedTuple):
    """The harmonic forms of Hill's damping and mass terms: ``Delta1(omega) = C +
    2 omega DM``, ``Delta2 = M`` (each m n x m n)."""

    C: np.ndarray
    DM: np.ndarray
    M: np.ndarray


_PARTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def hill_parts(hb: HarmonicBalance) -> HillParts:
    """:class:`HillParts` of ``hb``, built once per HarmonicBalance (whose matrices
    are fixed at construction)."""
    parts = _PARTS.get(hb)
    if parts is None:
        I_m = np.eye(hb.m)
        parts = HillParts(np.kron(I_m, hb.C0), np.kron(hb.basis.D, hb.M),
                          np.kron(I_m, hb.M))
        _PARTS[hb] = parts
    return parts


class _InverseHill(sla.LinearOperator):
    """``A^-1`` through the LU of J (:func:`lu_factors`); ``matvec`` is overridden
    itself, so ARPACK calls it without LinearOperator's per-call checks."""

    def __init__(self, hb: HarmonicBalance, lu, omega: float):
        parts = hill_parts(hb)
        self.size = hb.m * hb.n
        super().__init__(float, (2 * self.size, 2 * self.size))
        self.lu = lu
        # [u; v] -> Delta1 u + Delta2 v
        self.B = np.hstack([parts.C + 2.0 * omega * parts.DM, parts.M])

    def matvec(self, v):
        v = np.ravel(v)
        x = lapack.dgetrs(self.lu[0], self.lu[1], self.B @ v)[0]  # no lu_solve checks
        return np.concatenate([-x, v[:self.size]])

    _matvec = matvec


def _accepted(lam: np.ndarray, n: int, omega: float) -> bool:
    """Whether the 2 n eigenvalues of smallest imaginary part among ``lam`` are those
    of the whole spectrum (module docstring)."""
    if not np.all(np.isfinite(lam)) or len(lam) <= 2 * n:
        return False
    mag = np.abs(lam.imag)
    order = np.argsort(mag, kind="stable")
    c = mag[order[2 * n - 1]]
    if mag[order[2 * n]] == c and lam[order[2 * n]] != np.conj(lam[order[2 * n - 1]]):
        return False  # a tie at the cut that is not a conjugate pair
    R = float(np.max(np.abs(lam)))
    rho = np.sqrt(max(R * R - c * c, 0.0))
    spread = float(np.max(np.abs(lam[order[:2 * n]].real)))
    return bool(rho >= RHO_FACTOR * spread and rho >= RHO_MIN * omega)


def central_eigenvalues(hb: HarmonicBalance, J: np.ndarray, omega: float,
                        lu=None, tol: float = TOL) -> np.ndarray | None:
    """Hill's eigenvalues of smallest modulus (1/s), among them the 2 n Floquet
    exponents, or None when the dense problem must decide (small matrix, singular
    ``J``, ARPACK failed, or the acceptance test of the module docstring failed).

    Parameters
    ----------
    hb : HarmonicBalance
    J : ndarray, shape (m n, m n)
        ``dR/dX`` at the solution.
    omega : float
        rad/s.
    lu : tuple, optional
        :func:`lu_factors` of J if already computed.
    tol : float
        ARPACK's tolerance (:data:`TOL`, :data:`TOL_TIGHT`).
    """
    size = 2 * hb.m * hb.n
    if size < MIN_SIZE:
        return None
    if lu is None:
        lu = lu_factors(J)
    if lu is None:
        return None
    op = _InverseHill(hb, lu, omega)
    v0 = np.cos(0.7 * np.arange(1, size + 1))  # fixed: reproducible results
    for extra in EXTRA:
        k = min(2 * hb.n + extra, size - 2)
        try:
            mu = sla.eigs(op, k=k, which="LM", return_eigenvectors=False, tol=tol,
                          v0=v0)
        except (ArpackNoConvergence, ArpackError):
            return None
        if np.any(mu == 0):
            return None
        lam = 1.0 / mu
        if _accepted(lam, hb.n, omega):
            return lam
    return None
