"""Stability of periodic solutions by Hill's method on the harmonic-balance Jacobian.

A perturbation ``q = q* + p(t) exp(lambda t)`` with ``p`` periodic (H harmonics) of the
equations of motion linearised about the periodic solution ``q*`` gives the quadratic
eigenvalue problem (the nonlinear remainders are rate independent, so only ``M`` and the
linear damping ``C0`` carry velocity terms)

    (J(X, omega) + lambda Delta1 + lambda^2 Delta2) P = 0,
    Delta1 = I kron C0 + 2 omega (D kron M),   Delta2 = I kron M,

with ``J = dR/dX``. Of its 2 n (2H+1) eigenvalues the 2 n with the smallest imaginary
parts approximate the Floquet exponents; the solution is unstable when one has a
positive real part. For the Jenkins element ``J`` linearises the periodic map (the
slider position depends on the last slip sample); this is the usual approximation of
HB codes (NLvib), exact at smooth folds where ``det J`` changes sign.

References: von Groll and Ewins (2001); Detroux et al. (2015); Krack and Gross,
*Harmonic Balance for Nonlinear Vibration Problems* (2019), Sec. 5.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from hbm.residual import HarmonicBalance

__all__ = ["floquet_exponents", "is_stable"]


def floquet_exponents(hb: HarmonicBalance, J: np.ndarray, omega: float) -> np.ndarray:
    """Approximate Floquet exponents (2 n,) in 1/s from Hill's matrix.

    Parameters
    ----------
    hb : HarmonicBalance
    J : ndarray, shape (m n, m n)
        ``dR/dX`` at the solution.
    omega : float
        rad/s.
    """
    n, m = hb.n, hb.m
    Minv = np.linalg.inv(hb.M)
    I_m = np.eye(m)
    D = hb.basis.D
    Minv_k = np.kron(I_m, Minv)
    Delta1 = np.kron(I_m, hb.C0) + 2.0 * omega * np.kron(D, hb.M)
    size = m * n
    A = np.zeros((2 * size, 2 * size))
    A[:size, size:] = np.eye(size)
    A[size:, :size] = -Minv_k @ J
    A[size:, size:] = -Minv_k @ Delta1
    lam = scipy.linalg.eigvals(A, check_finite=False, overwrite_a=True)
    order = np.argsort(np.abs(lam.imag), kind="stable")
    return lam[order[: 2 * n]]


class Stability(NamedTuple):
    """Hill stability of one solution: the verdict and the largest real part of the
    Floquet exponents (1/s)."""

    stable: bool
    max_real: float


def is_stable(hb: HarmonicBalance, J: np.ndarray, omega: float,
              rtol: float = 1e-7) -> Stability:
    """Unstable if a Floquet exponent has a real part above ``rtol * omega``."""
    lam = floquet_exponents(hb, J, omega)
    mr = float(np.max(lam.real))
    return Stability(mr <= rtol * omega, mr)
