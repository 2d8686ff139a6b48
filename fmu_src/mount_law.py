"""Force law of a friction-damped engine mount: the single source of truth.

The FMU (``fmu_src/friction_mount.py``), the time-domain harness (``vehicle/``) and the
harmonic-balance AFT evaluation (``hbm/``) all call the functions of this module. It
imports only Python's standard library, so the FMU runs in any host Python.

In each local axis j of a mount (``axial``, ``radial1``, ``radial2``) the force that the
mount exerts on the chassis side (equal and opposite on the engine side) is

    F_j = F_el(u_j) + c_j du_j/dt + F_fr,j      u_j = engine minus chassis deflection

with ``F_el`` one of (thesis Sec. 2.3-2.4, PHYSICS.md section 1)

    linear            k1 u
    cubic             k1 u + kc u^3
    piecewise         k1 u                          for -delta < u < delta
                      k1 u + (k2 - k1)(u - delta)   for u >= delta
                      k1 u + (k2 - k1)(u + delta)   for u <= -delta
    piecewise_asym    as piecewise, knee at +delta for u > 0 and at -delta_neg for u < 0

and ``F_fr`` the macro-slip (Jenkins) element of thesis Sec. 2.2: a spring ``kf`` in
series with a Coulomb slider of slip force ``Fs = mu * n0``. Its state is the slider
position ``w``; the update for a displacement increment is the exact return map

    trial = kf (u_new - w);  if |trial| > Fs:  w = u_new - sign(trial) Fs / kf

(rate independent, exact when u is monotonic inside the increment). The energy the
slider dissipates in an increment is ``Fs * |w_new - w|``.

A positive force is a tensile force along the axis: for u > 0 (engine moved in the
positive axis direction relative to the chassis) the elastic force is positive, and the
engine feels ``-F_j`` while the chassis feels ``+F_j``.

References: thesis eq. 2.10-2.13 (Jenkins element), 2.15-2.20 (elastic laws), 4.4
(radial stiffness = lambda * axial).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

__all__ = [
    "AXES",
    "LAWS",
    "LAW_CODES",
    "AxisParameters",
    "MountParameters",
    "ParameterError",
    "elastic_force",
    "jenkins_update",
    "axis_force",
    "axis_force_p",
    "mount_force",
]

#: Names of the three local axes of a mount, in the order used everywhere.
AXES = ("axial", "radial1", "radial2")
#: Names of the elastic laws; the FMU's integer parameter ``<axis>_law`` is the index.
LAWS = ("linear", "cubic", "piecewise", "piecewise_asym")
LAW_CODES = {name: code for code, name in enumerate(LAWS)}

LINEAR, CUBIC, PIECEWISE, PIECEWISE_ASYM = range(4)


class ParameterError(ValueError):
    """Invalid mount parameters. ``problems`` lists every problem found."""

    def __init__(self, problems: list[str]):
        self.problems = list(problems)
        super().__init__("invalid mount parameters: " + "; ".join(self.problems))


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


@dataclass(frozen=True)
class AxisParameters:
    """Parameters of one local axis of a mount (SI units).

    Defaults are the thesis's piecewise-linear fit (Sec. 2.4: k1 = 91 870 N/m,
    k2 = 513 800 N/m, delta = 0.01225 m) with values the thesis does not print:
    c = 150 N s/m (damping ratio about 3 % on a 70 kg engine), kf = 60 000 N/m and
    mu = 1 (only the slip force Fs = mu * n0 matters, so n0 reads as a slip force).
    Friction is off unless ``friction`` is true.

    Attributes
    ----------
    law : str
        ``"linear"``, ``"cubic"``, ``"piecewise"`` or ``"piecewise_asym"``.
    k1 : float
        Linear (small-deflection) stiffness, N/m, >= 0.
    kc : float
        Cubic stiffness, N/m^3, >= 0 (used by ``cubic``).
    k2 : float
        Stiffness beyond the knee, N/m, >= 0 (used by the piecewise laws).
    delta : float
        Knee deflection for u > 0 (and u < 0 for ``piecewise``), m, > 0.
    delta_neg : float
        Knee deflection magnitude for u < 0 with ``piecewise_asym``, m, > 0.
    c : float
        Viscous damping, N s/m, >= 0.
    friction : bool
        Whether the macro-slip (Jenkins) element is present on this axis.
    kf : float
        Contact stiffness of the Jenkins element, N/m, > 0 when friction is on.
    mu : float
        Friction coefficient, >= 0.
    n0 : float
        Normal force on the friction contact, N, >= 0.
    """

    law: str = "piecewise"
    k1: float = 91870.0
    kc: float = 0.0
    k2: float = 513800.0
    delta: float = 0.01225
    delta_neg: float = 0.01225
    c: float = 150.0
    friction: bool = False
    kf: float = 60000.0
    mu: float = 1.0
    n0: float = 0.0

    def __post_init__(self):
        problems = self.problems()
        if problems:
            raise ParameterError(problems)

    def problems(self, prefix: str = "") -> list[str]:
        """Every problem of these parameters, each naming field, value and rule."""
        out = []
        if self.law not in LAW_CODES:
            out.append(f"`{prefix}law` must be one of {', '.join(LAWS)}, "
                       f"got {self.law!r}")
        for name, rule in (
            ("k1", ">= 0"),
            ("kc", ">= 0"),
            ("k2", ">= 0"),
            ("delta", "> 0"),
            ("delta_neg", "> 0"),
            ("c", ">= 0"),
            ("mu", ">= 0"),
            ("n0", ">= 0"),
        ):
            value = getattr(self, name)
            ok = _finite(value) and (value > 0 if rule == "> 0" else value >= 0)
            if not ok:
                out.append(f"`{prefix}{name}` must be finite and {rule}, got {value!r}")
        if not isinstance(self.friction, bool):
            out.append(f"`{prefix}friction` must be true or false, "
                       f"got {self.friction!r}")
        if not _finite(self.kf) or (self.friction and self.kf <= 0) or self.kf < 0:
            rule = "> 0 when friction is on" if self.friction else ">= 0"
            out.append(f"`{prefix}kf` must be finite and {rule}, got {self.kf!r}")
        return out

    @property
    def law_code(self) -> int:
        return LAW_CODES[self.law]

    @property
    def fs(self) -> float:
        """Slip force Fs = mu * n0 in N (0 without friction), thesis eq. 2.12."""
        return self.mu * self.n0 if self.friction else 0.0

    @property
    def eps(self) -> float:
        """Slip displacement eps = Fs / kf in m, thesis eq. 2.13 (0 if no friction)."""
        return self.fs / self.kf if self.friction else 0.0

    def scaled(self, lam: float) -> AxisParameters:
        """The same axis with stiffnesses and damping times ``lam`` (thesis eq. 4.4)."""
        if not (_finite(lam) and lam > 0):
            raise ParameterError([f"`lambda` must be finite and > 0, got {lam!r}"])
        return replace(self, k1=self.k1 * lam, kc=self.kc * lam, k2=self.k2 * lam,
                       c=self.c * lam)

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class MountParameters:
    """Three local axes of one mount, in the order of ``AXES``.

    Use :meth:`from_axial` for the thesis's convention radial = lambda * axial.
    """

    axial: AxisParameters = AxisParameters()
    radial1: AxisParameters = AxisParameters()
    radial2: AxisParameters = AxisParameters()

    def __post_init__(self):
        problems = []
        for name in AXES:
            axis = getattr(self, name)
            if not isinstance(axis, AxisParameters):
                problems.append(f"`{name}` must be AxisParameters, "
                                f"got {type(axis).__name__}")
        if problems:
            raise ParameterError(problems)

    @property
    def axes(self) -> tuple[AxisParameters, AxisParameters, AxisParameters]:
        return (self.axial, self.radial1, self.radial2)

    @classmethod
    def from_axial(
        cls,
        axial: AxisParameters,
        lam: float = 1.0,
        friction_axes: tuple[str, ...] | None = None,
    ) -> MountParameters:
        """Radial axes = ``lam`` * axial (stiffness and damping), thesis eq. 4.4.

        ``friction_axes`` names the axes that keep the axial friction element (default:
        only ``axial`` if it has friction); the others get none.
        """
        if friction_axes is None:
            friction_axes = ("axial",) if axial.friction else ()
        bad = [a for a in friction_axes if a not in AXES]
        if bad:
            raise ParameterError(
                [f"`friction_axes` entries must be among {AXES}, got {bad!r}"])
        radial = axial.scaled(lam)
        out = {}
        for name in AXES:
            base = axial if name == "axial" else radial
            out[name] = replace(base, friction=name in friction_axes)
        return cls(**out)


# --------------------------------------------------------------------------------------
# Scalar law: plain floats, standard library only (fast in a per-step loop).
# --------------------------------------------------------------------------------------


def elastic_force(u: float, law: int, k1: float, kc: float, k2: float,
                  delta: float, delta_neg: float) -> tuple[float, float]:
    """Elastic force and tangent stiffness ``(F_el, dF_el/du)`` at deflection ``u``.

    ``law`` is the integer code of ``LAWS``. Thesis eq. 2.15-2.20; the piecewise law
    is symmetric (eq. 3.30) unless ``law`` is ``piecewise_asym``.
    """
    if law == LINEAR:
        return k1 * u, k1
    if law == CUBIC:
        return k1 * u + kc * u * u * u, k1 + 3.0 * kc * u * u
    # piecewise: a linear spring plus a spring (k2 - k1) behind a gap (eq. 3.30)
    if u > delta:
        return k1 * u + (k2 - k1) * (u - delta), k2
    dneg = delta_neg if law == PIECEWISE_ASYM else delta
    if u < -dneg:
        return k1 * u + (k2 - k1) * (u + dneg), k2
    return k1 * u, k1


def jenkins_update(u: float, w: float, kf: float, fs: float
                   ) -> tuple[float, float, float, bool]:
    """Return map of the macro-slip element for a new deflection ``u``.

    Parameters
    ----------
    u : float
        Deflection across the element at the end of the increment, m.
    w : float
        Committed slider position, m.
    kf : float
        Contact stiffness, N/m (> 0).
    fs : float
        Slip force mu * n0, N (>= 0).

    Returns
    -------
    force, w_new, dforce_du, slipping
        Friction force in N, slider position after the increment in m, consistent
        tangent in N/m (kf when stuck, 0 when slipping) and whether it slips.

    Notes
    -----
    Exact whenever u is monotonic inside the increment (thesis eq. 2.10-2.13).
    """
    trial = kf * (u - w)
    if trial > fs:
        return fs, u - fs / kf, 0.0, True
    if trial < -fs:
        return -fs, u + fs / kf, 0.0, True
    return trial, w, kf, False


def axis_force(u: float, v: float, w: float, law: int, k1: float, kc: float,
               k2: float, delta: float, delta_neg: float, c: float,
               kf: float, fs: float) -> tuple[float, float, float, float, bool, float]:
    """Total force of one axis for a trial motion, without committing anything.

    ``kf <= 0`` means no friction element. Returns
    ``(force, friction_force, w_new, dforce_du, slipping, dissipated)``: total force in
    N, friction force in N, slider position after the increment in m, tangent
    stiffness dF/du in N/m (the damping tangent dF/dv is ``c``), whether the slider
    slips, and the energy the slider dissipates in the increment from ``w`` to
    ``w_new`` in J (``fs * |w_new - w|``).
    """
    f_el, k_el = elastic_force(u, law, k1, kc, k2, delta, delta_neg)
    if kf > 0.0:
        f_fr, w_new, k_fr, slipping = jenkins_update(u, w, kf, fs)
        return (f_el + c * v + f_fr, f_fr, w_new, k_el + k_fr, slipping,
                fs * abs(w_new - w))
    return f_el + c * v, 0.0, w, k_el, False, 0.0


def axis_force_p(u: float, v: float, w: float, p: AxisParameters,
                 fs: float | None = None
                 ) -> tuple[float, float, float, float, bool, float]:
    """:func:`axis_force` with an :class:`AxisParameters`; ``fs`` overrides mu * n0."""
    return axis_force(u, v, w, p.law_code, p.k1, p.kc, p.k2, p.delta, p.delta_neg,
                      p.c, p.kf if p.friction else 0.0, p.fs if fs is None else fs)


def mount_force(u, v, w, p: MountParameters):
    """Evaluate all three axes of a mount: lists of the six :func:`axis_force` results.

    ``u``, ``v``, ``w`` are length-3 sequences in the order of ``AXES``. Returns
    ``(force, friction_force, w_new, dforce_du, slipping, dissipated)``, each a list of
    three values.
    """
    results = [axis_force_p(u[j], v[j], w[j], p.axes[j]) for j in range(3)]
    return tuple([r[i] for r in results] for i in range(6))
