"""Linear analysis: exact FRF and undamped natural frequencies with mode shapes.

The mounts are linearised by :meth:`hbm.system.System.linearized`: each axis keeps its
small-deflection stiffness ``k1`` and damping ``c``; a friction element is either free
(slider slipping freely, adds nothing: ``stuck=False``) or stuck (adds ``kf``).

Phasor convention (sine excitation of :mod:`hbm.system`):
``q(t) = Im(Q exp(i omega t))``, so the harmonic-balance coefficients are
``Qc1 = Im Q`` and ``Qs1 = Re Q``, with

    (K - omega^2 M + i omega C) Q = F                   (force: F; unbalance: omega^2 U)
                                  = (Kb + i omega Cb) Y (base)

References: thesis eq. 2.1-2.9, 3.50 without the nonlinear term.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from drymount.hbm.system import System

__all__ = ["linear_frf", "natural_frequencies"]


def _freqs(freqs_hz) -> np.ndarray:
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    if f.ndim != 1 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError(f"`freqs_hz` must be finite frequencies >= 0, "
                         f"got {freqs_hz!r}")
    return f


def linear_frf(system: System, freqs_hz, stuck: bool = False) -> np.ndarray:
    """Exact FRF of the system with its mounts linearised, for its own excitation.

    Parameters
    ----------
    system : System
    freqs_hz : array_like, shape (n_freq,)
        Frequencies in Hz.
    stuck : bool
        Friction elements stuck (add ``kf``) instead of free.

    Returns
    -------
    Q : complex ndarray, shape (n_freq, n_dof)
        Complex amplitudes, ``q(t) = Im(Q exp(i omega t))``; ``abs(Q)`` is the amplitude
        in m (rad for rotations).

    Examples
    --------
    >>> from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    >>> from drymount.hbm.systems import sdof
    >>> mp = MountParameters(axial=AxisParameters(law="linear", k1=1e5, c=0.0))
    >>> s = sdof(100.0, mp, excitation="force", amplitude=1.0)
    >>> float(abs(linear_frf(s, [0.0])[0, 0]))
    1e-05
    """
    f = _freqs(freqs_hz)
    K, C = system.linearized(stuck=stuck)
    Kb, Cb = system.linearized_base(stuck=stuck)
    exc = system.excitation
    out = np.empty((f.size, system.n_dof), dtype=complex)
    for i, fi in enumerate(f):
        w = 2.0 * np.pi * fi
        A = K - w * w * system.M + 1j * w * C
        if exc.kind == "force":
            rhs = np.asarray(exc.amplitude, dtype=complex)
        elif exc.kind == "unbalance":
            rhs = w * w * np.asarray(exc.amplitude, dtype=complex)
        else:
            rhs = (Kb + 1j * w * Cb) @ np.asarray(exc.amplitude)
        out[i] = np.linalg.solve(A, rhs)
    return out


def natural_frequencies(system: System, stuck: bool = False
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Undamped natural frequencies and mass-normalised mode shapes.

    Solves ``K phi = omega^2 M phi`` with the mounts linearised (``stuck``: friction
    elements add ``kf``).

    Returns
    -------
    freq_hz : ndarray, shape (n,)
        Ascending, Hz (rigid-body modes give 0).
    modes : ndarray, shape (n, n)
        ``modes[:, i]`` is mode i, ``modes.T @ M @ modes = I``.
    """
    K, _ = system.linearized(stuck=stuck)
    lam, vec = scipy.linalg.eigh(K, system.M)
    lam = np.where(lam < 0.0, 0.0, lam)  # round-off of rigid-body modes
    return np.sqrt(lam) / (2.0 * np.pi), vec
