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

**Two readings** (issue 26): :func:`static_equilibrium` is the *relaxed* reading
above. :func:`lowered_equilibrium` is the engine *lowered onto the assembled mount*:
the load raised quasi-statically from zero on the unloaded mount (every friction
element relaxed at zero deflection), the elements following their own return maps,
so a stuck surface carries load. For the inclined element the two differ by far
more than Fs / k: any deflection between the equilibria of its four slip-slip
regimes is admissible (:func:`admissible_range`), the relaxed point is one of them
and the lowered point an end of the range (sdof_inclined: relaxed -10.86 mm,
lowered -5.87 mm, admissible -13.3 to -5.9 mm). docs/physics.md says which reading
is the physical one.

References: thesis Sec. 2.1 (models), 2.3-2.4 (elastic laws); PHYSICS.md section 7.
"""

from __future__ import annotations

import enum
import weakref
from dataclasses import dataclass

import numpy as np

from drymount.fmu_src.friction import flat_state
from drymount.fmu_src.inclined import _solve as _regime_forces
from drymount.fmu_src.mount_law import (AXES, ELASTIC_LAWS, axis_force,
                                        fluid_static, initial_sliders,
                                        static_force, without_branches)
from drymount.hbm.system import System

__all__ = ["StaticStatus", "StaticPoint", "gravity_load", "static_equilibrium",
           "working_point", "knee_warnings", "lowered_equilibrium",
           "AdmissibleRange", "admissible_range", "LOWER_STEPS"]

#: load steps of the quasi-static lowering (:func:`lowered_equilibrium`); the march
#: is exact for any count where each axis's deflection is monotonic in the load
LOWER_STEPS = 50

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

    #: ``"relaxed"`` (:func:`static_equilibrium`) or ``"lowered"``
    #: (:func:`lowered_equilibrium`)
    reading: str = "relaxed"
    #: the lowered reading's friction-element states ``{(element, axis): state}``
    states: dict | None = None
    #: the axes of ``states``, ``{(element, axis): AxisParameters}``
    axes: dict | None = None

    @property
    def sliders(self) -> np.ndarray:
        """Slider positions, shape (n_el, 3), m: the relaxed reading's are the static
        deflections; the lowered reading's the positions of its element states
        (``FrictionElement.position``, the FMU's ``w_<axis>``; the whole states,
        which the position alone does not give for every element, are
        :attr:`states`)."""
        out = self.deflection.copy()
        for (ie, j), state in (self.states or {}).items():
            out[ie, j] = _position(self, ie, j, state)
        return out


def _position(point: StaticPoint, ie: int, j: int, state) -> float:
    from drymount.fmu_src.mount_law import mean_slider

    p = point.axes[(ie, j)] if point.axes else None
    return p.element.position(state) if p is not None else mean_slider(state)


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


def working_point(system: System, reading: str | None = None) -> StaticPoint | None:
    """The working point of ``system`` under its ``static_load`` (None without one)
    that the HBM and the co-simulation start from: ``reading`` (default
    ``system.static_reading``, itself ``"lowered"`` by default) ``"lowered"``
    (:func:`lowered_equilibrium`: the engine lowered onto the assembled mount, its
    element states in ``states``) or ``"relaxed"`` (:func:`static_equilibrium`).

    Raises ValueError if the equilibrium is not found (HBM and co-simulation cannot
    run about a point that does not exist) or ``reading`` is unknown.
    """
    from drymount.hbm.system import STATIC_READINGS

    reading = system.static_reading if reading is None else reading
    if reading not in STATIC_READINGS:
        raise ValueError(f"`reading` must be one of {STATIC_READINGS}, got {reading!r}")
    if not system.has_static_load:
        return None
    if reading == "lowered":
        point = _lowered_cached(system)
    else:
        point = static_equilibrium(system, system.static_load)
    if point.status is not StaticStatus.CONVERGED:
        raise ValueError(f"the static working point ({reading}) under `static_load` "
                         f"{system.static_load.tolist()} {point.status.value} "
                         f"(largest residual {point.residual:.3g})")
    return point


_LOWERED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _lowered_cached(system: System) -> StaticPoint:
    """:func:`lowered_equilibrium` under ``system.static_load``, once per system
    (the HBM builds its problem several times per curve; a System is frozen)."""
    point = _LOWERED.get(system)
    if point is None:
        point = _LOWERED[system] = lowered_equilibrium(system, system.static_load)
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


def _committed_terms(system: System, q: np.ndarray, states: dict):
    """As :func:`_mount_terms`, the friction elements from their committed
    ``states`` (their return maps, at rest: v = 0); also the new states."""
    n_el = len(system.elements)
    u, F = np.zeros((n_el, 3)), np.zeros((n_el, 3))
    f = np.zeros(system.n_dof)
    Kt = np.zeros((system.n_dof, system.n_dof))
    new = {}
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            # a Maxwell branch carries no static force, the fluid at rest its
            # fluid_static (Ap^2 / (C1 + C2))
            p = without_branches(e.params.axes[j])
            u[ie, j] = float(e.B[j] @ q)
            if p.friction:
                r = axis_force(u[ie, j], 0.0, states[(ie, j)], p)
                F[ie, j], k, new[(ie, j)] = r[0], r[3], r[2]
            else:
                F[ie, j], k = static_force(u[ie, j], p)
            fh, kh = fluid_static(u[ie, j], e.params.axes[j])
            F[ie, j], k = F[ie, j] + fh, k + kh
            f += e.B[j] * F[ie, j]
            Kt += k * np.outer(e.B[j], e.B[j])
    return u, F, f, Kt, new


def _lower_step(system: System, load, q, states, max_iter: int):
    """Newton with backtracking on one load step of the lowering."""
    K = np.asarray(system.K, dtype=float)
    u, F, fm, Kt, new = _committed_terms(system, q, states)
    R = K @ q + fm - load
    for it in range(max_iter + 1):
        scale = np.max(np.abs(load)) + np.max(np.abs(F), initial=0.0) + 1.0
        if np.max(np.abs(R)) <= RTOL * scale:
            return q, u, F, new, R, it, StaticStatus.CONVERGED
        if it == max_iter:
            break
        try:
            dq = np.linalg.solve(K + Kt, -R)
        except np.linalg.LinAlgError:
            return q, u, F, new, R, it, StaticStatus.SINGULAR
        step, norm0 = 1.0, np.linalg.norm(R)
        while True:
            qn = q + step * dq
            un, Fn, fmn, Ktn, newn = _committed_terms(system, qn, states)
            Rn = K @ qn + fmn - load
            if np.linalg.norm(Rn) < norm0 or step < 1e-6:
                break
            step *= 0.5
        q, u, F, Kt, new, R = qn, un, Fn, Ktn, newn, Rn
    return q, u, F, new, R, max_iter, StaticStatus.NOT_CONVERGED


def lowered_equilibrium(system: System, load, steps: int = LOWER_STEPS,
                        max_iter: int = MAX_ITER) -> StaticPoint:
    """The working point with the engine lowered onto the assembled mount: ``load``
    raised from 0 in ``steps`` equal steps, every friction element starting relaxed
    at zero deflection and committed after each step (its exact return map, at
    rest), the equilibrium of each step by Newton. ``reading = "lowered"``; the
    elements' final states are in ``states``."""
    f = np.asarray(load, dtype=float)
    if f.shape != (system.n_dof,) or not np.all(np.isfinite(f)):
        raise ValueError(f"`load` must be finite with shape ({system.n_dof},), got "
                         f"{f.tolist()}")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ValueError(f"`steps` must be an integer >= 1, got {steps!r}")
    states = {(ie, j): initial_sliders(without_branches(e.params.axes[j]), 0.0)
              for ie, e in enumerate(system.elements) for j in e.active_axes
              if e.params.axes[j].friction}
    q = np.zeros(system.n_dof)
    total = 0
    for k in range(1, steps + 1):
        q, u, F, states, R, it, status = _lower_step(system, f * (k / steps), q,
                                                     states, max_iter)
        total += it
        if status is not StaticStatus.CONVERGED:
            break
    axes = {key: system.elements[key[0]].params.axes[key[1]] for key in states}
    # plain floats (the element's own state type), as a time simulation commits them
    states = {key: axes[key].element.from_flat(axes[key], flat_state(s))
              for key, s in states.items()}
    return StaticPoint(q, u, F, f, status, total, float(np.max(np.abs(R))),
                       reading="lowered", states=states, axes=axes)


