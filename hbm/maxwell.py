"""The Maxwell branches of the mount axes in the harmonic balance: exact, per harmonic.

A Maxwell branch (spring ``k`` in series with a damper ``c``, in parallel with the
elastic law; :mod:`fmu_src.linear_branches`) is linear, so its periodic force is
known in closed form: harmonic ``h`` of the deflection, ``u_h = Uc cos(h omega t) +
Us sin(h omega t)``, gives the force ``Re K*(h omega) (Uc - j Us) exp(j h omega t)``
with ``K* = a + j b`` the branches' complex stiffness:

    F_c = a Uc + b Us,    F_s = a Us - b Uc,     and no static force.

It enters the residual like the mounts' ``k1`` and ``c`` (a term linear in ``X`` with
its exact Jacobian and ``dR/domega`` from ``dK*/domega = sum k^2 j c / (k + j omega
c)^2``), not through the AFT time march; the axes' deflections include the base
motion ``u = B q - G y`` as the nonlinear axes' do.
"""

from __future__ import annotations

import numpy as np

from drymount.fmu_src.linear_branches import maxwell_complex_stiffness
from drymount.hbm.system import System

__all__ = ["MaxwellAxes", "maxwell_axes", "maxwell_derivative"]


def maxwell_derivative(pairs, omega: float) -> complex:
    """``dK*/domega`` (N s/m) of the Maxwell branches ``pairs`` ((k, c), ...)."""
    out = 0j
    for k, c in pairs:
        if k > 0.0 and c > 0.0:
            d = k + 1j * omega * c
            out += k * k * 1j * c / (d * d)
    return out


class MaxwellAxes:
    """The axes of a system that carry Maxwell branches: their deflection rows and
    their branches, with the residual terms of :class:`hbm.residual.HarmonicBalance`.
    """

    def __init__(self, system: System):
        B, G, pairs = [], [], []
        for e in system.elements:
            for j in e.active_axes:
                p = e.params.axes[j]
                if p.has_maxwell:
                    B.append(e.B[j])
                    G.append(e.G[j])
                    pairs.append(tuple(p.maxwell))
        n = system.n_dof
        self.n = len(pairs)
        self.B = np.array(B, dtype=float).reshape(self.n, n)
        nb = len(system.base_names)
        self.G = np.array(G, dtype=float).reshape(self.n, nb)
        self.pairs = tuple(pairs)

    def stiffness(self, omega: float) -> np.ndarray:
        """K* (N/m) of each axis's branches at ``omega`` (rad/s), shape (n_ax,)."""
        return np.array([maxwell_complex_stiffness([k for k, _ in q],
                                                   [c for _, c in q], omega)
                         for q in self.pairs], dtype=complex)

    def terms(self, U: np.ndarray, omega: float, H: int, n_dof: int,
              jacobian: bool):
        """Residual terms from the axes' deflection coefficients ``U`` (2H+1, n_ax):
        ``(R, J, dR/domega)``, R and dR/domega (m n,), J (m n, m n) or None."""
        m = 2 * H + 1
        F = np.zeros((m, self.n))
        dF = np.zeros((m, self.n))
        J = np.zeros((m, n_dof, m, n_dof)) if jacobian else None
        BB = np.einsum("ai,aj->aij", self.B, self.B)
        for h in range(1, H + 1):
            w = h * omega
            K = self.stiffness(w)
            dK = h * np.array([maxwell_derivative(q, w) for q in self.pairs])
            a, b = K.real, K.imag
            da, db = dK.real, dK.imag
            uc, us = U[2 * h - 1], U[2 * h]
            F[2 * h - 1] = a * uc + b * us
            F[2 * h] = a * us - b * uc
            dF[2 * h - 1] = da * uc + db * us
            dF[2 * h] = da * us - db * uc
            if jacobian:
                ic, is_ = 2 * h - 1, 2 * h
                J[ic, :, ic, :] += np.tensordot(a, BB, axes=(0, 0))
                J[ic, :, is_, :] += np.tensordot(b, BB, axes=(0, 0))
                J[is_, :, is_, :] += np.tensordot(a, BB, axes=(0, 0))
                J[is_, :, ic, :] -= np.tensordot(b, BB, axes=(0, 0))
        R = (F @ self.B).ravel()
        dR = (dF @ self.B).ravel()
        if jacobian:
            J = J.reshape(m * n_dof, m * n_dof)
        return R, J, dR


def maxwell_axes(system: System) -> MaxwellAxes | None:
    """The :class:`MaxwellAxes` of ``system``, None if no active axis has a
    branch."""
    ax = MaxwellAxes(system)
    return ax if ax.n else None
