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


from drymount.fmu_src.linear_branches import hydraulic_complex_stiffness
from drymount.hbm.linear_axes import LinearAxes
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


class HydraulicAxes(LinearAxes):
    """The axes of a system that carry the hydraulic fluid path (``params``: their
    HydraulicParameters), with the residual terms of
    :class:`hbm.residual.HarmonicBalance` (:class:`hbm.linear_axes.LinearAxes`)."""

    static = True

    @staticmethod
    def branch(axis):
        return axis.hydraulic if axis.has_hydraulic else None

    complex_stiffness = staticmethod(fluid_stiffness)
    derivative = staticmethod(_derivative)


def hydraulic_axes(system: System) -> HydraulicAxes | None:
    """The :class:`HydraulicAxes` of ``system``, None if no active axis has the
    fluid path."""
    ax = HydraulicAxes(system)
    return ax if ax.n else None
