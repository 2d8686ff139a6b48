"""Harmonic-balance residual ``R(X, omega)`` and its Jacobian (thesis eq. 3.51, 3.54).

Unknowns: the Fourier coefficients of the DOFs ``q`` with the static term and H
harmonics, harmonic-major: ``X.reshape(2H+1, n)`` has rows ``[Q0, Qc1, Qs1, ...,
QcH, QsH]`` with ``q(t) = Q0 + sum_k Qck cos(k omega t) + Qsk sin(k omega t)`` (the sine
convention of the excitation in :mod:`hbm.system`).

    R(X, omega) = (K0 + omega C0 (D kron) + omega^2 M (D^2 kron)) X
                  + [B^T F_nl(B q - G y)]_harmonics - f_exc(omega)

``K0``, ``C0`` hold the structure plus the mounts' linear parts (``k1``, ``c``) from
:meth:`hbm.system.System.linearized`; the base motion ``y = Y sin(omega t)`` enters
through ``Kb0 Y`` (sine row) and ``omega Cb0 Y`` (cosine row) and through
``u = B q - G y`` in the nonlinear remainders, which are evaluated by closed forms
(H = 1, :mod:`hbm.closed_form`) or AFT (:mod:`hbm.aft`); the mount forces enter as
``B^T F``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from drymount.fmu_src.linear_branches import maxwell_complex_stiffness
from drymount.hbm.aft import FourierBasis, aft_forces, default_n_samples
from drymount.hbm.closed_form import closed_form_forces
from drymount.hbm.elements import nonlinear_axes
from drymount.hbm.hydraulic import fluid_stiffness, hydraulic_axes
from drymount.hbm.maxwell import maxwell_axes
from drymount.hbm.static import working_point
from drymount.hbm.system import System

__all__ = ["HarmonicBalance"]


#: Unknowns (m n) from which the linear matrices are summed on their pattern only
#: (:meth:`HarmonicBalance._linear_pattern`): at 162 (six_dof_halved, H = 13) 18
#: instead of 52 us; below about 60 the dense sums are as fast.
PATTERN_FROM = 64


def _pattern_sums(omega: float) -> bool:
    """Whether the linear matrices may be summed on their pattern only: the zeros
    elsewhere stay +0 for ``omega >= +0`` whose square is finite (NaN and inf times
    zero are NaN everywhere; a negative omega turns ``-0`` terms into ``-0`` sums)."""
    return math.copysign(1.0, omega) > 0.0 and math.isfinite(omega * omega)


class Residual(NamedTuple):
    """Harmonic-balance residual at ``(X, omega)`` and its derivatives."""

    R: np.ndarray
    dR_dX: np.ndarray | None
    dR_domega: np.ndarray | None


def _closed_form_choice(closed_form: bool | None, H: int, ax, static: bool) -> bool:
    """Whether the H = 1 closed forms replace AFT: by default where they apply (H = 1,
    laws with closed forms, sliders at 0, no static load: the zero slider offset and
    zero mean deflection they assume); asked for where they do not apply, an error
    that says why."""
    offsets = bool(np.any(ax.w_start != 0.0))
    if closed_form is None:
        return H == 1 and ax.has_closed_form and not offsets and not static
    if closed_form:
        if static:
            raise ValueError("`closed_form` assumes no static load (zero mean "
                             "deflection); use closed_form=False (AFT)")
        if H != 1:
            raise ValueError(f"`closed_form` needs harmonics == 1, got {H}")
        if not ax.has_closed_form:
            raise ValueError("`closed_form`: the `piecewise_asym` law has no "
                             "closed form; use closed_form=False (AFT)")
        if offsets:
            raise ValueError("`closed_form` assumes sliders starting at 0; with "
                             "`sliders` use closed_form=False (AFT)")
    return bool(closed_form)


class HarmonicBalance:
    """Residual of the harmonic-balance equations of a :class:`hbm.system.System`.

    Parameters
    ----------
    system : System
    harmonics : int
        Number of harmonics H >= 1.
    n_samples : int or None
        AFT time samples per period (None: :func:`hbm.aft.default_n_samples`).
    closed_form : bool or None
        Use the H = 1 closed forms. None: when H == 1 and every law has one.

    Raises
    ------
    ValueError
        ``closed_form=True`` with H != 1 or a law without closed form; bad H or N.
    """

    def __init__(self, system: System, harmonics: int = 7, n_samples: int | None = None,
                 closed_form: bool | None = None, sliders=None):
        if not isinstance(system, System):
            raise TypeError(f"`system` must be a hbm.system.System, got "
                            f"{type(system).__name__}")
        if isinstance(harmonics, bool) or not isinstance(harmonics, (int, np.integer)) \
                or harmonics < 1:
            raise ValueError(f"`harmonics` must be an integer >= 1, got {harmonics!r}")
        H = int(harmonics)
        #: the static working point the system vibrates about (None: unloaded)
        self.static = working_point(system)
        states = None
        if self.static is not None and sliders is None:
            # the working point's elements: lowered onto the mount by default
            # (their states), or relaxed there (system.static_reading)
            sliders, states = self.static.sliders, self.static.states
        ax = nonlinear_axes(system, sliders, states)
        closed_form = _closed_form_choice(closed_form, H, ax, self.static is not None)
        if n_samples is None:
            n_samples = default_n_samples(H)
        if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)) \
                or n_samples <= 2 * H:
            raise ValueError(f"`n_samples` must be an integer > 2 * harmonics = "
                             f"{2 * H}, got {n_samples!r}")
        self.system = system
        self.H = H
        self.m = 2 * H + 1
        self.n = system.n_dof
        self.size = self.m * self.n
        self.closed_form = bool(closed_form)
        self.n_samples = int(n_samples)
        self.axes = ax
        #: the axes with Maxwell branches (None: none), exact per harmonic
        self.maxwell = maxwell_axes(system)
        #: the axes with the hydraulic fluid path (None: none), exact per harmonic
        self.hydraulic = hydraulic_axes(system)
        self.basis = FourierBasis(H, self.n_samples)
        K0, C0 = system.linearized(stuck=False)
        Kb0, Cb0 = system.linearized_base(stuck=False)
        self.K0, self.C0, self.M = K0, C0, system.M
        D = self.basis.D
        I_m = np.eye(self.m)
        self.A0 = np.kron(I_m, K0)
        self.A1 = np.kron(D, C0)
        self.A2 = np.kron(D @ D, system.M)
        self._linear_pattern()
        self._set_excitation(Kb0, Cb0)
        self.Bt = ax.B  # (n_ax, n)
        self.BB = np.einsum("ai,aj->aij", ax.B, ax.B)  # (n_ax, n, n)
        #: factor on the dynamic excitation (load stepping to a first solution; the
        #: static load stays); 1 normally
        self.exc_scale = 1.0
        self._trig = {}

    def _linear_pattern(self) -> None:
        """The entries where ``A0``, ``A1`` or ``A2`` is not +0 (Kronecker products
        with the identity, the derivative and its square: 3.2 % of six_dof_halved's at
        H = 13, 7.7 % at H = 5), and their values there: :meth:`linear_matrix` and
        ``dR/domega`` are summed on them only. Every other entry is +0 either way
        (``0 + omega 0 + omega^2 0``), so the matrices are the dense sums bit for bit
        (:func:`_pattern_sums` says when: not for a negative, NaN or huge omega)."""
        self._nz = None
        if self.size < PATTERN_FROM:  # the dense sums are as cheap
            return
        A0, A1, A2 = self.A0, self.A1, self.A2
        # a sum of zeros is -0 only where its terms are all -0 (both sums need A2's)
        keep = (A0 != 0.0) | (A1 != 0.0) | (A2 != 0.0)
        keep |= np.signbit(A2) & (np.signbit(A0) | np.signbit(A1))
        self._nz = np.flatnonzero(keep)
        self._A0nz, self._A1nz, self._A2nz = (a.ravel()[self._nz] for a in (A0, A1, A2))

    def _on_pattern(self, values: np.ndarray) -> np.ndarray:
        """A (m n, m n) matrix with ``values`` at :meth:`_linear_pattern`'s entries
        and +0 elsewhere."""
        out = np.zeros(self.A0.shape)
        out.ravel()[self._nz] = values
        return out

    def _set_excitation(self, Kb0: np.ndarray, Cb0: np.ndarray) -> None:
        """Coefficient vectors of ``f_exc(omega) = e0 + omega e1 + omega^2 e2``, the
        static load ``e_static`` and the base part ``Yax`` of the axis deflections
        (``Kb0``, ``Cb0``: the base's linearised stiffness and damping)."""
        e0, e1, e2, es = (np.zeros((self.m, self.n)) for _ in range(4))
        exc = self.system.excitation
        self.Yax = np.zeros((self.m, self.axes.n))
        if self.static is not None:
            es[0] = self.system.static_load  # the static row carries the load
        if exc.kind == "force":
            e0[2] = exc.amplitude
        elif exc.kind == "unbalance":
            e2[2] = exc.amplitude
        else:
            Y = np.asarray(exc.amplitude)
            e0[2] = Kb0 @ Y
            e1[1] = Cb0 @ Y
            self.Yax[2] = -(self.axes.G @ Y)
        self.Ymx = None
        if getattr(self, "maxwell", None) is not None:
            self.Ymx = np.zeros((self.m, self.maxwell.n))
            if exc.kind not in ("force", "unbalance"):
                self.Ymx[2] = -(self.maxwell.G @ np.asarray(exc.amplitude))
        self.Yhy = None
        if getattr(self, "hydraulic", None) is not None:
            self.Yhy = np.zeros((self.m, self.hydraulic.n))
            if exc.kind not in ("force", "unbalance"):
                self.Yhy[2] = -(self.hydraulic.G @ np.asarray(exc.amplitude))
        self.e0, self.e1, self.e2 = e0.ravel(), e1.ravel(), e2.ravel()
        #: the static load (not scaled by ``exc_scale``: load stepping raises the
        #: vibration about the loaded working point)
        self.e_static = es.ravel()

    # ----------------------------------------------------------------------------------
    def excitation(self, omega: float) -> np.ndarray:
        """Excitation coefficient vector ``f_exc(omega)``, shape (m n,)."""
        f = self.e0 + omega * self.e1 + omega * omega * self.e2
        return self.e_static + (f if self.exc_scale == 1.0 else self.exc_scale * f)

    def linear_matrix(self, omega: float) -> np.ndarray:
        """``dR/dX`` of the linear part, shape (m n, m n)."""
        if self._nz is None or not _pattern_sums(omega):
            return self.A0 + omega * self.A1 + (omega * omega) * self.A2
        return self._on_pattern(self._A0nz + omega * self._A1nz
                                + (omega * omega) * self._A2nz)

    def _omega_matrix(self, omega: float) -> np.ndarray:
        """``d(linear matrix)/domega = A1 + 2 omega A2``, as :meth:`linear_matrix`."""
        if self._nz is None or not _pattern_sums(omega):
            return self.A1 + (2.0 * omega) * self.A2
        return self._on_pattern(self._A1nz + (2.0 * omega) * self._A2nz)

    def axis_coefficients(self, X: np.ndarray) -> np.ndarray:
        """Deflection coefficients of the nonlinear axes, shape (2H+1, n_ax)."""
        return X.reshape(self.m, self.n) @ self.Bt.T + self.exc_scale * self.Yax

    def nonlinear_forces(self, X: np.ndarray, jacobian: bool = True,
                         omega: float | None = None):
        """Force coefficients ``(2H+1, n_ax)`` of the nonlinear remainders, dF/dU
        (``omega``, rad/s: for rate-dependent friction elements)."""
        U = self.axis_coefficients(X)
        if self.closed_form:
            F, dF = closed_form_forces(U, self.axes)
            return F, (dF if jacobian else None)
        return aft_forces(U, self.axes, self.basis, jacobian, omega)

    def residual(self, X: np.ndarray, omega: float, jacobian: bool = True):
        """Residual and derivatives at ``(X, omega)``.

        Parameters
        ----------
        X : ndarray, shape (m n,)
            Coefficients (m, rad for rotations).
        omega : float
            Excitation angular frequency, rad/s.

        Returns
        -------
        Residual
            ``R`` (m n,): residual, N (N m for rotational DOFs); ``dR_dX``
            (m n, m n) or None; ``dR_domega`` (m n,) or None.
        """
        A = self.linear_matrix(omega)
        R = A @ X - self.excitation(omega)
        if self.axes.n:
            F, dF = self.nonlinear_forces(X, jacobian, omega)
            R += (F @ self.Bt).ravel()
        mx = None
        if self.maxwell is not None:
            Um = (X.reshape(self.m, self.n) @ self.maxwell.B.T
                  + self.exc_scale * self.Ymx)
            mx = self.maxwell.terms(Um, omega, self.H, self.n, jacobian)
            R += mx[0]
        if self.hydraulic is not None:
            Uh = (X.reshape(self.m, self.n) @ self.hydraulic.B.T
                  + self.exc_scale * self.Yhy)
            hy = self.hydraulic.terms(Uh, omega, self.H, self.n, jacobian)
            R += hy[0]
            mx = hy if mx is None else (mx[0] + hy[0], None if mx[1] is None else
                                        mx[1] + hy[1], mx[2] + hy[2])
        if not jacobian:
            return Residual(R, None, None)
        J = A if mx is None else A + mx[1]
        if self.axes.n:
            if self.n == 1:
                J = J + (self.BB[:, 0, 0] @ dF.reshape(self.axes.n, -1)).reshape(
                    self.m, self.m)
            else:
                # J[h i, g j] += sum_a dF[a, h, g] B[a, i] B[a, j]: the product
                # np.tensordot(dF, BB, axes=(0, 0)) makes (its transposed copy of dF
                # times BB as one matrix), without its Python, added in place (J is
                # A, built by this call) through a view: the same numbers
                na, m, n = self.axes.n, self.m, self.n
                dFt = np.ascontiguousarray(dF.transpose(1, 2, 0)).reshape(m * m, na)
                prod = np.dot(dFt, self.BB.reshape(na, n * n)).reshape(m, m, n, n)
                if J is A:
                    J.reshape(m, n, m, n)[...] += prod.transpose(0, 2, 1, 3)
                else:
                    J = J + prod.transpose(0, 2, 1, 3).reshape(self.size, self.size)
        dR_dw = (self._omega_matrix(omega) @ X
                 - self.exc_scale * (self.e1 + 2.0 * omega * self.e2))
        if mx is not None:
            dR_dw = dR_dw + mx[2]
        return Residual(R, J, dR_dw)

    # ----------------------------------------------------------------------------------
    def time_samples(self, X: np.ndarray, n_samples: int = 256) -> np.ndarray:
        """``q`` at ``n_samples`` equidistant phases of one period, shape (N, n)."""
        if n_samples not in self._trig:
            theta = 2.0 * np.pi * np.arange(n_samples) / n_samples
            k = np.arange(1, self.H + 1)
            self._trig[n_samples] = (np.cos(np.outer(theta, k)),
                                     np.sin(np.outer(theta, k)))
        c, s = self._trig[n_samples]
        Xr = X.reshape(self.m, self.n)
        return Xr[0] + c @ Xr[1::2] + s @ Xr[2::2]

    def peak_abs(self, X: np.ndarray, n_samples: int = 256) -> np.ndarray:
        """``max |q(t)|`` over the period for each DOF.

        ``X`` has shape (m n,) or (P, m n) (P solutions at once); returns (n,) or
        (P, n). Sampled at ``n_samples`` phases, then refined by Newton on
        ``dq/dtheta = 0`` around the largest sample (exact to round-off for a smooth
        extremum).
        """
        single = X.ndim == 1
        Xr = X.reshape(-1, self.m, self.n)
        self.time_samples(Xr[0].ravel(), n_samples)  # fills the cache
        c, s = self._trig[n_samples]
        a, b = Xr[:, 1::2, :], Xr[:, 2::2, :]  # (P, H, n)
        q = Xr[:, :1, :] + c @ a + s @ b  # (P, N, n)
        aq = np.abs(q)
        idx = np.argmax(aq, axis=1)  # (P, n)
        best = np.take_along_axis(aq, idx[:, None, :], axis=1)[:, 0, :]
        h = 2.0 * np.pi / n_samples
        th0 = h * idx
        th = th0.copy()
        k = np.arange(1, self.H + 1)[None, :, None]
        for _ in range(4):
            kt = k * th[:, None, :]
            cs, sn = np.cos(kt), np.sin(kt)
            d1 = np.sum(k * (b * cs - a * sn), axis=1)
            d2 = -np.sum(k * k * (a * cs + b * sn), axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(d2 != 0.0, -d1 / d2, 0.0)
            th = th0 + np.clip(th - th0 + step, -h, h)
        kt = k * th[:, None, :]
        val = np.abs(Xr[:, 0, :] + np.sum(a * np.cos(kt) + b * np.sin(kt), axis=1))
        out = np.maximum(best, val)
        return out[0] if single else out

    def axis_force_fundamental(self, X: np.ndarray, omega: float,
                               pairs) -> np.ndarray:
        """Fundamental ``(cos1, sin1)`` of the total force of the (element, axis) pairs.

        Total force = ``k1 u + c du/dt + nonlinear remainder``, summed over ``pairs``.
        """
        sysm = self.system
        Xr = X.reshape(self.m, self.n)
        exc = sysm.excitation
        Y = np.asarray(exc.amplitude) if exc.kind == "base" else None
        Fnl = None
        total = np.zeros(2)
        for ie, j in pairs:
            e = sysm.elements[ie]
            p = e.params.axes[j]
            uc = Xr[1] @ e.B[j]
            us = Xr[2] @ e.B[j]
            if Y is not None:
                us -= e.G[j] @ Y
            # k1 u + c u', u' = omega (us cos - uc sin)
            fc = p.k1 * uc + p.c * omega * us
            fs = p.k1 * us - p.c * omega * uc
            if p.has_maxwell:   # the branches' exact fundamental (hbm.maxwell)
                km = maxwell_complex_stiffness([k for k, _ in p.maxwell],
                                               [c for _, c in p.maxwell], omega)
                fc += km.real * uc + km.imag * us
                fs += km.real * us - km.imag * uc
            if p.has_hydraulic:   # the fluid's exact fundamental (hbm.hydraulic)
                kh = fluid_stiffness(p.hydraulic, omega)
                fc += kh.real * uc + kh.imag * us
                fs += kh.real * us - kh.imag * uc
            if (ie, j) in self.axes.index:
                if Fnl is None:
                    Fnl = self.nonlinear_forces(X, False, omega)[0]
                a = self.axes.index.index((ie, j))
                fc += Fnl[1, a]
                fs += Fnl[2, a]
            total += (fc, fs)
        return total
