"""System description shared by harmonic balance (``hbm``) and the time-domain harness
(``vehicle``), so both always solve the same equations.

Equations of motion, DOFs ``q`` (n), base (chassis or road) displacements ``y``
(n_base):

    M q'' + C q' + K q + sum_e B_e^T F_e(u_e, v_e, w_e) = f(t) + K_b y + C_b y'

    u_e = B_e q - G_e y,   v_e = B_e q' - G_e y'          (3 local axes of mount e)

``F_e`` is the mount law of ``fmu_src.mount_law`` (force along each local axis, positive
in tension, i.e. the chassis side is pulled along +axis); ``w_e`` the slider positions.
``M``, ``C``, ``K`` hold only the linear structure *outside* the mounts (suspension,
tyre); the whole mount, its linear stiffness included, lives in the elements, so that
the FMU, the harness and the HBM use one law.

Harmonic excitation at angular frequency ``omega`` (rad/s), sine convention:

    kind "force":      f(t) = F sin(omega t)                 F: (n,) in N or N m
    kind "unbalance":  f(t) = omega^2 U sin(omega t)         U: (n,) in kg m or kg m^2
    kind "base":       y(t) = Y sin(omega t)                 Y: (n_base,) in m

References: thesis eq. 2.1-2.9 (models), 4.1-4.3 (transmissibilities).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drymount.fmu_src.mount_law import AXES, MountParameters

__all__ = ["MountElement", "Excitation", "Transmissibility", "System",
           "STATIC_READINGS"]

EXCITATION_KINDS = ("force", "unbalance", "base")
TRANSMISSIBILITY_KINDS = ("force", "displacement")


def _array(a, shape, name) -> np.ndarray:
    out = np.array(a, dtype=float)
    if out.shape != shape:
        raise ValueError(f"`{name}` must have shape {shape}, got {out.shape}")
    if not np.all(np.isfinite(out)):
        raise ValueError(f"`{name}` must be finite, got {out.tolist()}")
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class MountElement:
    """One mount: its law and where it sits.

    Attributes
    ----------
    name : str
        Label used in messages, CSV columns and FMU instance names.
    params : MountParameters
        The mount law, three local axes in the order of ``AXES``.
    B : ndarray, shape (3, n_dof)
        Local deflections from the DOFs: ``u = B q - G y``. A row of zeros (with the
        same row of ``G`` zero) marks an axis the model does not use.
    G : ndarray, shape (3, n_base)
        Local deflections from the base displacements (zeros: chassis side fixed).
    """

    name: str
    params: MountParameters
    B: np.ndarray
    G: np.ndarray

    @property
    def active_axes(self) -> tuple[int, ...]:
        """Indices of the axes that can deflect (non-zero row of B or G)."""
        return tuple(j for j in range(3)
                     if np.any(self.B[j] != 0.0) or np.any(self.G[j] != 0.0))

    @property
    def is_hysteretic(self) -> bool:
        return any(self.params.axes[j].friction for j in self.active_axes)


@dataclass(frozen=True, eq=False)
class Excitation:
    """Harmonic excitation (see module docstring for the three kinds)."""

    kind: str
    amplitude: np.ndarray

    def __post_init__(self):
        if self.kind not in EXCITATION_KINDS:
            raise ValueError(f"`excitation.kind` must be one of {EXCITATION_KINDS}, "
                             f"got {self.kind!r}")

    def force_amplitude(self, omega: float) -> np.ndarray:
        """Generalised force amplitude vector (n,) at ``omega`` (zeros for base)."""
        if self.kind == "force":
            return np.asarray(self.amplitude)
        if self.kind == "unbalance":
            return omega**2 * np.asarray(self.amplitude)
        return None

    def scalar_amplitude(self, omega: float) -> float:
        """Euclidean norm of the force (N) or base (m) amplitude at ``omega``."""
        a = self.force_amplitude(omega) if self.kind != "base" else self.amplitude
        return float(np.linalg.norm(a))


@dataclass(frozen=True)
class Transmissibility:
    """Definition of the scalar transmissibility reported by HBM and the harness.

    kind "force" (thesis eq. 4.1): fundamental amplitude of the sum of the mount
    forces listed in ``forces`` (pairs ``(element index, axis index)``) divided by the
    excitation force amplitude (``Excitation.scalar_amplitude``).

    kind "displacement" (thesis eq. 4.3): fundamental amplitude of DOF ``dof`` divided
    by that of DOF ``reference``, or by the base amplitude if ``reference`` is None.
    """

    kind: str
    forces: tuple[tuple[int, int], ...] = ()
    dof: int | None = None
    reference: int | None = None

    def __post_init__(self):
        if self.kind not in TRANSMISSIBILITY_KINDS:
            raise ValueError(f"`transmissibility.kind` must be one of "
                             f"{TRANSMISSIBILITY_KINDS}, got {self.kind!r}")


#: The readings of the static working point (``System.static_reading``): the engine
#: lowered onto the assembled mount (default) or every friction element relaxed there.
STATIC_READINGS = ("lowered", "relaxed")

@dataclass(frozen=True, eq=False)
class System:
    """A vehicle/engine model: linear structure + mount elements + excitation.

    Attributes
    ----------
    name : str
    dof_names : tuple of str, length n
        E.g. ``("x",)``, ``("engine", "sprung", "unsprung")`` or
        ``("x", "y", "z", "alpha", "beta", "gamma")``.
    M, C, K : ndarray, shape (n, n)
        Mass (kg, kg m^2), damping and stiffness of the structure outside the mounts.
    Kb, Cb : ndarray, shape (n, n_base)
        Coupling of the base displacement/velocity into the structure (tyre).
    elements : tuple of MountElement
    excitation : Excitation
    transmissibility : Transmissibility
    base_names : tuple of str, length n_base
    static_load : ndarray, shape (n,), optional
        Constant generalised load (N, N m), e.g. the engine's weight: the system
        vibrates about the static working point it produces (:mod:`hbm.static`).
        None (default): no static load, the unloaded point.
    static_reading : str
        Which static working point the HBM and the co-simulation start from
        (:data:`STATIC_READINGS`, :func:`hbm.static.working_point`): ``"lowered"``
        (default: the engine lowered onto the assembled mount, the friction elements
        following their return maps; docs/physics.md says why it is the physical
        one) or ``"relaxed"`` (every friction element unloaded at the working
        point).
    """

    name: str
    dof_names: tuple[str, ...]
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    elements: tuple[MountElement, ...]
    excitation: Excitation
    transmissibility: Transmissibility
    Kb: np.ndarray = None
    Cb: np.ndarray = None
    base_names: tuple[str, ...] = ()
    description: str = ""
    notes: dict = field(default_factory=dict)
    static_load: np.ndarray | None = None
    static_reading: str = "lowered"

    def __post_init__(self):
        if self.static_reading not in STATIC_READINGS:
            raise ValueError(f"`static_reading` must be one of {STATIC_READINGS}, got "
                             f"{self.static_reading!r}")
        n = len(self.dof_names)
        nb = len(self.base_names)
        object.__setattr__(self, "M", _array(self.M, (n, n), "M"))
        object.__setattr__(self, "C", _array(self.C, (n, n), "C"))
        object.__setattr__(self, "K", _array(self.K, (n, n), "K"))
        Kb = np.zeros((n, nb)) if self.Kb is None else self.Kb
        Cb = np.zeros((n, nb)) if self.Cb is None else self.Cb
        object.__setattr__(self, "Kb", _array(Kb, (n, nb), "Kb"))
        object.__setattr__(self, "Cb", _array(Cb, (n, nb), "Cb"))
        els = []
        for i, e in enumerate(self.elements):
            els.append(MountElement(e.name, e.params,
                                    _array(e.B, (3, n), f"elements[{i}].B"),
                                    _array(e.G, (3, nb), f"elements[{i}].G")))
        object.__setattr__(self, "elements", tuple(els))
        amp_shape = (nb,) if self.excitation.kind == "base" else (n,)
        object.__setattr__(self, "excitation", Excitation(
            self.excitation.kind,
            _array(self.excitation.amplitude, amp_shape, "excitation.amplitude")))
        if np.any(np.linalg.eigvalsh(self.M) <= 0):
            raise ValueError("`M` must be symmetric positive definite")
        if self.static_load is not None:
            object.__setattr__(self, "static_load",
                               _array(self.static_load, (n,), "static_load"))

    @property
    def n_dof(self) -> int:
        return len(self.dof_names)

    @property
    def has_static_load(self) -> bool:
        return self.static_load is not None and bool(np.any(self.static_load != 0.0))

    @property
    def n_base(self) -> int:
        return len(self.base_names)

    @property
    def is_hysteretic(self) -> bool:
        return any(e.is_hysteretic for e in self.elements)

    def linearized(self, stuck: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Stiffness and damping of the whole system with each mount linearised.

        Each axis contributes ``k1`` (small-deflection stiffness) and ``c``; with
        ``stuck`` a friction element adds its contact stiffness ``kf`` (stuck
        Jenkins element; the both-stuck tangent of the inclined element,
        ``AxisParameters.contact_stiffness``), otherwise it adds nothing (free
        slider). Exact for linear
        laws; for the others it is the tangent at zero deflection.

        Returns ``(K_total, C_total)``, shapes (n, n).
        """
        K = self.K.copy()
        C = self.C.copy()
        for e in self.elements:
            kd = np.zeros(3)
            cd = np.zeros(3)
            for j, p in enumerate(e.params.axes):
                kd[j] = p.k1 + (p.contact_stiffness if stuck else 0.0)
                cd[j] = p.c
            K += e.B.T @ (kd[:, None] * e.B)
            C += e.B.T @ (cd[:, None] * e.B)
        return K, C

    def linearized_base(self, stuck: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Base coupling ``(Kb_total, Cb_total)`` with mounts linearised, (n, n_base).

        The linear equations read
        ``M q'' + C_tot q' + K_tot q = f + Kb_tot y + Cb_tot y'``.
        """
        Kb = self.Kb.copy()
        Cb = self.Cb.copy()
        for e in self.elements:
            kd = np.array([p.k1 + (p.contact_stiffness if stuck else 0.0)
                           for p in e.params.axes])
            cd = np.array([p.c for p in e.params.axes])
            Kb += e.B.T @ (kd[:, None] * e.G)
            Cb += e.B.T @ (cd[:, None] * e.G)
        return Kb, Cb

    def is_linear(self) -> bool:
        """True when every active axis is linear and has no friction element."""
        return all(e.params.axes[j].law == "linear" and not e.params.axes[j].friction
                   for e in self.elements for j in e.active_axes)

    def axis_labels(self) -> list[str]:
        """``<mount>_<axis>`` for every active axis, in element order."""
        return [f"{e.name}_{AXES[j]}" for e in self.elements for j in e.active_axes]

    def with_mount_params(self, params: list[MountParameters] | MountParameters
                          ) -> System:
        """A copy with new mount parameters (one for all mounts, or one per mount)."""
        if isinstance(params, MountParameters):
            params = [params] * len(self.elements)
        els = tuple(MountElement(e.name, p, e.B, e.G)
                    for e, p in zip(self.elements, params, strict=True))
        return System(self.name, self.dof_names, self.M, self.C, self.K, els,
                      self.excitation, self.transmissibility, self.Kb, self.Cb,
                      self.base_names, self.description, dict(self.notes))

    def with_excitation(self, excitation: Excitation) -> System:
        return System(self.name, self.dof_names, self.M, self.C, self.K, self.elements,
                      excitation, self.transmissibility, self.Kb, self.Cb,
                      self.base_names, self.description, dict(self.notes))
