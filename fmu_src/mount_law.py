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

The friction elements (macro-slip, non-symmetric and micro-slip Jenkins, the
inclined element of thesis Ch. 5, ...) are entries of the registry of
:mod:`fmu_src.friction` (:data:`FRICTION_ELEMENTS`, registered in
:mod:`fmu_src.friction_elements`), one module each (:mod:`fmu_src.jenkins`,
:mod:`fmu_src.inclined_element`). ``AxisParameters`` carries the fields of every
registered element and ``friction_kind`` names the one of the axis; :func:`axis_force`
calls its step.

A positive force is a tensile force along the axis: for u > 0 (engine moved in the
positive axis direction relative to the chassis) the elastic force is positive, and the
engine feels ``-F_j`` while the chassis feels ``+F_j``.

References: thesis eq. 2.10-2.13 (Jenkins element), 2.15-2.20 (elastic laws), 4.4
(radial stiffness = lambda * axial).
"""

from __future__ import annotations

import math
from dataclasses import field as _dc_field
from dataclasses import dataclass, fields, make_dataclass, replace
from typing import NamedTuple

from . import friction_elements  # noqa: F401  (registers the friction elements)
from .elastic_laws import (ELASTIC_LAWS, LAWS, ElasticLaw, law_code, law_name,
                           register_law)
from .friction import (FRICTION_ELEMENTS, FRICTION_KINDS, ElementStep,
                       FrictionElement, element_fields, friction_kind_code,
                       friction_kind_name)
from .jenkins import (MAX_SLIDERS, SliderStep, iwan_update, jenkins_update,
                      slider_bank, slider_update)
from .linear_branches import (FLUID_STATE, HYDRAULIC_FIELDS, MAX_MAXWELL,
                              HydraulicParameters, fluid_propagator,
                              fluid_relaxed, fluid_step, maxwell_step)

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
    "ElementStep",
    "FrictionElement",
    "FRICTION_ELEMENTS",
    "MAX_SLIDERS",
    "elastic_force",
    "jenkins_update",
    "slider_update",
    "iwan_update",
    "slider_bank",
    "initial_sliders",
    "mean_slider",
    "slider_position",
    "axis_force",
    "FRICTION_KINDS",
    "friction_kind_code",
    "friction_kind_name",
    "conform_state",
    "normal_forces",
    "static_force",
    "MAX_MAXWELL",
    "MAXWELL_FIELDS",
    "MaxwellAxisState",
    "flat_state",
    "without_maxwell",
    "HYDRAULIC_AXIS_FIELDS",
    "without_branches",
    "fluid_static",
]

#: Names of the three local axes of a mount, in the order used everywhere.
AXES = ("axial", "radial1", "radial2")


class ParameterError(ValueError):
    """Invalid mount parameters. ``problems`` lists every problem found."""

    def __init__(self, problems: list[str]):
        self.problems = list(problems)
        super().__init__("invalid mount parameters: " + "; ".join(self.problems))


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


#: The axis fields of the elastic law and the damper: (name, default, rule).
_LAW_FIELDS = (("law", "piecewise", None), ("k1", 91870.0, ">= 0"),
               ("kc", 0.0, ">= 0"), ("k2", 513800.0, ">= 0"),
               ("delta", 0.01225, "> 0"), ("delta_neg", 0.01225, "> 0"),
               ("c", 150.0, ">= 0"))

#: The Maxwell branches' axis fields (``maxwell_k<i>`` N/m, ``maxwell_c<i>`` N s/m,
#: i = 1..MAX_MAXWELL), appended after every element's fields; default 0: absent.
MAXWELL_FIELDS = tuple(f"maxwell_{q}{i}" for i in range(1, MAX_MAXWELL + 1)
                       for q in ("k", "c"))

#: The hydraulic fluid path's axis fields (``hyd_Ap`` m^2, ``hyd_C1``, ``hyd_C2``
#: m^5/N, ``hyd_I_i``, ``hyd_I_d`` kg/m^4, ``hyd_R_i``, ``hyd_R_d`` N s/m^5; the
#: fields of :class:`linear_branches.HydraulicParameters` after ``kr, br``: the
#: rubber is the axis's own elastic law and damper ``c``), appended after the
#: Maxwell fields; default 0, ``hyd_Ap = 0``: absent.
HYDRAULIC_AXIS_FIELDS = tuple(f"hyd_{name}" for name, _u, _d in HYDRAULIC_FIELDS[2:])
_HYD_POSITIVE = ("hyd_C1", "hyd_C2", "hyd_I_i")


class _Axis:
    """The methods of :class:`AxisParameters` (its fields come from the registries).
    """

    def __post_init__(self):
        problems = self.problems()
        if problems:
            raise ParameterError(problems)
        # the law's scalar force, looked up once (per-step hot path of axis_force)
        object.__setattr__(self, "elastic_force", ELASTIC_LAWS[self.law].force)
        el = FRICTION_ELEMENTS[self.friction_kind] if self.friction else None
        object.__setattr__(self, "element", el)
        object.__setattr__(self, "element_params", None if el is None else
                           (el.params(self) if el.params else self))
        # the element's step bound to these parameters (None without friction)
        object.__setattr__(self, "friction_step", None if el is None else el.bind(self))
        # the Maxwell branches (k, c) in FMU order, and whether any is present
        pairs = tuple((getattr(self, f"maxwell_k{i}"), getattr(self, f"maxwell_c{i}"))
                      for i in range(1, MAX_MAXWELL + 1))
        object.__setattr__(self, "maxwell", pairs)
        object.__setattr__(self, "has_maxwell",
                           any(k > 0.0 and c > 0.0 for k, c in pairs))
        # the hydraulic fluid path (None: absent); the rubber kr, br of
        # HydraulicParameters are 0 here: they are the axis's k1/law and c
        hyd = self.hyd_Ap > 0.0
        object.__setattr__(self, "has_hydraulic", hyd)
        object.__setattr__(self, "hydraulic", HydraulicParameters(
            0.0, 0.0, *(getattr(self, n) for n in HYDRAULIC_AXIS_FIELDS))
            if hyd else None)
        object.__setattr__(self, "has_branches", self.has_maxwell or hyd)
        object.__setattr__(self, "fluid_cache", {})   # dt -> fluid_propagator

    def problems(self, prefix: str = "") -> list[str]:
        """Every problem of these parameters, each naming field, value and rule."""
        out = []
        if self.law not in ELASTIC_LAWS:
            out.append(f"`{prefix}law` must be one of {', '.join(LAWS)}, "
                       f"got {self.law!r}")
        for name, _default, rule in _LAW_FIELDS[1:]:
            value = getattr(self, name)
            ok = _finite(value) and (value > 0 if rule == "> 0" else value >= 0)
            if not ok:
                out.append(f"`{prefix}{name}` must be finite and {rule}, got {value!r}")
        if not isinstance(self.friction, bool):
            out.append(f"`{prefix}friction` must be true or false, "
                       f"got {self.friction!r}")
        kind = self.friction_kind
        el = FRICTION_ELEMENTS.get(kind) if isinstance(kind, str) else None
        on = self.friction is True
        for f in element_fields():   # checked on every axis, on or off (Field.always)
            if f.always and (msg := f.problem(getattr(self, f.name), prefix,
                                              on=on)) is not None:
                out.append(msg)
        if el is None:
            out.append(f"`{prefix}friction_kind` must be one of "
                       f"{', '.join(FRICTION_KINDS)}, got {kind!r}")
        elif on:
            out += el.field_problems(self, prefix)
        for name in MAXWELL_FIELDS:
            value = getattr(self, name, 0.0)
            if not (_finite(value) and value >= 0):
                out.append(f"`{prefix}{name}` must be finite and >= 0 (a Maxwell "
                           f"branch; 0: absent), got {value!r}")
        ap = getattr(self, "hyd_Ap", 0.0)   # (an FMU's namespace may lack it)
        on_hyd = _finite(ap) and ap > 0.0
        for name in HYDRAULIC_AXIS_FIELDS:
            value = getattr(self, name, 0.0)
            if not (_finite(value) and value >= 0):
                out.append(f"`{prefix}{name}` must be finite and >= 0 (the hydraulic "
                           f"fluid path; hyd_Ap = 0: absent), got {value!r}")
            elif on_hyd and name in _HYD_POSITIVE and value == 0.0:
                out.append(f"`{prefix}{name}` must be > 0 when `{prefix}hyd_Ap` > 0 "
                           f"(a fluid mount needs two compliant chambers and an "
                           f"inertia track), got {value!r}")
        return out

    @property
    def inclined(self):
        """The inclined element's ``InclinedParameters`` (None unless this axis
        carries it): read by the HBM's fast form of that element."""
        return self.element_params if self.friction and \
            self.friction_kind == "inclined" else None

    @property
    def general_friction(self) -> bool:
        """Whether friction is on and is not the symmetric macro-slip element (the
        closed forms and the event-exact reference know only that one)."""
        return self.friction and self.fast_form != "symmetric_slider"

    @property
    def fast_form(self) -> str | None:
        """The name of the element's fast form in the HBM (None: the generic march;
        :attr:`FrictionElement.fast_form`); None without friction."""
        return self.element.fast_form(self) if self.friction else None

    @property
    def micro_slip(self) -> bool:
        """Whether friction is a bank of more than one slider."""
        return self.fast_form == "slider_bank" and self.sliders > 1

    @property
    def contact_stiffness(self) -> float:
        """Stiffest tangent of the friction element, N/m (0 without friction)."""
        return self.element.stuck_stiffness(self) if self.friction else 0.0

    @property
    def elastic(self) -> ElasticLaw:
        """The registered :class:`ElasticLaw` named by ``law``."""
        return ELASTIC_LAWS[self.law]

    @property
    def fs(self) -> float:
        """Slip force Fs = mu * n0 in N (0 without an element that reads the normal
        force), eq. 2.12."""
        return self.mu * self.n0 if self.friction and \
            self.element.uses_normal_input else 0.0

    @property
    def eps(self) -> float:
        """Slip displacement eps = Fs / kf in m, thesis eq. 2.13 (0 if no friction)."""
        return self.fs / self.kf if self.friction else 0.0

    def scaled(self, lam: float):
        """The same axis with stiffnesses and damping times ``lam`` (thesis eq. 4.4)."""
        if not (_finite(lam) and lam > 0):
            raise ParameterError([f"`lambda` must be finite and > 0, got {lam!r}"])
        mx = {name: getattr(self, name) * lam for name in MAXWELL_FIELDS}
        # the fluid's stiffness Ap^2 f(C, Z) scales by lam with C / lam, I, R * lam
        # (its notch and peak frequencies unchanged)
        mx.update({name: getattr(self, name) / lam if name in ("hyd_C1", "hyd_C2")
                   else getattr(self, name) * lam
                   for name in HYDRAULIC_AXIS_FIELDS if name != "hyd_Ap"})
        return replace(self, k1=self.k1 * lam, kc=self.kc * lam, k2=self.k2 * lam,
                       c=self.c * lam, **mx)

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def __reduce__(self):
        # pickled (process pools) and copied by its fields: the bound step and the
        # element are rebuilt from the registry, not pickled (closures)
        return (_rebuild_axis, (self.to_dict(),))


