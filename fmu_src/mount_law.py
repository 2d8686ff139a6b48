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

Non-symmetric friction (``fs_ratio``): the slider slips at ``+Fs`` in the positive and
at ``-fs_ratio * Fs`` in the negative direction (:func:`slider_update`).

Micro-slip (``sliders`` = S > 1): an Iwan element, S Jenkins elements in parallel,
fitted to the macro-slip element (kf, Fs): slider i = 0..S-1 has stiffness kf / S and
slip displacement eps_i = eps r_i, r_i = 1 + spread ((2 i + 1) / S - 1), so its slip
force is Fs r_i / S. The r_i are uniform on [1 - spread, 1 + spread] with mean 1: the
total stiffness is kf, the full-slip force is Fs, and spread = 0 is the macro-slip
element. Its state is the tuple of the S slider positions (:func:`iwan_update`).

Inclined two-surface element (``friction_kind = "inclined"``, thesis Ch. 5): the
friction element of the axis is the wedge of :mod:`fmu_src.inclined` (parameters
``theta_deg``, ``k``, ``kf``, ``kf2``, ``mu1``, ``mu2``, ``preload``), whose normal
forces follow from its kinematics (``n0``, ``mu`` and the normal-force input are not
used). Its state is an :class:`fmu_src.inclined.InclinedState` (sliders ``w1``, ``w2``
and the committed deflection); its force (N2, along the axis) is the friction force
of the axis. The wedge is pressed in when the axis is compressed (element deflection
``x = -u``) and pushes the sides apart (axis force ``-N2``).

A positive force is a tensile force along the axis: for u > 0 (engine moved in the
positive axis direction relative to the chassis) the elastic force is positive, and the
engine feels ``-F_j`` while the chassis feels ``+F_j``.

References: thesis eq. 2.10-2.13 (Jenkins element), 2.15-2.20 (elastic laws), 4.4
(radial stiffness = lambda * axial).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import NamedTuple

from .elastic_laws import (ELASTIC_LAWS, LAWS, ElasticLaw, law_code, law_name,
                           register_law)
from .inclined import (INCLINED_FIELDS, InclinedParameters, InclinedState,
                       axis_normal_forces, axis_step, relaxed_force, relaxed_state,
                       stuck_stiffness)

__all__ = [
    "AXES",
    "LAWS",
    "ELASTIC_LAWS",
    "ElasticLaw",
    "register_law",
    "law_code",
    "law_name",
    "AxisParameters",
    "MountParameters",
    "ParameterError",
    "AxisForce",
    "SliderStep",
    "MAX_SLIDERS",
    "elastic_force",
    "jenkins_update",
    "slider_update",
    "iwan_update",
    "slider_bank",
    "initial_sliders",
    "mean_slider",
    "axis_force",
    "FRICTION_KINDS",
    "friction_kind_code",
    "friction_kind_name",
    "conform_state",
    "normal_forces",
    "static_force",
]

#: The friction elements of an axis, in the order of the FMU's ``<axis>_friction_kind``
#: code: the Jenkins/Iwan element (macro- or micro-slip) and the inclined element.
FRICTION_KINDS = ("jenkins", "inclined")


def friction_kind_code(name: str) -> int:
    """The FMU's integer ``<axis>_friction_kind`` of ``name``."""
    return FRICTION_KINDS.index(name)


def friction_kind_name(code) -> str | None:
    """The friction kind of the FMU's integer code; None if invalid."""
    if isinstance(code, int) and not isinstance(code, bool) \
            and 0 <= code < len(FRICTION_KINDS):
        return FRICTION_KINDS[code]
    return None

#: Largest number of sliders of a micro-slip (Iwan) element.
MAX_SLIDERS = 64

