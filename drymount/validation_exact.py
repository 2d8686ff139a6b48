"""The exact steady state of a linear single-DOF system with hydraulic mount axes,
for ``drymount validate`` (its third column beside HBM and co-simulation).

Each axis with the fluid path (``AxisParameters.has_hydraulic``) contributes the
complex stiffness found by solving its chamber and passage balances per frequency
(the linear inertia-track + decoupler model, docs/physics.md "Hydraulic mount"),
written here as the four equations, not through ``fmu_src.linear_branches``: with the
deflection ``U = 1`` and unknowns ``P1, P2, Qi, Qd``

    j w C1 P1 = j w Ap - Qi - Qd          (upper chamber: the piston displaces Ap U)
    j w C2 P2 = Qi + Qd                   (lower chamber)
    (R_i + j w I_i) Qi = P1 - P2          (inertia track)
    (R_d + j w I_d) Qd = P1 - P2          (decoupler; I_d = 0: absent, Qd = 0)

and the axis force ``K* = k1 + j w c + Ap P1`` (the rubber is the axis's linear law
``k1`` and damper ``c``). Axes without it are ``k1 + j w c``. The engine's
amplitude is then ``|F(w)| / |K - w^2 M + j w C + sum B^T K* B|`` with ``F`` the
force or unbalance amplitude: the closed form of the SDOF's FRF.
"""

from __future__ import annotations

import numpy as np

__all__ = ["chamber_stiffness", "exact_sdof_amplitude"]


def chamber_stiffness(axis, omega: float) -> complex:
    """K* (N/m) of the linear ``axis`` (AxisParameters) at ``omega`` (rad/s), the
    fluid path from its four balances (module docstring)."""
    k = complex(axis.k1, omega * axis.c)
    if not axis.has_hydraulic:
        return k
    h = axis.hydraulic
    jw = 1j * omega
    A = np.array([[jw * h.C1, 0, 1, 1],
                  [0, jw * h.C2, -1, -1],
                  [-1, 1, h.R_i + jw * h.I_i, 0],
                  [-1, 1, 0, h.R_d + jw * h.I_d]], dtype=complex)
    b = np.array([jw * h.Ap, 0, 0, 0], dtype=complex)
    if h.I_d == 0.0:
        A[3] = [0, 0, 0, 1]          # no decoupler: Qd = 0
    p1 = np.linalg.solve(A, b)[0]
    return k + h.Ap * p1


def _check(system) -> None:
    if system.n_dof != 1 or system.excitation.kind == "base":
        raise ValueError(f"the exact FRF is written for a force- or unbalance-"
                         f"excited single DOF, got {system.n_dof} DOFs and a "
                         f"{system.excitation.kind!r} excitation")
    for i, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            if p.law != "linear" or p.friction or p.has_maxwell:
                raise ValueError(f"the exact FRF needs linear mount axes: mount "
                                 f"{i + 1} axis {j} has law {p.law!r}, friction "
                                 f"{p.friction}, Maxwell branches {p.has_maxwell}")


def exact_sdof_amplitude(system, freqs_hz) -> np.ndarray:
    """Amplitude (m), shape (n_f, 1), of the linear single-DOF ``system``'s steady
    state at ``freqs_hz`` (module docstring); ValueError for another system."""
    _check(system)
    out = []
    for f in np.asarray(freqs_hz, dtype=float):
        w = 2.0 * np.pi * f
        a = complex(system.K[0, 0] - w * w * system.M[0, 0], w * system.C[0, 0])
        for e in system.elements:
            for j in e.active_axes:
                a += e.B[j, 0] ** 2 * chamber_stiffness(e.params.axes[j], w)
        force = system.excitation.force_amplitude(w)
        out.append([abs(complex(force[0])) / abs(a)])
    return np.array(out)