def _rebuild_axis(values: dict):
    """``AxisParameters(**values)`` (unpickling)."""
    return AxisParameters(**values)


def _axis_fields():
    """The dataclass fields of :class:`AxisParameters`: the elastic law's, the
    damper's, ``friction``, the first element's fields, ``friction_kind``, then the
    fields of the other registered elements (the historical FMU order)."""
    out = [(n, type(d), _dc_field(default=d)) for n, d, _ in _LAW_FIELDS]
    out.append(("friction", bool, _dc_field(default=False)))
    first = FRICTION_ELEMENTS[FRICTION_KINDS[0]].fields
    rest = [f for f in element_fields() if f not in first]
    out += [(f.name, type(f.default), _dc_field(default=f.default)) for f in first]
    out.append(("friction_kind", str, _dc_field(default=FRICTION_KINDS[0])))
    out += [(f.name, type(f.default), _dc_field(default=f.default)) for f in rest]
    out += [(name, float, _dc_field(default=0.0)) for name in MAXWELL_FIELDS]
    out += [(name, float, _dc_field(default=0.0)) for name in HYDRAULIC_AXIS_FIELDS]
    return out


AxisParameters = make_dataclass("AxisParameters", _axis_fields(), bases=(_Axis,),
                                frozen=True)
AxisParameters.__module__ = __name__
AxisParameters.__doc__ = """Parameters of one local axis of a mount (SI units).

    Defaults are the thesis's piecewise-linear fit (Sec. 2.4: k1 = 91 870 N/m,
    k2 = 513 800 N/m, delta = 0.01225 m) with values the thesis does not print:
    c = 150 N s/m (damping ratio about 3 % on a 70 kg engine), kf = 60 000 N/m and
    mu = 1 (only the slip force Fs = mu * n0 matters, so n0 reads as a slip force).
    Friction is off unless ``friction`` is true.

    Attributes
    ----------
    law : str
        ``"linear"``, ``"cubic"``, ``"piecewise"`` or ``"piecewise_asym"``.
    k1, kc, k2 : float
        Linear stiffness (N/m), cubic stiffness (N/m^3, ``cubic``), stiffness beyond
        the knee (N/m, the piecewise laws), all >= 0.
    delta, delta_neg : float
        Knee deflections for u > 0 and (``piecewise_asym``) u < 0, m, > 0.
    c : float
        Viscous damping, N s/m, >= 0.
    friction : bool
        Whether the axis has a friction element.
    friction_kind : str
        Its name in the registry (:data:`fmu_src.friction.FRICTION_KINDS`).
    <fields of the elements> :
        Every field of every registered element (:class:`fmu_src.friction.Field`:
        ``kf``, ``mu``, ``n0``, ``sliders``, ``spread``, ``fs_ratio`` of the Jenkins
        element, ``theta_deg``, ``k``, ``kf2``, ``mu1``, ``mu2``, ``preload`` of the
        inclined one, ...), with the element's defaults.
    """


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


