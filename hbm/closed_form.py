"""Closed-form single-harmonic (H = 1) Fourier coefficients of the mount nonlinearities.

For a deflection ``u = X sin(theta)`` the restoring force of an element is approximated
by ``F(theta) ~ F_s sin(theta) + F_c cos(theta)`` (F_c > 0: dissipation). The forms
below are the *corrected* ones of PHYSICS.md section 6; each is checked against a
numerical Fourier integral of the exact law in ``tests/test_hbm_closed_form.py``:

- cubic spring ``kc u^3`` (thesis eq. 3.17-3.18, printed correctly):
  ``F_s = (3/4) kc X^3``, ``F_c = 0``.
- gap part of the piecewise spring, ``(k2 - k1)(u -+ delta)`` beyond ``|u| > delta``
  (thesis eq. 3.32). The printed form is pi times too large; correct is
  ``F_s = ((k2 - k1)/pi)(X sin 2a1 + pi X - 4 delta cos a1 - 2 X a1)``,
  ``a1 = arcsin(delta/X)`` for X > delta (0 below), which simplifies to
  ``F_s = (k2 - k1) X (pi - 2 a1 - sin 2a1) / pi``; ``F_c = 0``.
- Jenkins element (thesis eq. 3.46-3.47). The printed sine coefficient has the wrong
  overall sign; correct is ``F_s = (kf X/pi)(pi/2 - a2 - sin a2 cos a2)``,
  ``a2 = arcsin(1 - 2 Fs/(kf X))``, and ``F_c = (4 Fs/pi)(1 - Fs/(kf X))`` (eq. 3.47 is
  right), for ``kf X > Fs``; below, the element sticks: ``F_s = kf X``, ``F_c = 0``.

With a phase, ``u = Uc cos(theta) + Us sin(theta) = X sin(theta + phi)``, the same
coefficients rotate: with the equivalent stiffness ``g_s = F_s/X`` and damping
``g_c = F_c/X``, ``F_cos = g_s Uc + g_c Us`` and ``F_sin = g_s Us - g_c Uc``.

Static term: the cubic is exact for any mean ``U0``. For the gap and the Jenkins element
the forms assume zero mean (symmetric laws: the H = 1 solution has ``U0 = 0``
identically, since no excitation has a static part); their static row is the tangent at
``U0 = 0``: ``F_0 = (k2 - k1)(1 - 2 a1/pi) U0`` (the fraction of the period beyond the
knees) and, for the Jenkins element, ``F_0 = kf U0`` when stuck, 0 when slipping
(translation invariance of the slipping loop). ``piecewise_asym`` has no closed form.
"""

from __future__ import annotations

import math

import numpy as np

from drymount.hbm.elements import NonlinearAxes
from drymount.hbm.laws import hbm_law

__all__ = ["cubic_coefficients", "gap_coefficients", "jenkins_coefficients",
           "closed_form_forces"]


def cubic_coefficients(X, kc):
    """``(F_s, F_c, dF_s/dX, dF_c/dX)`` of ``kc u^3`` for ``u = X sin(theta)``.

    Thesis eq. 3.17-3.18: ``F_s = (3/4) kc X^3``, ``F_c = 0``.
    """
    X = np.asarray(X, dtype=float)
    z = np.zeros_like(X)
    return 0.75 * kc * X**3, z, 2.25 * kc * X**2, z


def gap_coefficients(X, dk, delta):
    """``(F_s, F_c, dF_s/dX, dF_c/dX)`` of the gap spring (piecewise law minus k1 u).

    ``dk = k2 - k1`` (N/m), ``delta`` (m). Corrected thesis eq. 3.32 (the printed
    form is pi times too large):
    ``F_s = (dk/pi)(X sin 2a1 + pi X - 4 delta cos a1 - 2 X a1)``
    with ``a1 = arcsin(delta/X)`` for ``X > delta``, else 0; ``F_c = 0``.
    """
    X = np.asarray(X, dtype=float)
    over = X > delta
    Xs = np.where(over, X, 2.0 * delta)
    a1 = np.arcsin(delta / Xs)
    fs_ = (dk / np.pi) * (Xs * np.sin(2 * a1) + np.pi * Xs - 4 * delta * np.cos(a1)
                          - 2 * Xs * a1)
    # d/dX of X*g(X) with g = dk (pi - 2 a1 - sin 2a1)/pi:
    # g + X g' = g + 4 dk cos(a1) delta / (pi X)
    g = dk * (np.pi - 2 * a1 - np.sin(2 * a1)) / np.pi
    dfs = g + 4 * dk * np.cos(a1) * delta / (np.pi * Xs)
    z = np.zeros_like(X)
    return np.where(over, fs_, 0.0), z, np.where(over, dfs, 0.0), z


