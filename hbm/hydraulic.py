"""The hydraulic fluid path of the mount axes in the harmonic balance: exact, per
harmonic.

The fluid path (:mod:`fmu_src.linear_branches`: the piston ``Ap`` on two chambers
joined by the inertia track and the decoupler) is linear, so its periodic force is
known in closed form: harmonic ``h`` of the deflection, ``u_h = Uc cos(h omega t) +
Us sin(h omega t)``, gives ``F_c = a Uc + b Us``, ``F_s = a Us - b Uc`` with ``K* = a
+ j b`` the fluid's complex stiffness at ``h omega`` (the rubber ``kr, br`` are the
axis's own elastic law and damper: :func:`linear_branches.hydraulic_complex_stiffness`
with ``kr = br = 0``). Unlike a Maxwell branch the fluid carries a static force: the
mean ``U0`` gives ``K*(0) U0 = Ap^2 U0 / (C1 + C2)`` (both chambers at rest at the
same pressure). It enters the residual as a term linear in ``X`` with its exact
Jacobian and exact ``dR/domega``, not through the AFT time march; the axes' deflections
include the base motion ``u = B q - G y``.
"""

from __future__ import annotations

import numpy as np

from drymount.fmu_src.linear_branches import hydraulic_complex_stiffness
from drymount.hbm.system import System

__all__ = ["HydraulicAxes", "hydraulic_axes", "fluid_stiffness"]



def fluid_stiffness(h, omega: float) -> complex:
    """K* (N/m) of the fluid path ``h`` (HydraulicParameters, kr = br = 0)."""
    return hydraulic_complex_stiffness(h, float(omega))


def _derivative(h, omega: float) -> complex:
    """``dK*/domega`` (N s/m) of the fluid path ``h``, exact: with ``Z`` the passages'
    parallel impedance, ``N = 1 + j w C2 Z``, ``D = C1 + C2 + j w C1 C2 Z``, ``K* =
    Ap^2 N / D`` and ``d(w Z)/dw = Z + w dZ/dw``."""
    zi, dzi = complex(h.R_i, omega * h.I_i), 1j * h.I_i
    if h.I_d == 0.0:
        z, dz = zi, dzi
    else:
        zd, dzd = complex(h.R_d, omega * h.I_d), 1j * h.I_d
        s = zi + zd
        z = zi * zd / s
        dz = (dzi * zd + zi * dzd) / s - zi * zd * (dzi + dzd) / (s * s)
    jw = 1j * omega
    n = 1.0 + jw * h.C2 * z
    d = h.C1 + h.C2 + jw * h.C1 * h.C2 * z
    dwz = 1j * (z + omega * dz)
    dn, dd = h.C2 * dwz, h.C1 * h.C2 * dwz
    return h.Ap * h.Ap * (dn * d - n * dd) / (d * d)


class HydraulicAxes:
    """The axes of a system that carry the hydraulic fluid path: their deflection
    rows and fluid parameters, with the residual terms of
    :class:`hbm.residual.HarmonicBalance`."""

    def __init__(self, system: System):
        B, G, hyd = [], [], []
        for e in system.elements:
            for j in e.active_axes:
                p = e.params.axes[j]
                if p.has_hydraulic:
                    B.append(e.B[j])
                    G.append(e.G[j])
                    hyd.append(p.hydraulic)
        n = system.n_dof
        self.n = len(hyd)
        self.B = np.array(B, dtype=float).reshape(self.n, n)
        self.G = np.array(G, dtype=float).reshape(self.n, len(system.base_names))
        self.params = tuple(hyd)

    def stiffness(self, omega: float) -> np.ndarray:
        """K* (N/m) of each axis's fluid at ``omega`` (rad/s), shape (n_ax,)."""
        return np.array([fluid_stiffness(h, omega) for h in self.params], dtype=complex)

    def terms(self, U: np.ndarray, omega: float, H: int, n_dof: int, jacobian: bool):
        """Residual terms from the axes' deflection coefficients ``U`` (2H+1, n_ax):
        ``(R, J, dR/domega)``, R and dR/domega (m n,), J (m n, m n) or None."""
        m = 2 * H + 1
        F = np.zeros((m, self.n))
        dF = np.zeros((m, self.n))
        J = np.zeros((m, n_dof, m, n_dof)) if jacobian else None
        BB = np.einsum("ai,aj->aij", self.B, self.B)
        k0 = self.stiffness(0.0).real
        F[0] = k0 * U[0]
        if jacobian:
            J[0, :, 0, :] += np.tensordot(k0, BB, axes=(0, 0))
        for h in range(1, H + 1):
            w = h * omega
            K = self.stiffness(w)
            dK = h * np.array([_derivative(q, w) for q in self.params])
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


def hydraulic_axes(system: System) -> HydraulicAxes | None:
    """The :class:`HydraulicAxes` of ``system``, None if no active axis has the
    fluid path."""
    ax = HydraulicAxes(system)
    return ax if ax.n else None
