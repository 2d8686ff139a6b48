"""Builders of the thesis's three systems (:class:`hbm.system.System`), below the
harness: the HBM and its tests need no `vehicle`.

- :func:`sdof`: engine mass on one mount (thesis Sec. 2.1.1, eq. 2.1).
- :func:`quarter_car`: engine on a quarter car, 3 DOF (Sec. 2.1.2, eq. "1.4"-"1.6"
  with the errata of PHYSICS.md section 6: the mount and the tyre are two springs).
- :func:`rigid_engine`: 6-DOF rigid engine on 3 or 4 mounts (Sec. 2.1.3, eq. 2.9).

The mounts are :class:`fmu_src.mount_law.MountParameters`; their whole law (linear
stiffness included) stays in the mount elements.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from drymount.fmu_src.mount_law import MountParameters
from drymount.hbm.system import Excitation, MountElement, System, Transmissibility

__all__ = ["sdof", "quarter_car", "rigid_engine", "RIGID_DOFS", "skew"]

RIGID_DOFS = ("x", "y", "z", "alpha", "beta", "gamma")

#: Default mount orientation of the 6-DOF model: rows are the local axes (axial,
#: radial1, radial2) in body axes. Axial is vertical (z), radial1 = x, radial2 = y.
DEFAULT_ORIENTATION = ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))

_AXIAL_ONLY = np.array([[1.0], [0.0], [0.0]])


def _positive(value, name):
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"`{name}` must be finite and > 0, got {value!r}")


def sdof(mass: float, mount: MountParameters, excitation: str = "unbalance",
         amplitude: float = 0.0) -> System:
    """Engine of mass ``mass`` (kg) on one mount (axial axis only).

    ``excitation``: ``"unbalance"`` (f = amplitude * omega^2 sin(omega t), amplitude
    f0 in kg m, thesis eq. 4.2), ``"force"`` (amplitude in N) or ``"base"`` (chassis
    displacement, amplitude in m). Transmissibility: transmitted force over engine
    force (eq. 4.1) for force inputs, engine over chassis displacement for base input.
    DOF ``x``: engine displacement, m, positive along the mount axis.
    """
    _positive(mass, "mass")
    if excitation == "base":
        el = MountElement("mount", mount, _AXIAL_ONLY, _AXIAL_ONLY)
        exc = Excitation("base", np.array([amplitude]))
        tr = Transmissibility("displacement", dof=0, reference=None)
        base = ("chassis",)
    else:
        el = MountElement("mount", mount, _AXIAL_ONLY, np.zeros((3, 0)))
        exc = Excitation(excitation, np.array([amplitude]))
        tr = Transmissibility("force", forces=((0, 0),))
        base = ()
    return System("sdof", ("x",), [[mass]], [[0.0]], [[0.0]], (el,), exc, tr,
                  base_names=base, description="engine on one mount")


def quarter_car(m_e: float, m_s: float, m_us: float, k_s: float, c_s: float,
                k_t: float, c_t: float, mount: MountParameters,
                road_amplitude: float = 0.0) -> System:
    """Engine (``m_e``) on the mount on the sprung mass (``m_s``) of a quarter car.

    Suspension ``k_s``, ``c_s`` between sprung and unsprung (``m_us``) mass, tyre
    ``k_t``, ``c_t`` from the unsprung mass to the road. DOFs ``engine``, ``sprung``,
    ``unsprung`` (m, up). Base: ``road`` displacement, amplitude ``road_amplitude`` m.
    Transmissibility: engine amplitude / sprung amplitude (thesis eq. 4.3).
    """
    for v, n in ((m_e, "m_e"), (m_s, "m_s"), (m_us, "m_us"), (k_t, "k_t")):
        _positive(v, n)
    for v, n in ((k_s, "k_s"), (c_s, "c_s"), (c_t, "c_t")):
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"`{n}` must be finite and >= 0, got {v!r}")
    M = np.diag([m_e, m_s, m_us])
    K = np.array([[0.0, 0.0, 0.0], [0.0, k_s, -k_s], [0.0, -k_s, k_s + k_t]])
    C = np.array([[0.0, 0.0, 0.0], [0.0, c_s, -c_s], [0.0, -c_s, c_s + c_t]])
    B = np.zeros((3, 3))
    B[0, 0], B[0, 1] = 1.0, -1.0  # u = x_engine - x_sprung
    el = MountElement("mount", mount, B, np.zeros((3, 1)))
    return System("quarter_car", ("engine", "sprung", "unsprung"), M, C, K, (el,),
                  Excitation("base", np.array([road_amplitude])),
                  Transmissibility("displacement", dof=0, reference=1),
                  Kb=np.array([[0.0], [0.0], [k_t]]),
                  Cb=np.array([[0.0], [0.0], [c_t]]),
                  base_names=("road",), description="engine on a quarter car")


def skew(a) -> np.ndarray:
    """Matrix S(a) with S(a) b = a x b."""
    ax, ay, az = a
    return np.array([[0.0, -az, ay], [az, 0.0, -ax], [-ay, ax, 0.0]])


def rigid_engine(mass: float, inertia: Sequence[float], positions: Sequence,
                 mounts: Sequence[MountParameters], names: Sequence[str] | None = None,
                 orientations: Sequence | None = None, excitation: str = "base",
                 amplitude: Sequence[float] = (0.0, 0.0, 0.0035)) -> System:
    """Rigid engine (6 DOF) on mounts at ``positions`` (m, from the centre of mass).

    DOFs ``x, y, z`` (m) and small rotations ``alpha, beta, gamma`` (rad) about the
    principal axes through the centre of mass. The displacement of a point at ``a`` is
    ``t + theta x a = t - S(a) theta`` (thesis eq. 2.9). Each mount's local axes are the
    rows of its orientation (default: axial = z, radial1 = x, radial2 = y).

    ``excitation``: ``"base"`` (all chassis attachment points translate by
    ``amplitude`` (3,) m sin(omega t); transmissibility = z amplitude / base amplitude)
    or ``"unbalance"``/``"force"`` with ``amplitude`` (6,) (engine excitation:
    transmissibility = sum of the mounts' axial forces / force amplitude).
    """
    _positive(mass, "mass")
    inertia = np.asarray(inertia, dtype=float)
    if inertia.shape != (3,) or not np.all(inertia > 0):
        raise ValueError(f"`inertia` must be three values > 0, got {inertia.tolist()}")
    if len(positions) != len(mounts) or len(mounts) < 3:
        raise ValueError(f"`positions` and `mounts` must have the same length >= 3, "
                         f"got {len(positions)} and {len(mounts)}")
    names = list(names) if names is not None else [f"mount{i + 1}" for i in
                                                    range(len(mounts))]
    orientations = orientations or [DEFAULT_ORIENTATION] * len(mounts)
    els = []
    for i, (a, p, R) in enumerate(zip(positions, mounts, orientations, strict=True)):
        R = np.asarray(R, dtype=float)
        if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9):
            raise ValueError(f"`mounts[{i}].orientation` must be a 3x3 rotation, "
                             f"got {R.tolist()}")
        B = R @ np.hstack([np.eye(3), -skew(np.asarray(a, dtype=float))])
        els.append(MountElement(names[i], p, B, R.copy()))
    M = np.diag([mass, mass, mass, *inertia])
    Z = np.zeros((6, 6))
    if excitation == "base":
        exc = Excitation("base", np.asarray(amplitude, dtype=float))
        tr = Transmissibility("displacement", dof=2, reference=None)
        base = ("chassis_x", "chassis_y", "chassis_z")
    else:
        exc = Excitation(excitation, np.asarray(amplitude, dtype=float))
        tr = Transmissibility("force", forces=tuple((i, 0) for i in range(len(els))))
        base = ()
        els = [MountElement(e.name, e.params, e.B, np.zeros((3, 0))) for e in els]
    return System("rigid_engine", RIGID_DOFS, M, Z, Z, tuple(els), exc, tr,
                  base_names=base, description="6-DOF rigid engine on mounts")