def jenkins_coefficients(X, kf, fs):
    """``(F_s, F_c, dF_s/dX, dF_c/dX)`` of the Jenkins element for ``u = X sin(theta)``.

    Corrected thesis eq. 3.46 (the printed sine coefficient has the wrong sign) and
    eq. 3.47: for ``kf X > Fs``, ``a2 = arcsin(1 - 2 Fs/(kf X))``,
    ``F_s = (kf X/pi)(pi/2 - a2 - sin a2 cos a2)``,
    ``F_c = (4 Fs/pi)(1 - Fs/(kf X))``; else ``F_s = kf X``, ``F_c = 0`` (stuck).
    """
    X = np.asarray(X, dtype=float)
    slip = kf * X > fs
    Xs = np.where(slip, X, 2.0 * fs / kf if fs > 0 else 1.0)
    r = fs / (kf * Xs)
    a2 = np.arcsin(1.0 - 2.0 * r)
    ca = np.cos(a2)
    g_s = (kf / np.pi) * (np.pi / 2 - a2 - np.sin(a2) * ca)
    # dg_s/dX = -(kf/pi) 2 cos^2(a2) da2/dX, da2/dX = 2 r / (X cos a2)
    dg_s = -4.0 * kf * r * ca / (np.pi * Xs)
    F_s = np.where(slip, g_s * Xs, kf * X)
    dF_s = np.where(slip, g_s + Xs * dg_s, kf)
    F_c = np.where(slip, (4 * fs / np.pi) * (1.0 - r), 0.0)
    dF_c = np.where(slip, (4 * fs / np.pi) * r / Xs, 0.0)
    return F_s, F_c, dF_s, dF_c


def closed_form_forces(U: np.ndarray, ax: NonlinearAxes
                       ) -> tuple[np.ndarray, np.ndarray]:
    """H = 1 Fourier coefficients of the nonlinear remainders and their Jacobian.

    Parameters
    ----------
    U : ndarray, shape (3, n_ax)
        Deflection coefficients ``[static, cos1, sin1]`` of each axis, m.
    ax : NonlinearAxes

    Returns
    -------
    F : ndarray, shape (3, n_ax)
        Force coefficients ``[static, cos1, sin1]``, N.
    dF : ndarray, shape (n_ax, 3, 3)
        ``dF[a, h, g] = dF[h, a] / dU[g, a]``.
    """
    n_ax = U.shape[1]
    # plain Python floats and math: the arrays are tiny and NumPy scalars are slow
    U0s, Ucs, Uss = U.tolist()
    F = [[0.0] * n_ax for _ in range(3)]
    dF = np.zeros((n_ax, 3, 3))
    pi = math.pi
    for a in range(n_ax):
        u0, uc, us = U0s[a], Ucs[a], Uss[a]
        x = math.hypot(uc, us)
        d = [[0.0] * 3 for _ in range(3)]
        gs = gc = dgs = dgc = 0.0  # equivalent stiffness/damping and d/dX
        k0 = dk0 = 0.0  # static tangent at U0 = 0 and its d/dX
        # the elastic law's terms (hbm.laws, by name), then the Jenkins element's
        terms = hbm_law(ax.law[a]).closed_form(a, ax, u0, uc, us, x, d)
        F[0][a] += terms.f0
        gs += terms.gs
        dgs += terms.dgs
        k0 += terms.k0
        dk0 += terms.dk0
        kf, fs = ax.kf_list[a], ax.fs_list[a]
        if kf > 0.0:
            if kf * x > fs:
                r = fs / (kf * x)
                a2 = math.asin(1.0 - 2.0 * r)
                ca = math.cos(a2)
                gs += (kf / pi) * (pi / 2 - a2 - math.sin(a2) * ca)
                dgs += -4.0 * kf * r * ca / (pi * x)
                gc += (4 * fs / (pi * x)) * (1.0 - r)
                dgc += (4 * fs / pi) * (-1.0 / x**2 + 2 * fs / (kf * x**3))
            else:
                gs += kf
                k0 += kf
        F[0][a] += k0 * u0
        d[0][0] += k0
        F[1][a] += gs * uc + gc * us
        F[2][a] += gs * us - gc * uc
        # chain rule through X = hypot(Uc, Us)
        if x > 0.0:
            xc, xs = uc / x, us / x
            d[0][1] += dk0 * u0 * xc
            d[0][2] += dk0 * u0 * xs
        else:
            xc = xs = 0.0
        d[1][1] += gs + (dgs * uc + dgc * us) * xc
        d[1][2] += gc + (dgs * uc + dgc * us) * xs
        d[2][1] += -gc + (dgs * us - dgc * uc) * xc
        d[2][2] += gs + (dgs * us - dgc * uc) * xs
        dF[a] = d
    F = np.array(F)
    return F, dF