def elastic_force(u: float, p: AxisParameters) -> tuple[float, float]:
    """Elastic force and tangent stiffness ``(F_el, dF_el/du)`` of axis ``p`` at ``u``.

    Looks the law up by its name ``p.law`` in :data:`ELASTIC_LAWS` (thesis eq.
    2.15-2.20).
    """
    return ELASTIC_LAWS[p.law].force(u, p)


def static_force(u: float, p: AxisParameters) -> tuple[float, float]:
    """Force and tangent ``(F, dF/du)`` of axis ``p`` at rest at ``u`` with its
    friction element relaxed (the static working point, ``hbm.static``): the elastic
    law plus the element's ``relaxed_force`` (a relaxed Jenkins element carries
    none, the inclined one its wedge spring and preload)."""
    f, k = p.elastic_force(u, p)
    if p.has_hydraulic:   # the fluid at rest: both chambers at Ap u / (C1 + C2)
        fh, kh = fluid_static(u, p)
        f, k = f + fh, k + kh
    if p.friction:
        fi, ki = p.element.relaxed_force(u, p)
        return f + fi, k + ki
    return f, k


def fluid_static(u: float, p: AxisParameters) -> tuple[float, float]:
    """Force and tangent of axis ``p``'s fluid at rest at ``u``: ``Ap^2 u / (C1 +
    C2)`` and ``Ap^2 / (C1 + C2)`` ((0, 0) without the hydraulic path)."""
    if not p.has_hydraulic:
        return 0.0, 0.0
    h = p.hydraulic
    k = h.Ap * h.Ap / (h.C1 + h.C2)
    return k * u, k


