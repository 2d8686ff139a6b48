"""Dynamic stiffness and loss angle of one mount axis (the datasheet of a mount).

A mount test rig imposes a harmonic deflection about a static working point,

    u(t) = U0 + X sin(omega t),

and reports the complex dynamic stiffness as the fundamental of the measured force over
the displacement amplitude: with the force's fundamental ``F_s sin + F_c cos``,

    K*(omega, X, U0) = (F_s + i F_c) / X,   |K*|,   loss angle delta = arg K*.

Here the force is the mount law of ``fmu_src.mount_law`` under that imposed motion: the
harmonic balance of one axis whose deflection harmonics are all imposed (only the
fundamental is non-zero), so the force harmonics follow from the alternating
frequency-time evaluation (:func:`hbm.aft.aft_forces`) of the nonlinear remainder plus
the linear part ``k1 u + c v`` in closed form. The static row of the same balance fixes
the working point for a static preload ``P`` (N):

    mean over a period of F(U0 + X sin theta) = P.

The friction element's mean force is zero under this motion (its periodic loop is
point-symmetric about its centre; a stuck element is started relaxed at ``U0``, i.e.
``w = U0``: the slider settles while the preload creeps on), so the elastic law
carries the preload. The law is rate independent apart from ``c``, so
``K* = K*_rate-independent(X, U0) + i omega c`` exactly; a rate-dependent friction
element is evaluated at each frequency (its march gets the velocity samples
and the step, :mod:`hbm.generic_march`), and its working point is the elastic law's
(its mean force taken as zero, as the rate-independent elements' is).

For a linear spring and damper ``K* = k1 + i omega c``; for the Jenkins element the
closed forms of :mod:`hbm.closed_form` (tests). :func:`time_domain_stiffness` is the
independent route: it marches :func:`fmu_src.mount_law.axis_force` through several
periods of the imposed motion and takes the fundamental of the last one.

References: thesis Sec. 2.2-2.4 (law), 3.1 (Fourier approximation); ISO 10846 for the
dynamic stiffness of resilient elements.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from drymount.fmu_src.linear_branches import (hydraulic_complex_stiffness,
                                              maxwell_complex_stiffness)
from drymount.fmu_src.mount_law import AxisParameters, axis_force, initial_sliders
from drymount.hbm.aft import FourierBasis, aft_forces
from drymount.hbm.elements import NonlinearAxes, friction_columns
from drymount.hbm.roots import brentq

__all__ = ["DEFAULT_SAMPLES", "DynamicStiffnessMap", "axis_as_nonlinear",
           "rate_independent_stiffness", "working_deflection", "dynamic_stiffness",
           "time_domain_stiffness"]

#: Samples per period of the AFT evaluation. The Jenkins force has slope jumps, so the
#: rectangle rule converges as 1/N^2: 4096 samples give about 1e-7 relative error.
DEFAULT_SAMPLES = 4096


@dataclass(frozen=True)
class DynamicStiffnessMap:
    """Dynamic stiffness of one axis on a grid of frequency, amplitude and preload.

    Attributes
    ----------
    freq_hz : ndarray, shape (nf,)
    amplitude : ndarray, shape (na,)
        Displacement amplitudes X, m.
    preload : ndarray, shape (np,)
        Static forces P, N.
    mean_deflection : ndarray, shape (np, na)
        Working point U0 solving the static row for each preload and amplitude, m.
    K : ndarray of complex, shape (np, na, nf)
        Dynamic stiffness K*, N/m.
    """

    freq_hz: np.ndarray
    amplitude: np.ndarray
    preload: np.ndarray
    mean_deflection: np.ndarray
    K: np.ndarray

    @property
    def magnitude(self) -> np.ndarray:
        """|K*| in N/m, shape (np, na, nf)."""
        return np.abs(self.K)

    @property
    def loss_angle_deg(self) -> np.ndarray:
        """Loss angle arg K* in degrees, shape (np, na, nf)."""
        return np.degrees(np.angle(self.K))

    @property
    def loss_factor(self) -> np.ndarray:
        """tan(delta) = Im K* / Re K*, shape (np, na, nf)."""
        return self.K.imag / self.K.real


def axis_as_nonlinear(axis: AxisParameters, w_start: float = 0.0) -> NonlinearAxes:
    """The axis as a one-row :class:`hbm.elements.NonlinearAxes` (for the AFT)."""
    one = np.ones((1, 1))
    return NonlinearAxes(
        labels=("axis",), index=((0, 0),), B=one, G=np.zeros((1, 1)),
        law=(axis.law,), k1=np.array([axis.k1]),
        kc=np.array([axis.kc]), k2=np.array([axis.k2]),
        delta=np.array([axis.delta]),
        delta_neg=np.array([axis.delta_neg]), w_start=np.array([float(w_start)]),
        **friction_columns([axis]))


def _coefficients(axis: AxisParameters, X: float, U0: float, basis: FourierBasis,
                  omega: float | None = None) -> np.ndarray:
    """Force coefficients ``[static, cos 1, sin 1]`` of the law without ``c`` (at the
    frequency ``omega``, rad/s, for a rate-dependent friction element)."""
    U = np.zeros((3, 1))
    U[0, 0], U[2, 0] = U0, X
    F, _ = aft_forces(U, axis_as_nonlinear(axis, w_start=U0), basis, jacobian=False,
                      omega=omega)
    F = F[:, 0] + axis.k1 * U[:, 0]
    return F


def _check_amplitude(X: float) -> float:
    X = float(X)
    if not (math.isfinite(X) and X > 0):
        raise ValueError(f"`amplitude` must be finite and > 0 (m), got {X!r}")
    return X


def _rate_dependent(axis: AxisParameters) -> bool:
    return axis.friction and axis.element.rate_dependent


def working_deflection(axis: AxisParameters, preload: float, X: float,
                       n_samples: int = DEFAULT_SAMPLES) -> float:
    """Mean deflection U0 (m) at which the period-mean force equals ``preload`` (N).

    The static row of the imposed-deflection balance, solved by Brent's method: the
    period-mean elastic force increases strictly with U0 when ``k1 > 0`` and ``k2 > 0``
    (the friction element contributes no mean force, module docstring).
    """
    X = _check_amplitude(X)
    P = float(preload)
    if not math.isfinite(P):
        raise ValueError(f"`preload` must be finite (N), got {preload!r}")
    if P == 0.0 and axis.law != "piecewise_asym":
        return 0.0  # odd law: the mean force vanishes at U0 = 0
    k_min = min(axis.k1, axis.k2) if axis.law.startswith("piecewise") else axis.k1
    if not k_min > 0:
        raise ValueError(f"a preload needs a stiff law: k1 and k2 must be > 0, got "
                         f"k1 = {axis.k1!r}, k2 = {axis.k2!r}")
    basis = FourierBasis(1, n_samples)
    if _rate_dependent(axis):   # the elastic law carries the preload
        axis = replace(axis, friction=False)
    mean = lambda u0: _coefficients(axis, X, u0, basis)[0] - P  # noqa: E731
    span = abs(P) / k_min + X
    return float(brentq(mean, -span, span, xtol=1e-15, rtol=1e-13))


def rate_independent_stiffness(axis: AxisParameters, X: float, U0: float = 0.0,
                               n_samples: int = DEFAULT_SAMPLES,
                               omega: float | None = None) -> complex:
    """``(F_s + i F_c) / X`` of the law without its viscous term, N/m (a
    rate-dependent friction element needs the frequency ``omega``, rad/s)."""
    X = _check_amplitude(X)
    F = _coefficients(axis, X, float(U0), FourierBasis(1, n_samples), omega)
    return complex(F[2], F[1]) / X


def dynamic_stiffness(axis: AxisParameters, freqs_hz, amplitudes, preloads=(0.0,),
                      n_samples: int = DEFAULT_SAMPLES, progress=None
                      ) -> DynamicStiffnessMap:
    """K* on the grid ``preloads x amplitudes x freqs_hz`` (see the module docstring).

    ``progress`` (optional) is called with no argument after each (preload, amplitude)
    pair, e.g. a progress bar's ``update``.
    """
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    a = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    p = np.atleast_1d(np.asarray(preloads, dtype=float))
    for name, arr, rule in (("freqs_hz", f, "> 0"), ("amplitudes", a, "> 0"),
                            ("preloads", p, "finite")):
        ok = np.all(np.isfinite(arr)) and (rule == "finite" or np.all(arr > 0))
        if arr.size == 0 or not ok:
            raise ValueError(f"`{name}` must be a non-empty list of numbers {rule}, "
                             f"got {arr.tolist()}")
    omega = 2.0 * np.pi * f
    U0 = np.zeros((p.size, a.size))
    K = np.zeros((p.size, a.size, f.size), dtype=complex)
    for i, P in enumerate(p):
        for j, X in enumerate(a):
            U0[i, j] = working_deflection(axis, P, X, n_samples)
            if _rate_dependent(axis):   # its loop changes with the frequency
                k_ri = np.array([rate_independent_stiffness(axis, X, U0[i, j],
                                                            n_samples, float(w))
                                 for w in omega])
            else:
                k_ri = rate_independent_stiffness(axis, X, U0[i, j], n_samples)
            K[i, j] = k_ri + 1j * omega * axis.c
            if axis.has_maxwell:   # linear: their closed form (no static force)
                K[i, j] += np.asarray(maxwell_complex_stiffness(
                    [k for k, _ in axis.maxwell], [c for _, c in axis.maxwell],
                    omega.tolist()))
            if axis.has_hydraulic:   # linear: the fluid's closed form (its static
                # part Ap^2 / (C1 + C2) is the omega -> 0 limit; rubber: k1/law, c)
                K[i, j] += np.asarray(hydraulic_complex_stiffness(axis.hydraulic,
                                                                  omega.tolist()))
            if progress is not None:
                progress()
    return DynamicStiffnessMap(f, a, p, U0, K)


def time_domain_stiffness(axis: AxisParameters, freq_hz: float, X: float,
                          U0: float = 0.0, periods: int = 4,
                          steps_per_period: int = 2048) -> complex:
    """K* from a time march of the law (independent of the AFT), N/m.

    The deflection starts at the working point ``U0`` with the slider relaxed there
    (``w = U0``), then follows ``U0 + X sin(omega t)`` for
    ``periods`` periods; :func:`fmu_src.mount_law.axis_force` is marched sample by
    sample (velocity exact) and the fundamental of the last period is taken with the
    rectangle rule.
    """
    X = _check_amplitude(X)
    omega = 2.0 * math.pi * freq_hz
    n = int(steps_per_period)
    w = initial_sliders(axis, float(U0))   # relaxed at U0 (any friction kind)
    last = np.empty(n)
    for k in range(periods * n):
        th = 2.0 * math.pi * (k % n) / n
        u = U0 + X * math.sin(th)
        v = X * omega * math.cos(th)
        r = axis_force(u, v, w, axis, None, 2.0 * math.pi / (omega * n))
        w = r.w_new
        if k >= (periods - 1) * n:
            last[k % n] = r.force
    th = 2.0 * np.pi * np.arange(n) / n
    F_s = 2.0 / n * float(np.dot(last, np.sin(th)))
    F_c = 2.0 / n * float(np.dot(last, np.cos(th)))
    return complex(F_s, F_c) / X
