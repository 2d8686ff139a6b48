"""The inclined two-surface element of thesis Ch. 5 as a friction element of a mount
axis (``friction_kind = "inclined"``): its declaration for the registry.

The element's law is :mod:`fmu_src.inclined`; here it is put on an axis. Its normal
forces follow from its kinematics (``n0``, ``mu`` and the normal-force input are not
used). Its state is an :class:`fmu_src.inclined.InclinedState` (sliders ``w1``, ``w2``
and the committed deflection); its force (N2, along the axis) is the friction force of
the axis. The wedge is pressed in when the axis is compressed (element deflection
``x = -u``) and pushes the sides apart (axis force ``-N2``). Standard library only.
"""

from __future__ import annotations

import math

from .friction import ElementStep, Field, FrictionElement
from .inclined import (INCLINED_FIELDS, InclinedParameters, axis_normal_forces,
                       axis_step, relaxed_force, relaxed_state, stuck_stiffness)

__all__ = ["INCLINED", "inclined_parameters"]

_new = tuple.__new__


def inclined_parameters(p) -> InclinedParameters:
    """The :class:`InclinedParameters` of axis ``p``'s fields (checked)."""
    return InclinedParameters(**{f: getattr(p, f) for f in INCLINED_FIELDS})


def _unchecked(p) -> InclinedParameters:
    obj = object.__new__(InclinedParameters)  # problems() reads attributes only
    for f in INCLINED_FIELDS:
        object.__setattr__(obj, f, getattr(p, f))
    return obj


def _problems(p, prefix: str) -> list[str]:
    """``InclinedParameters.problems`` on the axis's fields, plus: micro-slip and
    non-symmetric friction belong to the Jenkins element."""
    out = _unchecked(p).problems(prefix)
    if p.sliders != 1 or p.fs_ratio != 1.0:
        out.append(f"`{prefix}sliders` = {p.sliders!r} and `{prefix}fs_ratio` = "
                   f"{p.fs_ratio!r}: micro-slip and non-symmetric friction belong to "
                   f"the Jenkins element; the inclined element needs sliders = 1 and "
                   f"fs_ratio = 1")
    return out


def _bind(p):
    q = p.element_params

    def step(state, u, v, n, dt):   # element coordinates x = -u, F = -N2
        st, w_new = axis_step(u, state, q)
        return _new(ElementStep, (-st.force, w_new, st.tangent, 0.0,
                                  st.slip1 or st.slip2, st.dissipated))
    return step


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and not math.isnan(x)


def _rule(ok):
    return lambda v: _num(v) and ok(v)


_D = InclinedParameters
INCLINED = FrictionElement(
    name="inclined",
    summary="inclined two-surface element of thesis Ch. 5 (normal forces from its "
            "kinematics; its kf is the inclined surface's contact stiffness)",
    fields=(
        Field("theta_deg", "Real", "deg", _D.theta_deg, "in (0, 90] degrees",
              _rule(lambda v: 0 < v <= 90), "inclined element: angle of the "
              "inclined surface to the plate, in (0, 90]", required=True),
        Field("k", "Real", "N/m", _D.k, "finite and >= 0",
              _rule(lambda v: 0 <= v < math.inf), "inclined element: stiffness of "
              "the elastic pieces pushing the wedge, >= 0", required=True),
        Field("kf", "Real", "N/m", _D.kf, "finite and > 0",
              _rule(lambda v: 0 < v < math.inf), "contact stiffness of the friction "
              "element, > 0 if friction", required=True, always=True),
        Field("kf2", "Real", "N/m", _D.kf2, "finite and > 0",
              _rule(lambda v: 0 < v < math.inf), "inclined element: contact "
              "stiffness of the flat surface, > 0", required=True),
        Field("mu1", "Real", "1", _D.mu1, ">= 0 (inf = bonded)",
              _rule(lambda v: v >= 0), "inclined element: friction coefficient of "
              "the inclined surface, >= 0 (inf: bonded)", required=True),
        Field("mu2", "Real", "1", _D.mu2, ">= 0 (inf = bonded)",
              _rule(lambda v: v >= 0), "inclined element: friction coefficient of "
              "the flat surface, >= 0 (inf: bonded)", required=True),
        Field("preload", "Real", "N", _D.preload, "finite and >= 0",
              _rule(lambda v: 0 <= v < math.inf), "inclined element: force of the "
              "elastic pieces at u = 0, >= 0", required=True),
    ),
    bind=_bind,
    state_size=lambda p: 3,
    start=lambda p, w=0.0: relaxed_state(p.element_params, w),
    position=lambda state: state.uc,
    stuck_stiffness=lambda p: stuck_stiffness(p.element_params),
    normal_forces=lambda p, state, n: axis_normal_forces(state, p.element_params),
    uses_normal_input=False,
    problems=_problems,
    relaxed_force=lambda u, p: relaxed_force(u, p.element_params),
    params=inclined_parameters,
    fast_form=lambda p: "inclined",
    c_port="ml_inclined",
    # the sliders of the inclined surface (w1) and of the flat one (w2), element
    # coordinates: a state that is not relaxed (the engine lowered onto the mount)
    slider_slots=lambda p: (0, 1),
)