def initial_sliders(p: AxisParameters, w: float = 0.0):
    """The friction state of axis ``p`` relaxed at deflection ``w`` (m): the
    element's ``start`` (a float for the macro-slip element, a tuple of ``sliders``
    floats for the micro-slip one, ...); a float without friction. With Maxwell
    branches (``p.has_maxwell``) a :class:`MaxwellAxisState`, every branch relaxed
    at ``w`` too."""
    inner = p.element.start(p, w) if p.friction else float(w)
    if p.has_branches:
        return _maxwell_state(inner, float(w), (float(w),) * MAX_MAXWELL,
                              _fluid0(p, float(w)))
    return inner


def slider_position(p: AxisParameters, w) -> float:
    """The one number (m) of the friction state ``w`` of axis ``p`` (the FMU's
    ``w_<axis>``; the element's ``position``)."""
    if isinstance(w, MaxwellAxisState) and p.has_branches:
        w = _split(p, w)[0]
    return p.element.position(w) if p.friction else mean_slider(w)


def conform_state(p: AxisParameters, w):
    """``w`` if it is a friction state of axis ``p``'s element (a flat sequence of
    its ``state_size`` floats is read as one: a restored FMU state), else the state
    of :func:`initial_sliders` at its :func:`mean_slider` (e.g. after the
    parameters changed)."""
    if p.has_branches:
        return _conform_maxwell(p, w)
    el = p.element
    if el is None:
        return mean_slider(w)
    start = el.start(p, 0.0)
    if isinstance(w, (int, float)):
        flat = (w,) if isinstance(start, float) else None
    else:   # a state of another element keeps only its position
        ok = isinstance(w, list) or type(w) is type(start) or type(w) is tuple
        flat = w if ok else None
    state = None if flat is None else el.from_flat(p, flat)
    return el.start(p, mean_slider(w)) if state is None else state


