"""The linear rate-dependent branches of the mount axes in the harmonic balance
(Maxwell branches :mod:`hbm.maxwell`, the hydraulic fluid path :mod:`hbm.hydraulic`):
exact, per harmonic.

A linear branch with complex stiffness ``K*(omega) = a + j b`` turns harmonic ``h`` of
the deflection, ``u_h = Uc cos(h omega t) + Us sin(h omega t)``, into the force

    F_c = a Uc + b Us,    F_s = a Us - b Uc    (a, b at h omega),

and the mean ``U0`` into ``K*(0) U0``. It enters the residual as a term linear in
``X`` with its exact Jacobian and exact ``dR/domega``, not through the AFT time
march; the axes' deflections include the base motion ``u = B q - G y``.
:class:`LinearAxes` holds the rows of the axes that carry one kind of branch and
builds these terms; a subclass gives the branch's parameters per axis
(:meth:`LinearAxes.branch`), ``K*`` and ``dK*/domega``.
"""

from __future__ import annotations

import numpy as np

from drymount.hbm.system import System

__all__ = ["LinearAxes"]


class LinearAxes:
    """The axes of a system that carry one kind of linear branch: their deflection
    rows ``B``, base rows ``G`` and the branches' parameters ``params``, with the
    residual terms of :class:`hbm.residual.HarmonicBalance`. ``static``: the branch
    carries a static force ``K*(0) U0`` (a Maxwell branch does not)."""

    static = False

    def __init__(self, system: System):
        B, G, params = [], [], []
        for e in system.elements:
            for j in e.active_axes:
                q = self.branch(e.params.axes[j])
                if q is not None:
                    B.append(e.B[j])
                    G.append(e.G[j])
                    params.append(q)
        self.n = len(params)
        self.B = np.array(B, dtype=float).reshape(self.n, system.n_dof)
        self.G = np.array(G, dtype=float).reshape(self.n, len(system.base_names))
        self.params = tuple(params)

    @staticmethod
    def branch(axis):
        """The branch's parameters on ``axis`` (AxisParameters), None without one."""
        raise NotImplementedError

    @staticmethod
    def complex_stiffness(q, omega: float) -> complex:
        """``K*`` (N/m) of the branch ``q`` at ``omega`` (rad/s)."""
        raise NotImplementedError

    @staticmethod
    def derivative(q, omega: float) -> complex:
        """``dK*/domega`` (N s/m) of the branch ``q``."""
        raise NotImplementedError

    def stiffness(self, omega: float) -> np.ndarray:
        """K* (N/m) of each axis's branch at ``omega`` (rad/s), shape (n_ax,)."""
        return np.array([self.complex_stiffness(q, omega) for q in self.params],
                        dtype=complex)

    def terms(self, U: np.ndarray, omega: float, H: int, n_dof: int, jacobian: bool):
        """Residual terms from the axes' deflection coefficients ``U`` (2H+1, n_ax):
        ``(R, J, dR/domega)``, R and dR/domega (m n,), J (m n, m n) or None."""
        m = 2 * H + 1
        F = np.zeros((m, self.n))
        dF = np.zeros((m, self.n))
        J = np.zeros((m, n_dof, m, n_dof)) if jacobian else None
        BB = np.einsum("ai,aj->aij", self.B, self.B)
        if self.static:
            k0 = self.stiffness(0.0).real
            F[0] = k0 * U[0]
            if jacobian:
                J[0, :, 0, :] += np.tensordot(k0, BB, axes=(0, 0))
        for h in range(1, H + 1):
            w = h * omega
            K = self.stiffness(w)
            dK = h * np.array([self.derivative(q, w) for q in self.params])
            a, b = K.real, K.imag
            uc, us = U[2 * h - 1], U[2 * h]
            F[2 * h - 1] = a * uc + b * us
            F[2 * h] = a * us - b * uc
            dF[2 * h - 1] = dK.real * uc + dK.imag * us
            dF[2 * h] = dK.real * us - dK.imag * uc
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
