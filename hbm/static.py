"""Static working point of a system under constant loads (engine weight, torques).

Equilibrium of the structure and the mounts' elastic laws with the base at rest:

    R(q) = K q + sum_e B_e^T F_el,e(B_e q) - f_static = 0

(``hbm.system`` conventions; ``F_el`` from :func:`fmu_src.mount_law.elastic_force`),
solved by Newton's method with the laws' tangent stiffness and a backtracking line
search (the piecewise laws have kinks), started from the small-deflection (k1) solution.

**Friction sliders are relaxed**: the Jenkins elements carry no static force. A slider
holds at most Fs (10-250 N in the presets, a fraction of the engine's weight) and any
vibration about the working point makes it slip whenever its force would exceed Fs, so
over the first cycles it settles where its spring is unloaded: the working point is the
elastic laws' equilibrium and each slider's committed position is the deflection there
(``w = u0``). The inclined element of Ch. 5 is relaxed the same way (both surfaces
unloaded, ``fmu_src.inclined.relaxed_state``); its wedge spring and preload still
carry load through the inclined surface, so its relaxed force
(``fmu_src.mount_law.static_force``) enters the equilibrium. The alternative, sliders
stuck at a position committed before loading
(e.g. 0), would let them carry up to Fs of the load, a history-dependent share that no
datasheet knows; it moves the working point by at most Fs / k_tangent per mount.

References: thesis Sec. 2.1 (models), 2.3-2.4 (elastic laws); PHYSICS.md section 7.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from drymount.fmu_src.mount_law import AXES, ELASTIC_LAWS, static_force
from drymount.hbm.system import System

__all__ = ["StaticStatus", "StaticPoint", "gravity_load", "static_equilibrium",
           "working_point", "knee_warnings"]

#: Newton stops when |R| <= RTOL * (|f_static| + the largest elastic force).
RTOL = 1e-12
MAX_ITER = 60


class StaticStatus(enum.Enum):
    CONVERGED = "converged"
    NOT_CONVERGED = "not converged"
    SINGULAR = "singular tangent (a DOF without stiffness)"


@dataclass(frozen=True)
class StaticPoint:
    """The static working point.

    Attributes
    ----------
    q : ndarray, shape (n,)
        Generalised displacements, m or rad.
    deflection, force : ndarray, shape (n_elements, 3)
        Static deflection (m) and elastic force (N, positive = tension) of each mount
        axis in the order of ``AXES``; zero on axes the model does not move.
    load : ndarray, shape (n,)
        The static load, N or N m.
    status : StaticStatus
    iterations : int
    residual : float
        Largest |R| component at ``q``, N or N m.
    """

    q: np.ndarray
    deflection: np.ndarray
    force: np.ndarray
    load: np.ndarray
    status: StaticStatus
    iterations: int
    residual: float

    @property
    def sliders(self) -> np.ndarray:
        """Relaxed slider positions (= the static deflections), shape (n_el, 3), m."""
        return self.deflection.copy()


def gravity_load(system: System, vertical, g: float = 9.81) -> np.ndarray:
    """Weight as a generalised force: ``-g M d`` with ``d`` the upward unit motion.

    ``vertical`` (n,) is the generalised displacement of a unit upward translation of
    every body (1 on the vertical translation DOFs, 0 elsewhere).
    """
    d = np.asarray(vertical, dtype=float)
    if d.shape != (system.n_dof,):
        raise ValueError(f"`vertical` must have shape ({system.n_dof},), got {d.shape}")
    if not (np.isfinite(g) and g >= 0):
        raise ValueError(f"`g` must be finite and >= 0 (m/s^2), got {g!r}")
    return -g * (system.M @ d)


def _mount_terms(system: System, q: np.ndarray):
    """Elastic forces (n_el, 3), their generalised sum (n,) and tangent (n, n)."""
    n_el = len(system.elements)
    u = np.zeros((n_el, 3))
    F = np.zeros((n_el, 3))
    f = np.zeros(system.n_dof)
    Kt = np.zeros((system.n_dof, system.n_dof))
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            u[ie, j] = float(e.B[j] @ q)
            F[ie, j], k = static_force(u[ie, j], e.params.axes[j])
            f += e.B[j] * F[ie, j]
            Kt += k * np.outer(e.B[j], e.B[j])
    return u, F, f, Kt


def static_equilibrium(system: System, load, q0=None, max_iter: int = MAX_ITER
                       ) -> StaticPoint:
    """Solve ``K q + sum B^T F_el(B q) = load`` (sliders relaxed, base at rest)."""
    f = np.asarray(load, dtype=float)
    if f.shape != (system.n_dof,) or not np.all(np.isfinite(f)):
        raise ValueError(f"`load` must be finite with shape ({system.n_dof},), got "
                         f"{f.tolist()}")
    K = np.asarray(system.K, dtype=float)
    q = np.zeros(system.n_dof) if q0 is None else np.asarray(q0, dtype=float).copy()
    u, F, fm, Kt = _mount_terms(system, q)
    R = K @ q + fm - f
    if q0 is None:  # the small-deflection (k1) solution as the start
        K1, _ = system.linearized()
        try:
            q = np.linalg.solve(K1, f)
        except np.linalg.LinAlgError:
            return StaticPoint(q, u, F, f, StaticStatus.SINGULAR, 0,
                               float(np.max(np.abs(R))))
        u, F, fm, Kt = _mount_terms(system, q)
        R = K @ q + fm - f
    it = 0
    while True:
        scale = np.max(np.abs(f)) + np.max(np.abs(F), initial=0.0) + 1.0
        if np.max(np.abs(R)) <= RTOL * scale:
            status = StaticStatus.CONVERGED
            break
        if it >= max_iter:
            status = StaticStatus.NOT_CONVERGED
            break
        it += 1
        try:
            dq = np.linalg.solve(K + Kt, -R)
        except np.linalg.LinAlgError:
            status = StaticStatus.SINGULAR
            break
        step, norm0 = 1.0, np.linalg.norm(R)
        while True:  # backtrack: a full step may jump across a kink and back
            qn = q + step * dq
            un, Fn, fmn, Ktn = _mount_terms(system, qn)
            Rn = K @ qn + fmn - f
            if np.linalg.norm(Rn) < norm0 or step < 1e-6:
                break
            step *= 0.5
        q, u, F, Kt, R = qn, un, Fn, Ktn, Rn
    return StaticPoint(q, u, F, f, status, it, float(np.max(np.abs(R))))


def working_point(system: System) -> StaticPoint | None:
    """The working point of ``system`` under its ``static_load`` (None without one).

    Raises ValueError if the equilibrium is not found (HBM and co-simulation cannot
    run about a point that does not exist).
    """
    if not system.has_static_load:
        return None
    point = static_equilibrium(system, system.static_load)
    if point.status is not StaticStatus.CONVERGED:
        raise ValueError(f"the static working point under `static_load` "
                         f"{system.static_load.tolist()} {point.status.value} "
                         f"(largest residual {point.residual:.3g})")
    return point


def knee_warnings(system: System, point: StaticPoint, travel: float | None = None
                  ) -> list[str]:
    """One message per mount axis that works past a knee of its law or its travel."""
    out = []
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            u = point.deflection[ie, j]
            past = [k for k in ELASTIC_LAWS[p.law].knees(p)
                    if (k > 0 and u > k) or (k < 0 and u < k)]
            where = f"{e.name} {AXES[j]}"
            if past:
                out.append(f"{where}: static deflection {u * 1e3:.3f} mm is past the "
                           f"knee at {past[0] * 1e3:+.3f} mm (stiffness k2 = "
                           f"{p.k2:.6g} N/m instead of k1 = {p.k1:.6g} N/m)")
            if travel is not None and abs(u) > travel:
                out.append(f"{where}: static deflection {u * 1e3:.3f} mm exceeds the "
                           f"travel of {travel * 1e3:.3f} mm")
    return out