def normal_forces(p: AxisParameters, w, n: float | None = None
                  ) -> tuple[float, float]:
    """Normal forces ``(N, N2)`` in N of axis ``p``'s friction element in state
    ``w`` (the state after an increment, e.g. ``axis_force(...).w_new``) under the
    normal-force input ``n`` (default ``n0``): the element's ``normal_forces``;
    (0, 0) without friction."""
    if not p.friction:
        return 0.0, 0.0
    if isinstance(w, MaxwellAxisState) and p.has_branches:
        w = _split(p, w)[0]
    return p.element.normal_forces(p, w, p.n0 if n is None else n)


def mean_slider(w) -> float:
    """One number of a friction state of unknown element: the state itself (a
    float); the committed deflection ``uc`` of a named state that has one; the
    mean of a tuple of slider positions (exactly the common one when all agree)."""
    if isinstance(w, (tuple, list)):
        if hasattr(w, "uc"):
            return w.uc
        first = w[0]
        if all(x == first for x in w):
            return first
        return math.fsum(w) / len(w)
    return w


def axis_force(u: float, v: float, w, p: AxisParameters, n: float | None = None,
               dt: float = 0.0) -> AxisForce:
    """Total force of one axis for a trial motion, without committing anything.

    ``u`` deflection (m), ``v`` its rate (m/s), ``w`` the committed friction state
    (:func:`initial_sliders`), ``p`` the axis; ``n`` the normal-force input (N,
    default ``p.n0``; negative: lost contact), ``dt`` the increment (s; read by
    rate-dependent elements only). Without a friction element (``p.friction``
    false) the state is ignored. With Maxwell branches (``p.has_maxwell``) ``w`` is
    a :class:`MaxwellAxisState` and their forces are part of ``force`` (not of
    ``friction_force``; their dissipation is not in ``dissipated``, which is the
    friction element's).
    """
    if p.has_branches:
        return _maxwell_axis_force(u, v, w, p, n, dt)
    f_el, k_el = p.elastic_force(u, p)
    step = p.friction_step
    if step is not None:
        f_fr, w_new, k_fr, _d, slipping, diss = step(w, u, v, p.n0 if n is None
                                                     else n, dt)
        return _new(AxisForce, (f_el + p.c * v + f_fr, f_fr, w_new, k_el + k_fr,
                                slipping, diss))
    return _new(AxisForce, (f_el + p.c * v, 0.0, w, k_el, False, 0.0))


# --------------------------------------------------------------------------------------
# Maxwell branches in parallel with the elastic law (fmu_src.linear_branches)
# --------------------------------------------------------------------------------------


class MaxwellAxisState(tuple):
    """The state of an axis with Maxwell branches: one flat tuple of floats, the
    friction element's state (its ``state_size`` floats; one placeholder float
    without friction), then the committed deflection ``uc`` (m) and the damper
    strokes ``w_1 .. w_MAX_MAXWELL`` (m) of the branches (an absent branch's stroke
    follows ``u``), then, with the hydraulic fluid path (``p.has_hydraulic``), the
    :data:`linear_branches.FLUID_STATE` fluid states ``x1, p2, q_i, q_d``. Flat, so
    that the FMU serializes it as a list and reads it back (:func:`conform_state`)."""

    __slots__ = ()


def _inner_size(p: AxisParameters) -> int:
    return p.element.state_size(p) if p.friction else 1


def _fluid0(p: AxisParameters, w: float) -> tuple:
    return fluid_relaxed(p.hydraulic, w) if p.has_hydraulic else ()


def _state_size(p: AxisParameters) -> int:
    return _inner_size(p) + 1 + MAX_MAXWELL + (FLUID_STATE if p.has_hydraulic else 0)


def _maxwell_state(inner, uc: float, branches, fluid=()) -> MaxwellAxisState:
    flat = (inner,) if isinstance(inner, float) else tuple(inner)
    return tuple.__new__(MaxwellAxisState, flat + (uc,) + tuple(branches)
                         + tuple(fluid))