#: Names of the three local axes of a mount, in the order used everywhere.
AXES = ("axial", "radial1", "radial2")


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
    sliders : int
        Number of Jenkins elements of the micro-slip (Iwan) element, 1 to
        ``MAX_SLIDERS`` (1: the macro-slip element).
    spread : float
        Half-width of the uniform slip-displacement distribution of the sliders
        relative to eps = Fs / kf, in [0, 1) (0: all sliders slip together).
    fs_ratio : float
        Slip force in the negative direction over the one in the positive direction,
        >= 0 (1: symmetric friction).
    friction_kind : str
        ``"jenkins"`` (the macro-/micro-slip element above) or ``"inclined"`` (the
        two-surface element of thesis Ch. 5, :mod:`fmu_src.inclined`; ``kf`` is then
        its inclined surface's contact stiffness).
    theta_deg : float
        Inclined element: angle of the inclined surface to the plate, deg, (0, 90].
    k : float
        Inclined element: stiffness of the elastic pieces pushing the wedge, N/m.
    kf2 : float
        Inclined element: contact stiffness of the flat surface, N/m, > 0.
    mu1, mu2 : float
        Inclined element: friction coefficients of the inclined and of the flat
        surface, >= 0 (``inf``: bonded).
    preload : float
        Inclined element: force of the elastic pieces at u = 0, N, >= 0.
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
    sliders: int = 1
    spread: float = 0.0
    fs_ratio: float = 1.0
    friction_kind: str = "jenkins"
    # the inclined element's fields, with its defaults (fmu_src.inclined)
    theta_deg: float = InclinedParameters.theta_deg
    k: float = InclinedParameters.k
    kf2: float = InclinedParameters.kf2
    mu1: float = InclinedParameters.mu1
    mu2: float = InclinedParameters.mu2
    preload: float = InclinedParameters.preload

    def __post_init__(self):
        problems = self.problems()
        if problems:
            raise ParameterError(problems)
        # the law's scalar force, looked up once (per-step hot path of axis_force)
        object.__setattr__(self, "elastic_force", ELASTIC_LAWS[self.law].force)
        # the inclined element's parameters (None unless this axis carries it)
        object.__setattr__(self, "inclined", InclinedParameters(
            **{f: getattr(self, f) for f in INCLINED_FIELDS})
            if self.friction and self.friction_kind == "inclined" else None)
        # friction beyond the symmetric macro-slip element (micro-slip, fs_ratio or
        # the inclined element)
        object.__setattr__(self, "general_friction",
                           self.sliders > 1 or self.fs_ratio != 1.0
                           or self.inclined is not None)

    def problems(self, prefix: str = "") -> list[str]:
        """Every problem of these parameters, each naming field, value and rule."""
        out = []
        if self.law not in ELASTIC_LAWS:
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
            ("fs_ratio", ">= 0"),
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
        n = self.sliders
        if not (isinstance(n, int) and not isinstance(n, bool)
                and 1 <= n <= MAX_SLIDERS):
            out.append(f"`{prefix}sliders` must be an integer from 1 to {MAX_SLIDERS} "
                       f"(the number of Jenkins elements of the micro-slip element), "
                       f"got {n!r}")
        if not (_finite(self.spread) and 0.0 <= self.spread < 1.0):
            out.append(f"`{prefix}spread` must be finite and in [0, 1) (half-width of "
                       f"the sliders' slip displacements / eps), got {self.spread!r}")
        if self.friction_kind not in FRICTION_KINDS:
            out.append(f"`{prefix}friction_kind` must be one of "
                       f"{', '.join(FRICTION_KINDS)}, got {self.friction_kind!r}")
        elif self.friction_kind == "inclined" and self.friction is True:
            out += _inclined_problems(self, prefix)
        return out

    @property
    def micro_slip(self) -> bool:
        """Whether friction is a micro-slip (Iwan) element (``sliders`` > 1)."""
        return self.friction and self.sliders > 1 and self.friction_kind == "jenkins"

    @property
    def contact_stiffness(self) -> float:
        """Stiffest tangent of the friction element, N/m (0 without friction): ``kf``
        of the Jenkins element, the both-stuck tangent of the inclined one."""
        if not self.friction:
            return 0.0
        return stuck_stiffness(self.inclined) if self.inclined else self.kf

    @property
    def elastic(self) -> ElasticLaw:
        """The registered :class:`ElasticLaw` named by ``law``."""
        return ELASTIC_LAWS[self.law]

    @property
    def fs(self) -> float:
        """Slip force Fs = mu * n0 in N (0 without a Jenkins element), eq. 2.12."""
        return self.mu * self.n0 if self.friction and self.inclined is None else 0.0

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


def _inclined_problems(p, prefix: str) -> list[str]:
    """The inclined element's checks (``InclinedParameters.problems``) on the axis's
    fields, plus: micro-slip and non-symmetric friction are Jenkins-only."""
    unchecked = object.__new__(InclinedParameters)  # problems() reads attributes only
    for f in INCLINED_FIELDS:
        object.__setattr__(unchecked, f, getattr(p, f))
    out = unchecked.problems(prefix)
    if p.sliders != 1 or p.fs_ratio != 1.0:
        out.append(f"`{prefix}sliders` = {p.sliders!r} and `{prefix}fs_ratio` = "
                   f"{p.fs_ratio!r}: micro-slip and non-symmetric friction belong to "
                   f"the Jenkins element; the inclined element needs sliders = 1 and "
                   f"fs_ratio = 1")
    return out


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


class AxisForce(NamedTuple):
    """One axis's force for a trial motion (:func:`axis_force`); nothing committed.

    Attributes
    ----------
    force : float
        Total force, N.
    friction_force : float
        Force of the Jenkins element, N.
    w_new : float
        Slider position after the increment, m.
    tangent : float
        dF/du, N/m (the damping tangent dF/dv is ``c``).
    slipping : bool
        Whether the slider slips.
    dissipated : float
        Energy the slider dissipates from ``w`` to ``w_new``, J (``Fs |w_new - w|``).
    """

    force: float
    friction_force: float
    w_new: float
    tangent: float
    slipping: bool
    dissipated: float


#: ``_new(NamedTupleClass, values)``: one C call (the generated ``__new__`` is Python
#: code, about 3x slower in the per-step law).
_new = tuple.__new__


class SliderStep(NamedTuple):
    """Return map of the macro-slip element (:func:`jenkins_update`)."""

    force: float
    w_new: float
    tangent: float
    slipping: bool


def elastic_force(u: float, p: AxisParameters) -> tuple[float, float]:
    """Elastic force and tangent stiffness ``(F_el, dF_el/du)`` of axis ``p`` at ``u``.

    Looks the law up by its name ``p.law`` in :data:`ELASTIC_LAWS` (thesis eq.
    2.15-2.20).
    """
    return ELASTIC_LAWS[p.law].force(u, p)


def static_force(u: float, p: AxisParameters) -> tuple[float, float]:
    """Force and tangent ``(F, dF/du)`` of axis ``p`` at rest at ``u`` with its
    friction element relaxed (the static working point, ``hbm.static``): the elastic
    law, plus the inclined element's relaxed force
    (:func:`fmu_src.inclined.relaxed_force`; a relaxed Jenkins element carries none).
    """
    f, k = p.elastic_force(u, p)
    if p.inclined is not None:
        fi, ki = relaxed_force(u, p.inclined)
        return f + fi, k + ki
    return f, k


def jenkins_update(u: float, w: float, kf: float, fs: float) -> SliderStep:
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
    SliderStep
        ``(force, w_new, tangent, slipping)``: friction force in N, slider position
        after the increment in m, consistent tangent in N/m (kf when stuck, 0 when
        slipping) and whether it slips.

    Notes
    -----
    Exact whenever u is monotonic inside the increment (thesis eq. 2.10-2.13).
    """
    trial = kf * (u - w)
    if trial > fs:
        return _new(SliderStep, (fs, u - fs / kf, 0.0, True))
    if trial < -fs:
        return _new(SliderStep, (-fs, u + fs / kf, 0.0, True))
    return _new(SliderStep, (trial, w, kf, False))


def slider_update(u: float, w: float, kf: float, fs_pos: float, fs_neg: float
                  ) -> SliderStep:
    """Return map of a Jenkins element with non-symmetric slip forces.

    As :func:`jenkins_update`, but the slider slips at ``+fs_pos`` when pulled in the
    positive direction and at ``-fs_neg`` in the negative one (both N, >= 0).
    """
    trial = kf * (u - w)
    if trial > fs_pos:
        return _new(SliderStep, (fs_pos, u - fs_pos / kf, 0.0, True))
    if trial < -fs_neg:
        return _new(SliderStep, (-fs_neg, u + fs_neg / kf, 0.0, True))
    return _new(SliderStep, (trial, w, kf, False))


def slider_bank(p: AxisParameters, fs: float | None = None
                ) -> tuple[tuple[float, float, float], ...]:
    """``(k_i, fs_pos_i, fs_neg_i)`` of every slider of axis ``p``'s friction element.

    ``fs`` overrides the slip force ``p.fs`` (the normal-force input). One slider
    ``(kf, Fs, fs_ratio Fs)`` for the macro-slip element; for ``sliders`` = S > 1
    the Iwan fit of the module docstring: ``k_i = kf / S``, ``fs_pos_i = Fs r_i / S``.
    """
    if fs is None:
        fs = p.mu * p.n0
    n = p.sliders
    k = p.kf / n
    out = []
    for i in range(n):
        r = 1.0 + p.spread * ((2 * i + 1) / n - 1.0)
        out.append((k, fs * r / n, fs * r * p.fs_ratio / n))
    return tuple(out)


def initial_sliders(p: AxisParameters, w: float = 0.0):
    """The friction state of axis ``p`` with every slider at ``w`` (m): a float for
    the macro-slip element, a tuple of ``sliders`` floats for the micro-slip one, the
    element relaxed at deflection ``w`` for the inclined one
    (:func:`fmu_src.inclined.relaxed_state`)."""
    if p.inclined is not None:
        return relaxed_state(p.inclined, w)
    return tuple([float(w)] * p.sliders) if p.micro_slip else float(w)


def conform_state(p: AxisParameters, w):
    """``w`` if it is a friction state of axis ``p``'s kind, else the state of
    :func:`initial_sliders` at its :func:`mean_slider` (e.g. after the parameters
    changed). A plain 3-sequence is read as an inclined state ``(w1, w2, uc)`` on an
    inclined axis (a restored FMU state)."""
    if p.inclined is not None:
        if isinstance(w, InclinedState):
            return w
        if isinstance(w, (tuple, list)) and len(w) == 3:
            return InclinedState(*(float(x) for x in w))
        return initial_sliders(p, mean_slider(w))
    if isinstance(w, InclinedState):
        return initial_sliders(p, w.uc)
    n = p.sliders if p.micro_slip else 1
    if isinstance(w, (tuple, list)):
        return tuple(float(x) for x in w) if len(w) == n > 1 \
            else initial_sliders(p, mean_slider(tuple(w)))
    return initial_sliders(p, w) if n > 1 else w


def normal_forces(p: AxisParameters, w, fs: float | None = None
                  ) -> tuple[float, float]:
    """Normal forces ``(N, N2)`` in N of axis ``p``'s friction element in state ``w``
    (the state after an increment, e.g. ``axis_force(...).w_new``): the inclined
    element's two contacts (from its kinematics); the Jenkins element's contact
    force ``fs / mu`` (``fs`` the slip force used, default ``mu n0``) and 0; (0, 0)
    without friction."""
    if not p.friction:
        return 0.0, 0.0
    if p.inclined is not None:
        return axis_normal_forces(w, p.inclined)
    if fs is None:
        return p.n0, 0.0
    return (fs / p.mu if p.mu > 0 else p.n0), 0.0


def mean_slider(w) -> float:
    """Mean slider position (m) of a friction state (float or tuple); exactly the
    common position when every slider is at the same one; the committed deflection
    ``uc`` of an inclined state."""
    if isinstance(w, InclinedState):
        return w.uc
    if isinstance(w, tuple):
        first = w[0]
        if all(x == first for x in w):
            return first
        return math.fsum(w) / len(w)
    return w


def iwan_update(u: float, w: tuple[float, ...], bank) -> AxisForce:
    """Return map of the micro-slip (Iwan) element: parallel sliders of ``bank``.

    ``w`` holds the committed slider positions (m), ``bank`` the
    ``(k_i, fs_pos_i, fs_neg_i)`` of :func:`slider_bank`. Returns an
    :class:`AxisForce` of the friction element alone: ``force`` = ``friction_force``
    (N), ``w_new`` a tuple, ``tangent`` the sum of the stuck sliders' stiffnesses,
    ``slipping`` whether any slider slips, ``dissipated`` the sum of each slider's
    slip force times its slide (J).
    """
    f = kt = diss = 0.0
    slipping = False
    w_new = []
    for wi, (k, fp, fn) in zip(w, bank):
        trial = k * (u - wi)
        if trial > fp:
            wn = u - fp / k
            f += fp
            diss += fp * (wn - wi)
            slipping = True
        elif trial < -fn:
            wn = u + fn / k
            f -= fn
            diss += fn * (wi - wn)
            slipping = True
        else:
            wn = wi
            f += trial
            kt += k
        w_new.append(wn)
    return _new(AxisForce, (f, f, tuple(w_new), kt, slipping, diss))


def _friction(u: float, w, p: AxisParameters, fs: float):
    """Friction of a non-symmetric, micro-slip or inclined axis: (force, w_new,
    tangent, slipping, dissipated)."""
    if p.inclined is not None:   # element coordinates x = -u, F = -N2 (inclined.py)
        st, w_new = axis_step(u, w, p.inclined)
        return -st.force, w_new, st.tangent, st.slip1 or st.slip2, st.dissipated
    if p.sliders > 1:
        r = iwan_update(u, w, slider_bank(p, fs))
        return r[0], r[2], r[3], r[4], r[5]
    fn = fs * p.fs_ratio
    f, w_new, k, slipping = slider_update(u, w, p.kf, fs, fn)
    return f, w_new, k, slipping, (fs if w_new > w else fn) * abs(w_new - w)


def axis_force(u: float, v: float, w: float, p: AxisParameters,
               fs: float | None = None) -> AxisForce:
    """Total force of one axis for a trial motion, without committing anything.

    ``u`` deflection (m), ``v`` its rate (m/s), ``w`` the committed slider position
    (m; a tuple of the slider positions for a micro-slip axis, see
    :func:`initial_sliders`), ``p`` the axis; ``fs`` overrides the slip force ``p.fs``
    (the FMU's normal-force input). Without a friction element (``p.friction`` false)
    the slider is ignored.
    """
    f_el, k_el = p.elastic_force(u, p)
    if p.friction:
        if fs is None:
            fs = p.mu * p.n0
        if p.general_friction:
            f_fr, w_new, k_fr, slipping, diss = _friction(u, w, p, fs)
            return _new(AxisForce, (f_el + p.c * v + f_fr, f_fr, w_new, k_el + k_fr,
                                    slipping, diss))
        f_fr, w_new, k_fr, slipping = jenkins_update(u, w, p.kf, fs)
        return _new(AxisForce, (f_el + p.c * v + f_fr, f_fr, w_new, k_el + k_fr,
                                slipping, fs * abs(w_new - w)))
    return _new(AxisForce, (f_el + p.c * v, 0.0, w, k_el, False, 0.0))