@dataclass(frozen=True)
class AdmissibleRange:
    """Static deflections (m) of one inclined axis at which some state of its
    element is in equilibrium (both surfaces within their friction limits):
    ``low`` to ``high``, the equilibria of its slip-slip regimes."""

    element: int
    axis: int
    low: float
    high: float


def _vertex_system(system: System, ie: int, j: int, reg):
    """``system`` with axis (ie, j)'s inclined element replaced by its slip-slip
    regime ``reg`` (an affine law, added to the elastic law as a ``static_force``)."""
    p = system.elements[ie].params.axes[j]
    q = p.element_params
    s, c = q.sc
    f0 = -_regime_forces(0.0, 0.0, 0.0, reg, q, s, c)[3]
    f1 = -_regime_forces(-1.0, 0.0, 0.0, reg, q, s, c)[3]   # axis u = 1: x = -1
    return f0, f1 - f0


def admissible_range(system: System, load) -> list[AdmissibleRange]:
    """Per inclined axis, the admissible static deflections under ``load``: the
    axis's element force lies between the extremes of its four slip-slip regimes
    (the vertices of the friction limits; the axis force is linear in the friction
    forces), so the range ends are the equilibria with the element in those
    regimes (the other axes as in :func:`static_equilibrium`)."""
    out = []
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            if not (p.friction and p.element.name == "inclined"):
                continue
            ends = []
            for reg in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                f0, k = _vertex_system(system, ie, j, reg)
                pt = _static_with(system, load, ie, j, f0, k)
                if pt is not None:
                    ends.append(pt)
            if ends:
                out.append(AdmissibleRange(ie, j, min(ends), max(ends)))
    return out


def _static_with(system: System, load, ie: int, j: int, f0: float, k: float):
    """Deflection of axis (ie, j) at the equilibrium with its friction element
    replaced by the affine force ``f0 + k u`` (None if not found)."""
    e = system.elements[ie]
    p = e.params.axes[j]
    b = np.asarray(e.B[j], dtype=float)

    def terms(q):
        u, F, f, Kt = _mount_terms(system, q)
        fr, kr = p.element.relaxed_force(u[ie, j], p)  # replace relaxed by regime
        dF = f0 + k * u[ie, j] - fr
        return f + b * dF, Kt + (k - kr) * np.outer(b, b), u

    K = np.asarray(system.K, dtype=float)
    f = np.asarray(load, dtype=float)
    q = static_equilibrium(system, f).q
    for _ in range(MAX_ITER):
        fm, Kt, u = terms(q)
        R = K @ q + fm - f
        if np.max(np.abs(R)) <= RTOL * (np.max(np.abs(f)) + 1.0):
            return float(u[ie, j])
        try:
            q = q - np.linalg.solve(K + Kt, R)
        except np.linalg.LinAlgError:
            return None
    return None
