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


from drymount.fmu_src.linear_branches import maxwell_complex_stiffness
from drymount.hbm.linear_axes import LinearAxes
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


class MaxwellAxes(LinearAxes):
    """The axes of a system that carry Maxwell branches (``params``: their ``(k, c)``
    pairs), with the residual terms of :class:`hbm.residual.HarmonicBalance`
    (:class:`hbm.linear_axes.LinearAxes`; no static force)."""

    @staticmethod
    def branch(axis):
        return tuple(axis.maxwell) if axis.has_maxwell else None

    @staticmethod
    def complex_stiffness(q, omega: float) -> complex:
        return maxwell_complex_stiffness([k for k, _ in q], [c for _, c in q], omega)

    derivative = staticmethod(maxwell_derivative)

    @property
    def pairs(self) -> tuple:
        """The ``(k, c)`` pairs of each axis (``params``)."""
        return self.params


def maxwell_axes(system: System) -> MaxwellAxes | None:
    """The :class:`MaxwellAxes` of ``system``, None if no active axis has a
    branch."""
    ax = MaxwellAxes(system)
    return ax if ax.n else None
