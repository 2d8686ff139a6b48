"""The FrictionMount FMU's interface: one table of variables, units and capabilities.

Everything that names an FMU variable reads it from here: the PythonFMU slave
(``fmu_src/friction_mount.py``), the builder (``fmu_build``), the configuration's unit
handling (``drymount/config``) and the harness's FMU backend (``vehicle/backends.py``).
``VARIABLES`` is in value-reference order (``vr`` = index). Standard library only: this
module ships inside the FMU.

Per axis in ``AXES`` (``axial``, ``radial1``, ``radial2``): parameters
``<axis>_<field>`` (the fields of :class:`fmu_src.mount_law.AxisParameters`; ``law`` as
its integer code, :func:`fmu_src.mount_law.law_code`), inputs ``u_``, ``v_``, ``n_``,
outputs ``F_``, ``Ffr_``, ``kt_``, ``slip_``, ``E_fr_``; then the output ``E_fr`` (all
axes) and the locals ``w_<axis>`` (committed slider positions); then, appended so that
the earlier value references stay, ``<axis>_friction_kind`` with the fields of the
second registered friction element (:data:`INCLINED_PARAMETER_FIELDS`) and the
outputs ``N_<axis>``, ``N2_<axis>`` (normal forces of the friction contacts); then the
new fields of every later element (:data:`LATER_PARAMETER_FIELDS`); then the outputs
about the last step ``slipped_``, ``dE_fr_``, ``ks_<axis>``
(``fmu_src/step_record.py``); then the locals
``w1_<axis>``, ``w2_<axis>`` (:data:`SLIDER_SLOTS` slider positions of the element,
which start it with these sliders: a state that is not relaxed). The friction
fields' rows are generated from the element declarations
(:class:`fmu_src.friction.Field`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .friction import FRICTION_ELEMENTS
from .jenkins import MAX_SLIDERS
from .linear_branches import HYDRAULIC_FIELDS
from .mount_law import (AXES, LAWS, MAX_MAXWELL, AxisParameters,
                        friction_kind_code, law_code)

__all__ = ["Variable", "VARIABLES", "BASE_UNITS", "CAPABILITIES",
           "DEFAULT_EXPERIMENT", "MODEL_NAME", "PARAMETER_FIELDS", "variable",
           "by_causality", "parameter_unit", "INCLINED_PARAMETER_FIELDS",
           "ALL_PARAMETER_FIELDS", "LATER_PARAMETER_FIELDS", "declared_bounds",
           "MAXWELL_PARAMETER_FIELDS", "SLIDER_SLOTS", "SLIDER_SLOT_NAMES",
           "HYDRAULIC_PARAMETER_FIELDS"]

MODEL_NAME = "FrictionMount"


@dataclass(frozen=True)
class Variable:
    """One FMI 2.0 ScalarVariable of the FMU.

    Attributes
    ----------
    name : str
        FMU variable name (== the slave's attribute), e.g. ``"axial_k1"``.
    type : str
        ``"Real"``, ``"Integer"`` or ``"Boolean"``.
    causality : str
        ``"parameter"``, ``"input"``, ``"output"``, ``"local"`` or ``"independent"``.
    variability : str
        ``"fixed"``, ``"tunable"``, ``"continuous"``, ``"discrete"`` or ``"constant"``.
    start : float, int, bool or None
        Start value (None: the model description has none).
    unit : str or None
        A key of :data:`BASE_UNITS` (Real variables only).
    description : str
    initial : str or None
        ``"exact"``, ``"calculated"``, ``"approx"`` or None (FMI default).
    """

    name: str
    type: str
    causality: str
    variability: str
    start: float | int | bool | None
    unit: str | None
    description: str
    initial: str | None = None


#: SI exponents of every unit the model description uses (FMI 2.0 ``BaseUnit``).
BASE_UNITS: dict[str, dict[str, int]] = {
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "N/m3": {"kg": 1, "m": -2, "s": -2},
    "N.s/m": {"kg": 1, "s": -1},
    "J": {"kg": 1, "m": 2, "s": -2},
    "1": {},
    "deg": {"rad": 1, "factor": 0.017453292519943295},  # pi / 180
    "m2": {"m": 2},                               # the hydraulic mount's units
    "m5/N": {"kg": -1, "m": 4, "s": 2},
    "kg/m4": {"kg": 1, "m": -4},
    "N.s/m5": {"kg": 1, "m": -4, "s": -1},
}

#: CoSimulation capability flags of the model description.
CAPABILITIES: dict[str, bool] = {
    "needsExecutionTool": False,
    "canHandleVariableCommunicationStepSize": True,
    "canBeInstantiatedOnlyOncePerProcess": False,
    "canGetAndSetFMUstate": True,
    "canSerializeFMUstate": True,
}

DEFAULT_EXPERIMENT: dict[str, float] = {
    "startTime": 0.0, "stopTime": 1.0, "stepSize": 1e-4, "tolerance": 1e-6}

#: Slider positions of a friction element the FMU shows and sets as the locals
#: ``w1_<axis>`` .. ``w<SLIDER_SLOTS>_<axis>`` (``FrictionElement.slider_slots``).
SLIDER_SLOTS = 2
#: The quantities of those locals: ``w1``, ``w2`` (``w1_<axis>`` without its axis).
SLIDER_SLOT_NAMES = tuple(f"w{k}" for k in range(1, SLIDER_SLOTS + 1))
_SLOT_TEXT = ("the inclined surface's slider w1", "the flat surface's slider w2")

_LAW_TEXT = ", ".join(f"{law_code(name)} = {name}" for name in LAWS)

def _rows(fields) -> tuple[tuple[str, str, str | None, str], ...]:
    return tuple((f.name, f.type, f.unit, f.description) for f in fields)


def _element_blocks() -> list[tuple]:
    """Per registered element, the fields no earlier element declared."""
    seen, out = set(), []
    for el in FRICTION_ELEMENTS.values():
        out.append(tuple(f for f in el.fields if f.name not in seen))
        seen |= {f.name for f in el.fields}
    return out


_BLOCKS = _element_blocks()

#: (field, FMI type, unit, description) of the per-axis parameters, in the order of
#: the fields of ``AxisParameters``: the elastic law's, ``friction`` and the fields
#: of the first registered friction element.
PARAMETER_FIELDS: tuple[tuple[str, str, str | None, str], ...] = (
    ("law", "Integer", None, f"elastic law: {_LAW_TEXT}"),
    ("k1", "Real", "N/m", "linear (small-deflection) stiffness, >= 0"),
    ("kc", "Real", "N/m3", "cubic stiffness (law 1), >= 0"),
    ("k2", "Real", "N/m", "stiffness beyond the knee (laws 2, 3), >= 0"),
    ("delta", "Real", "m", "knee deflection for u > 0 (and u < 0 with law 2), > 0"),
    ("delta_neg", "Real", "m", "knee deflection magnitude for u < 0 with law 3, > 0"),
    ("c", "Real", "N.s/m", "viscous damping, >= 0"),
    ("friction", "Boolean", None, "whether the axis has a friction element (of kind "
     "<axis>_friction_kind)"),
) + _rows(_BLOCKS[0])

_KIND_TEXT = ", ".join(f"{friction_kind_code(name)} = {name} ({el.summary})"
                       for name, el in FRICTION_ELEMENTS.items())

#: (field, FMI type, unit, description): ``friction_kind`` and the new fields of the
#: second registered element (the inclined one of thesis Ch. 5), appended to the
#: table after the locals ``w_<axis>``.
INCLINED_PARAMETER_FIELDS: tuple[tuple[str, str, str | None, str], ...] = (
    ("friction_kind", "Integer", None, f"friction element: {_KIND_TEXT}"),
) + _rows(_BLOCKS[1] if len(_BLOCKS) > 1 else ())

#: The new fields of every later registered element, appended at the end.
LATER_PARAMETER_FIELDS: tuple[tuple[str, str, str | None, str], ...] = _rows(
    [f for block in _BLOCKS[2:] for f in block])


def _parameters(table) -> list[Variable]:
    defaults = AxisParameters()
    out = []
    for axis in AXES:
        for name, typ, unit, text in table:
            start = getattr(defaults, name)
            if name == "law":
                start = law_code(start)
            elif name == "friction_kind":
                start = friction_kind_code(start)
            out.append(Variable(f"{axis}_{name}", typ, "parameter", "fixed", start,
                                unit, f"{axis}: {text}"))
    return out


def _variables() -> tuple[Variable, ...]:
    """Every variable of the FMU, in the order of their value references (groups
    added later are appended, so that the earlier references stay)."""
    out = _parameters(PARAMETER_FIELDS)
    out += _axis_inputs() + _axis_outputs() + _committed_positions()
    out += _parameters(INCLINED_PARAMETER_FIELDS)
    out += _normal_force_outputs()
    out += _parameters(LATER_PARAMETER_FIELDS)
    out += _parameters(MAXWELL_PARAMETER_FIELDS)
    out += _post_step_outputs()
    out += _slider_positions()   # appended: the earlier value references stay
    out += _parameters(HYDRAULIC_PARAMETER_FIELDS)   # appended: the others stay
    return tuple(out)


def _axis_inputs() -> list[Variable]:
    """Per axis: the deflection, its rate and the normal force."""
    defaults = AxisParameters()
    out = []
    for axis in AXES:
        out += [
            Variable(f"u_{axis}", "Real", "input", "continuous", 0.0, "m",
                     f"{axis}: deflection, engine side minus chassis side"),
            Variable(f"v_{axis}", "Real", "input", "continuous", 0.0, "m/s",
                     f"{axis}: deflection rate d(u_{axis})/dt"),
            Variable(f"n_{axis}", "Real", "input", "continuous", defaults.n0, "N",
                     f"{axis}: normal force of the friction contact; equals "
                     f"{axis}_n0 until set (setting it to its start value 0 before "
                     f"the end of initialization, as importers writing start values "
                     f"do, keeps {axis}_n0); negative = lost contact (Fs = 0)"),
        ]
    return out


def _axis_outputs() -> list[Variable]:
    """Per axis: the forces, the tangent, the slip flag and the energy; then the
    energy of all axes."""
    out = []
    for axis in AXES:
        out += [
            Variable(f"F_{axis}", "Real", "output", "continuous", None, "N",
                     f"{axis}: total force, positive = tension (chassis pulled along "
                     f"+axis, engine feels -F)"),
            Variable(f"Ffr_{axis}", "Real", "output", "continuous", None, "N",
                     f"{axis}: force of the friction element"),
            Variable(f"kt_{axis}", "Real", "output", "continuous", None, "N/m",
                     f"{axis}: tangent stiffness dF/du (damping tangent dF/dv is c); "
                     f"read after doStep (until an input of the axis changes): the "
                     f"tangent the step ended with, i.e. the one the next step "
                     f"starts from when it continues the motion"),
            Variable(f"slip_{axis}", "Boolean", "output", "discrete", None, None,
                     f"{axis}: true while the friction slider slips (trial of the "
                     f"current inputs; read after doStep until an input of the axis "
                     f"changes: whether that step slipped, as slipped_{axis})"),
            Variable(f"E_fr_{axis}", "Real", "output", "continuous", None, "J",
                     f"{axis}: cumulative energy dissipated by friction"),
        ]
    out.append(Variable("E_fr", "Real", "output", "continuous", None, "J",
                        "cumulative energy dissipated by friction, all axes"))
    return out


def _committed_positions() -> list[Variable]:
    """Per axis: the friction element's committed position (a local state)."""
    out = []
    for axis in AXES:
        out.append(Variable(
            f"w_{axis}", "Real", "local", "continuous", 0.0, "m",
            f"{axis}: committed position of the friction element (Jenkins: the "
            f"slider, micro-slip: the mean of the sliders; inclined element: the "
            f"committed deflection); setting it relaxes the element there",
            "exact"))
    return out


def _normal_force_outputs() -> list[Variable]:
    """Per axis: the normal forces of the friction contact."""
    out = []
    for axis in AXES:
        out += [
            Variable(f"N_{axis}", "Real", "output", "continuous", None, "N",
                     f"{axis}: normal force of the friction contact (inclined "
                     f"element: on the inclined surface, from its kinematics; Jenkins "
                     f"element: max(n_{axis}, 0); 0 without friction)"),
            Variable(f"N2_{axis}", "Real", "output", "continuous", None, "N",
                     f"{axis}: normal force on the inclined element's flat surface "
                     f"(0 for the Jenkins element and without friction)"),
        ]
    return out


def _slider_positions() -> list[Variable]:
    """Per axis and slider slot: the slider's position (a local state)."""
    out = []
    for axis in AXES:   # appended: the earlier value references stay
        for k in range(1, SLIDER_SLOTS + 1):
            out.append(Variable(
                f"w{k}_{axis}", "Real", "local", "continuous", 0.0, "m",
                f"{axis}: position of slider {k} of the friction element, its own "
                f"coordinates (inclined element: {_SLOT_TEXT[k - 1]}; Jenkins: "
                f"slider {k} of its bank; 0 where the element has none); setting "
                f"it after w_{axis} starts the element with this slider there (a "
                f"state that is not relaxed, e.g. the engine lowered onto the "
                f"mount)", "exact"))
    return out


def _post_step_outputs() -> list[Variable]:
    """Per axis, what the FMU reports about the step just taken
    (``fmu_src/step_record.py``), appended after every older variable: they change
    only in ``doStep`` (no input dependencies)."""
    out = []
    for axis in AXES:
        out += [
            Variable(f"slipped_{axis}", "Boolean", "output", "discrete", False, None,
                     f"{axis}: whether the friction element slipped during the last "
                     f"doStep (false before the first)", "exact"),
            Variable(f"dE_fr_{axis}", "Real", "output", "discrete", 0.0, "J",
                     f"{axis}: energy dissipated by the friction element during the "
                     f"last doStep (0 before the first)", "exact"),
            Variable(f"ks_{axis}", "Real", "output", "discrete", None, "N/m",
                     f"{axis}: secant stiffness of the last doStep, (R_n - R_n-1) / "
                     f"(u_n - u_n-1) with R = F_{axis} - {axis}_c v_{axis} (the first "
                     f"step from the end of initialization); a step with u_n = u_n-1 "
                     f"gives the tangent kt_{axis} it started from (before the first "
                     f"step: that tangent)"),
        ]
    return out


#: (field, FMI type, unit, description) of the Maxwell branches (a spring in series
#: with a damper, in parallel with the elastic law; fmu_src.linear_branches), up to
#: MAX_MAXWELL per axis, appended after every element's fields.
MAXWELL_PARAMETER_FIELDS: tuple[tuple[str, str, str | None, str], ...] = tuple(
    row for i in range(1, MAX_MAXWELL + 1) for row in (
        (f"maxwell_k{i}", "Real", "N/m",
         f"Maxwell branch {i}: spring stiffness in series with its damper, >= 0 "
         f"(0: no branch)"),
        (f"maxwell_c{i}", "Real", "N.s/m",
         f"Maxwell branch {i}: damping in series with its spring, >= 0 (0: no "
         f"branch)")))


#: (field, FMI type, unit, description) of the hydraulic mount's fluid path (piston,
#: two chambers, inertia track, decoupler; fmu_src.linear_branches, the rubber is the
#: axis's own elastic law and c), appended after every other variable; hyd_Ap = 0:
#: absent.
HYDRAULIC_PARAMETER_FIELDS: tuple[tuple[str, str, str | None, str], ...] = tuple(
    (f"hyd_{name}", "Real", unit,
     f"hydraulic mount: {text}, >= 0" + (" (0: no fluid path)" if name == "Ap" else
                                         ", > 0 when hyd_Ap > 0"
                                         if name in ("C1", "C2", "I_i") else ""))
    for name, unit, text in HYDRAULIC_FIELDS[2:])

#: Every per-axis parameter field: (field, FMI type, unit, description).
ALL_PARAMETER_FIELDS = (PARAMETER_FIELDS + INCLINED_PARAMETER_FIELDS
                        + LATER_PARAMETER_FIELDS + MAXWELL_PARAMETER_FIELDS
                        + HYDRAULIC_PARAMETER_FIELDS)


def declared_bounds(field: str, typ: str) -> dict[str, str]:
    """The ``min``/``max`` attributes every build declares for the parameter
    ``<axis>_<field>`` of FMI type ``typ`` (strict bounds such as delta > 0 are in
    the descriptions and checked at initialization): law and friction-kind codes,
    sliders 1..MAX_SLIDERS, spread in [0, 1) (max: the largest double below 1),
    theta_deg in [0, 90], every other Real >= 0."""
    if field == "law":
        return {"min": "0", "max": str(len(LAWS) - 1)}
    if field == "friction_kind":
        return {"min": "0", "max": str(len(FRICTION_ELEMENTS) - 1)}
    if field == "sliders":
        return {"min": "1", "max": str(MAX_SLIDERS)}
    if field == "spread":
        return {"min": "0", "max": repr(math.nextafter(1.0, 0.0))}
    if field == "theta_deg":
        return {"min": "0", "max": "90"}
    return {"min": "0"} if typ == "Real" else {}

#: Every variable of the FMU, in value-reference order.
VARIABLES: tuple[Variable, ...] = _variables()
_BY_NAME = {v.name: v for v in VARIABLES}


def variable(name: str) -> Variable:
    """The variable called ``name`` (KeyError naming the allowed kinds if unknown)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"{MODEL_NAME} has no variable {name!r} (variables are "
                       f"<axis>_<parameter>, u_/v_/n_/F_/Ffr_/kt_/slip_/E_fr_/w_/N_/"
                       f"N2_/slipped_/dE_fr_/ks_/w1_/w2_<axis> "
                       f"and E_fr; axes {', '.join(AXES)})") from None


def by_causality(causality: str) -> tuple[Variable, ...]:
    """The variables of one causality, in value-reference order."""
    return tuple(v for v in VARIABLES if v.causality == causality)


def parameter_unit(field: str) -> str | None:
    """FMI unit of the per-axis parameter ``field`` (e.g. ``"kc"`` -> ``"N/m3"``)."""
    return variable(f"{AXES[0]}_{field}").unit
