"""The Model Exchange side of the native FMUs' model descriptions (fmu_build/native.py).

Both native FMUs declare Model Exchange beside Co-Simulation, with the same model
identifier (one binary, ``fmu_src/native/fmi2_me.c`` / ``fmi3_me.c`` on top of
``me.c``). The variables below follow the interface table's (and FMI 3.0's ``time``):
per axis the two continuous states of a Dahl or LuGre element (Berg's element: its
dissipated energy; a Jenkins bank under a varying normal force: its friction work;
constant 0 otherwise), their derivatives, and the two event indicators; see
``fmu_src/native/me.h`` and docs/fmu.md ("Model Exchange").
"""

from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from drymount.fmu_src import interface
from drymount.fmu_src.mount_law import AXES

__all__ = ["EVENT_INDICATORS", "STATES", "me_depends", "me_role", "me_variables",
           "model_exchange", "structure_derivatives", "structure_event_indicators"]

#: Continuous states per axis (me_state.h: MX_STATES_PER_AXIS, in this order).
STATES = ("zb", "Eb")
#: Event indicators per axis (MX_INDICATORS_PER_AXIS, in this order).
EVENT_INDICATORS = ("zs", "zr")
#: Units the Model Exchange variables add to the interface table's.
EXTRA_UNITS = {"W": {"kg": 1, "m": 2, "s": -3}}

_ROLES = {"zb": "MX_ROLE_Z", "Eb": "MX_ROLE_E", "der(zb)": "MX_ROLE_DZ",
          "der(Eb)": "MX_ROLE_DE", "zs": "MX_ROLE_STICK", "zr": "MX_ROLE_REVERSE"}


def me_variables() -> list[interface.Variable]:
    """The Model Exchange variables, axis by axis (states, derivatives, indicators)."""
    out = []
    for axis in AXES:
        out += [
            interface.Variable(
                f"zb_{axis}", "Real", "local", "continuous", None, "m",
                f"Model Exchange state: bristle deflection of the {axis} Dahl or LuGre "
                f"element (Dahl: its force / {axis}_kf); 0 for other elements",
                "calculated"),
            interface.Variable(
                f"der(zb_{axis})", "Real", "local", "continuous", None, "m/s",
                f"derivative of zb_{axis}: v - kf |v| z / g(v)", "calculated"),
            interface.Variable(
                f"Eb_{axis}", "Real", "local", "continuous", None, "J",
                f"Model Exchange state: energy the {axis} Dahl, LuGre or Berg "
                f"element dissipated (in E_fr_{axis}); a Jenkins bank's friction "
                f"work once n_{axis} varies; 0 for other elements", "calculated"),
            interface.Variable(
                f"der(Eb_{axis})", "Real", "local", "continuous", None, "W",
                f"derivative of Eb_{axis}: the dissipated power", "calculated"),
            interface.Variable(
                f"zs_{axis}", "Real", "local", "continuous", None, "N",
                f"event indicator: margin of the {axis} stuck slider (or surface) "
                f"nearest to its slip limit, negative once it slips (Berg: its force "
                f"times the sign of v at the last event)", "calculated"),
            interface.Variable(
                f"zr_{axis}", "Real", "local", "continuous", None, "m/s",
                f"event indicator: v_{axis} times its sign at the last event while "
                f"the {axis} element slips; negative once the motion reverses",
                "calculated"),
        ]
    return out


def me_role(name: str) -> tuple[str, int] | None:
    """(C role, axis index) of a Model Exchange variable, None for other names."""
    for j, axis in enumerate(AXES):
        for stem, role in _ROLES.items():
            inner = stem.removeprefix("der(").removesuffix(")")
            full = f"der({inner}_{axis})" if stem.startswith("der(") else \
                f"{stem}_{axis}"
            if name == full:
                return role, j
    return None


#: Extra dependencies of the outputs in Model Exchange (per axis): the continuous
#: states of a Dahl/LuGre element, and v (slip of a continuous element is v != 0).
_OUTPUT_STATES = {"F": ("zb",), "Ffr": ("zb",), "kt": ("zb",), "slip": ("v",),
                  "E_fr": ("zb", "Eb")}


def me_depends(prefix: str, axis: str | None) -> list[str]:
    """Names the output ``<prefix>_<axis>`` (``E_fr`` alone: axis None) depends on
    beyond its Co-Simulation inputs."""
    if axis is None:
        return [f"Eb_{a}" for a in AXES] if prefix == "E_fr" else []
    return [f"{d}_{axis}" for d in _OUTPUT_STATES.get(prefix, ())]


def model_exchange(root: Element, fmi: int, identifier: str, source_file: str) -> None:
    """The ``<ModelExchange>`` element (same model identifier as Co-Simulation)."""
    caps = {"needsExecutionTool": "false",
            "canBeInstantiatedOnlyOncePerProcess": "false",
            "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true"}
    if fmi == 2:
        caps["completedIntegratorStepNotNeeded"] = "false"
        me = SubElement(root, "ModelExchange", modelIdentifier=identifier, **caps)
        SubElement(SubElement(me, "SourceFiles"), "File", name=source_file)
        return
    caps = {k.replace("FMUstate", "FMUState"): v for k, v in caps.items()}
    caps["needsCompletedIntegratorStep"] = "true"
    caps["providesEvaluateDiscreteStates"] = "false"
    SubElement(root, "ModelExchange", modelIdentifier=identifier, **caps)


def _state_depends(axis: str, state: str) -> list[str]:
    # Berg's energy rate depends on u (its force and tangent from the committed state)
    return [f"zb_{axis}", *([f"u_{axis}"] if state == "Eb" else []), f"v_{axis}",
            f"n_{axis}"]


def structure_derivatives(structure: Element, fmi: int, ref: dict[str, str]) -> None:
    """ModelStructure's Derivatives (FMI 2.0) / ContinuousStateDerivative (3.0)."""
    parent = SubElement(structure, "Derivatives") if fmi == 2 else structure
    for axis in AXES:
        for state in STATES:
            deps = " ".join(ref[d] for d in _state_depends(axis, state))
            if fmi == 2:
                SubElement(parent, "Unknown", index=ref[f"der({state}_{axis})"],
                           dependencies=deps)
            else:
                SubElement(parent, "ContinuousStateDerivative",
                           valueReference=ref[f"der({state}_{axis})"],
                           dependencies=deps)


def initial_unknowns() -> list[str]:
    """The Model Exchange variables among the initial unknowns (states and
    derivatives: initial="calculated")."""
    return [f"{s}_{a}" for a in AXES for s in STATES] + \
        [f"der({s}_{a})" for a in AXES for s in STATES]


def structure_event_indicators(structure: Element, ref: dict[str, str]) -> None:
    """ModelStructure's EventIndicator elements (FMI 3.0)."""
    for axis in AXES:
        for name in EVENT_INDICATORS:
            SubElement(structure, "EventIndicator",
                       valueReference=ref[f"{name}_{axis}"])
