"""The FrictionMount FMU's model description beyond what pythonfmu writes.

pythonfmu's ``Fmi2Slave.to_xml`` writes the variables with their causality,
variability, start values and descriptions. :func:`complete` adds what an importer
needs besides (docs/fmu.md): the co-simulation capabilities, the unit definitions and
each Real's unit, the declared ranges of the parameters, and the model structure
(each output's input dependencies and the initial unknowns). Standard library only.
"""

from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from .interface import (ALL_PARAMETER_FIELDS, BASE_UNITS, CAPABILITIES, VARIABLES,
                        declared_bounds)
from .mount_law import AXES

__all__ = ["complete"]

# Declared ranges of the parameters (strict bounds such as delta > 0 and the rule for
# kf are in the descriptions and checked at initialization).
_BOUNDS = {name: declared_bounds(name, typ) for name, typ, *_ in ALL_PARAMETER_FIELDS}
# The inputs of its axis each output depends on (a rate-dependent friction element,
# LuGre, reads v in Ffr, kt and E_fr); the others depend on u and n.
_DEPENDS = {"F": ("u", "v", "n"), "Ffr": ("u", "v", "n"), "kt": ("u", "v", "n"),
            "E_fr": ("u", "v", "n")}


def complete(root: Element) -> Element:
    """``root`` (pythonfmu's model description) with capabilities, units, ranges and
    the model structure; changed in place and returned."""
    cosim = root.find("CoSimulation")
    for flag, value in CAPABILITIES.items():
        cosim.set(flag, "true" if value else "false")
    # UnitDefinitions follows the CoSimulation element (FMI 2.0 schema order).
    root.insert(list(root).index(cosim) + 1, _unit_definitions())
    index = _units_and_ranges(root)
    root.remove(root.find("ModelStructure"))
    _model_structure(SubElement(root, "ModelStructure"), index)
    return root


def _unit_definitions() -> Element:
    units = Element("UnitDefinitions")
    for name, exps in BASE_UNITS.items():
        SubElement(SubElement(units, "Unit", name=name), "BaseUnit",
                   {k: str(e) for k, e in exps.items()})
    return units


def _units_and_ranges(root: Element) -> dict[str, str]:
    """Set each variable's unit and each parameter's declared range; return the
    1-based index of every variable by name."""
    index = {}
    unit_of = {var.name: var.unit for var in VARIABLES}
    for i, sv in enumerate(root.find("ModelVariables"), start=1):
        index[sv.get("name")] = str(i)
        unit = unit_of.get(sv.get("name"))
        if unit is not None:
            sv.find("Real").set("unit", unit)
        bounds = _BOUNDS.get(sv.get("name").partition("_")[2])
        if bounds is not None and sv.get("causality") == "parameter":
            sv[0].attrib.update(bounds)
    return index


def _model_structure(structure: Element, index: dict[str, str]) -> None:
    outputs = SubElement(structure, "Outputs")
    initial = SubElement(structure, "InitialUnknowns")
    rows = []  # (index, dependencies) of every output, listed in index order
    for axis in AXES:
        for name in ("F", "Ffr", "kt", "slip", "E_fr", "N", "N2"):
            rows.append((int(index[f"{name}_{axis}"]), " ".join(
                index[f"{d}_{axis}"] for d in _DEPENDS.get(name, ("u", "n")))))
    rows.append((int(index["E_fr"]), " ".join(
        index[f"{d}_{axis}"] for axis in AXES for d in ("u", "v", "n"))))
    # the records of the last step change only in doStep: no input dependencies
    rows += [(int(index[f"{name}_{axis}"]), "") for axis in AXES
             for name in ("slipped", "dE_fr", "ks")]
    for i, refs in sorted(rows):
        SubElement(outputs, "Unknown", index=str(i), dependencies=refs)
    # Initial values of the outputs depend on inputs, parameters and the start
    # value of w: no `dependencies` attribute = depends on all knowns (FMI 2.0);
    # outputs with initial="exact" (slipped_, dE_fr_) are not initial unknowns.
    exact = {index[v.name] for v in VARIABLES if v.initial == "exact"}
    for unknown in outputs:
        if unknown.get("index") not in exact:
            SubElement(initial, "Unknown", index=unknown.get("index"))