def _split(p: AxisParameters, w: MaxwellAxisState):
    """``(friction state, uc, branch strokes)`` of ``w`` (the fluid: ``_fluid``)."""
    n = _inner_size(p)
    if not p.friction:
        inner = w[0]
    elif n == 1:
        inner = w[0]
    else:
        inner = p.element.from_flat(p, w[:n])
    return inner, w[n], w[n + 1:n + 1 + MAX_MAXWELL]


def _conform_maxwell(p: AxisParameters, w) -> MaxwellAxisState:
    """:func:`conform_state` of an axis with Maxwell branches: a flat sequence of
    the right length is read as a state (a restored FMU state); a state without
    branches keeps its friction state, the branches relaxed at its position;
    anything else is relaxed at its mean."""
    n = _inner_size(p)
    if isinstance(w, (tuple, list)) and not hasattr(w, "_fields") \
            and len(w) == _state_size(p) \
            and all(isinstance(x, (int, float)) for x in w):
        flat = tuple(float(x) for x in w)
        inner = flat[0] if n == 1 else p.element.from_flat(p, flat[:n])
        if inner is not None:
            return tuple.__new__(MaxwellAxisState, flat)
    if isinstance(w, MaxwellAxisState):
        return initial_sliders(p, mean_slider(tuple(w)))
    q = without_branches(p)
    inner = conform_state(q, w)
    x = slider_position(q, inner)
    return _maxwell_state(inner, x, (x,) * MAX_MAXWELL, _fluid0(p, x))


def _maxwell_axis_force(u, v, w, p, n, dt) -> AxisForce:
    if not isinstance(w, MaxwellAxisState):
        w = _conform_maxwell(p, w)
    inner, uc, strokes = _split(p, w)
    f_el, k_el = p.elastic_force(u, p)
    f_m = k_m = 0.0
    new = []
    for (k, c), w0 in zip(p.maxwell, strokes):
        f, w1, kt = maxwell_step(k, c, uc, w0, u, dt)
        f_m += f
        k_m += kt
        new.append(w1)
    step = p.friction_step
    if step is not None:
        f_fr, inner, k_fr, _d, slipping, diss = step(inner, u, v, p.n0 if n is None
                                                     else n, dt)
    else:
        f_fr, k_fr, slipping, diss = 0.0, 0.0, False, 0.0
    fluid = ()
    if p.has_hydraulic:
        f_h, fluid, k_h = _fluid_step(p, w, uc, u, dt)
        f_m += f_h
        k_m += k_h
    return _new(AxisForce, (f_el + p.c * v + f_fr + f_m, f_fr,
                            _maxwell_state(inner, u, new, fluid), k_el + k_fr + k_m,
                            slipping, diss))


def _fluid_step(p: AxisParameters, w, uc: float, u: float, dt: float):
    """The exact fluid step (:func:`linear_branches.fluid_step`) of the fluid states
    at the end of ``w``; the propagator of ``dt`` cached on the axis."""
    x0 = w[len(w) - FLUID_STATE:]
    prop = None
    if dt > 0.0:
        prop = p.fluid_cache.get(dt)
        if prop is None:
            if len(p.fluid_cache) > 64:
                p.fluid_cache.clear()
            prop = p.fluid_cache[dt] = fluid_propagator(p.hydraulic, dt)
    return fluid_step(p.hydraulic, prop, x0, uc, u, dt)


def flat_state(w) -> float | list[float]:
    """A committed axis state as the FMU serializes it: a float, or a flat list of
    floats (:func:`conform_state` reads it back)."""
    return list(w) if isinstance(w, tuple) else w


def without_maxwell(p: AxisParameters) -> AxisParameters:
    """Axis ``p`` without its Maxwell branches (the HBM and ``characterise`` add
    them exactly in the frequency domain, :mod:`fmu_src.linear_branches`)."""
    if not p.has_maxwell:
        return p
    return replace(p, **{name: 0.0 for name in MAXWELL_FIELDS})


def without_branches(p: AxisParameters) -> AxisParameters:
    """Axis ``p`` without its Maxwell branches and its hydraulic fluid path (the
    static equilibrium adds the fluid at rest, :func:`fluid_static`)."""
    if not p.has_branches:
        return p
    return replace(p, **{name: 0.0 for name in MAXWELL_FIELDS + HYDRAULIC_AXIS_FIELDS})
