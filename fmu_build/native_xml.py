"""The XML of the native FMUs (:mod:`fmu_build.native`): ``modelDescription.xml`` of
the FMI 2.0 and 3.0 flavours (header, Co-Simulation, with the Model Exchange part of
:mod:`fmu_build.native_me`; units, log categories, default experiment, variables with
their declared ranges, the model structure) and FMI 3.0's ``buildDescription.xml``.
Everything comes from the one interface table (``fmu_src/interface.py``).
"""

from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement, indent, tostring

from drymount.fmu_build import native_me
from drymount.fmu_src import interface
from drymount.fmu_src.mount_law import AXES

__all__ = ["model_description", "build_description"]

_FMI3_TYPE = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}
#: Inputs each output depends on (per axis; E_fr on those of every axis): a
#: rate-dependent friction element reads v in Ffr, kt and E_fr.
_DEPENDS = {"F": ("u", "v", "n"), "Ffr": ("u", "v", "n"), "kt": ("u", "v", "n"),
            "slip": ("u", "n"), "E_fr": ("u", "v", "n"), "N": ("u", "n"),
            "N2": ("u", "n"),
            # the records of the last step change only in doStep (step_record.py)
            "slipped": (), "dE_fr": (), "ks": ()}
_LOG_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError",
                   "logStatusFatal", "logAll")


def _bounds(var: interface.Variable) -> dict[str, str]:
    """Declared ranges of a parameter, as every build (interface.declared_bounds)."""
    if var.causality != "parameter":
        return {}
    return interface.declared_bounds(var.name.partition("_")[2], var.type)


def _start_text(var: interface.Variable) -> str | None:
    if var.start is None:
        return None
    if var.type == "Boolean":
        return "true" if var.start else "false"
    if var.type == "Integer":
        return str(int(var.start))
    return repr(float(var.start))


def _header_attributes(target, token: str) -> dict[str, str]:
    key = "guid" if target.fmi == 2 else "instantiationToken"
    return {"fmiVersion": f"{target.fmi}.0", "modelName": interface.MODEL_NAME,
            key: token,
            "description": ("Friction-damped engine mount (native C build): elastic "
                            "law + viscous damping + a friction element "
                            "(<axis>_friction_kind) on three local axes"
                            + (" -- NULL MODEL, no physics" if target.null else "")),
            "author": "drymount", "generationTool": "drymount fmu_build.native",
            "variableNamingConvention": "flat"}


def _cosimulation(root: Element, target, unity: str) -> None:
    caps = {name: "true" if value else "false"
            for name, value in interface.CAPABILITIES.items()}
    if target.fmi == 3:
        caps = {name.replace("FMUstate", "FMUState"): value
                for name, value in caps.items()}
        caps.update(hasEventMode="false", providesIntermediateUpdate="false",
                    canReturnEarlyAfterIntermediateUpdate="false")
    cs = SubElement(root, "CoSimulation", modelIdentifier=target.model_identifier,
                    **caps)
    if target.fmi == 2:
        files = SubElement(cs, "SourceFiles")  # the rest is #included (internal.h)
        SubElement(files, "File", name=unity)


def _units(root: Element, target) -> None:
    units = SubElement(root, "UnitDefinitions")
    table = dict(interface.BASE_UNITS) | native_me.EXTRA_UNITS
    if target.fmi == 3:
        table["s"] = {"s": 1}
    for name, exps in table.items():
        SubElement(SubElement(units, "Unit", name=name), "BaseUnit",
                   {k: str(e) for k, e in exps.items()})


def _variable_element(parent: Element, target, vr: int,
                      var: interface.Variable) -> None:
    attrs = {"name": var.name, "valueReference": str(vr),
             "description": var.description, "causality": var.causality,
             "variability": var.variability}
    if var.initial is not None:
        attrs["initial"] = var.initial
    typed = dict(_bounds(var))
    if var.unit is not None and var.type == "Real":
        typed["unit"] = var.unit
    start = _start_text(var)
    if start is not None:
        typed["start"] = start
    if target.fmi == 2:
        SubElement(SubElement(parent, "ScalarVariable", attrs), var.type, typed)
    else:
        SubElement(parent, _FMI3_TYPE[var.type], {**attrs, **typed})


def _structure(root: Element, target, variables) -> None:
    # FMI 2.0 refers to variables by 1-based index, FMI 3.0 by value reference
    ref = {var.name: str(vr + 1 if target.fmi == 2 else vr) for vr, var in variables}
    outputs = []
    for vr, var in variables:
        if var.causality != "output":
            continue
        prefix, _, axis = var.name.rpartition("_")
        if var.name == "E_fr":
            deps = [f"{d}_{a}" for a in AXES for d in _DEPENDS["E_fr"]]
            deps += native_me.me_depends("E_fr", None)
        else:
            deps = [f"{d}_{axis}" for d in _DEPENDS[prefix]]
            deps += [d for d in native_me.me_depends(prefix, axis) if d not in deps]
        outputs.append((ref[var.name], " ".join(
            sorted((ref[d] for d in deps), key=int))))
    # Model Exchange: the states and derivatives are initial unknowns too
    initial = [index for index, _ in outputs] + [
        ref[n] for n in native_me.initial_unknowns()]
    initial.sort(key=int)
    structure = SubElement(root, "ModelStructure")
    # outputs declared initial="exact" (slipped_, dE_fr_) are no initial unknowns
    exact = {ref[var.name] for _, var in variables if var.initial == "exact"}
    if target.fmi == 2:
        out_el = SubElement(structure, "Outputs")
        for index, deps in outputs:
            SubElement(out_el, "Unknown", index=index, dependencies=deps)
        native_me.structure_derivatives(structure, 2, ref)
        init_el = SubElement(structure, "InitialUnknowns")
        for index in initial:
            if index not in exact:
                SubElement(init_el, "Unknown", index=index)
        return
    for index, deps in outputs:
        SubElement(structure, "Output", valueReference=index, dependencies=deps)
    native_me.structure_derivatives(structure, 3, ref)
    for index in initial:
        if index not in exact:
            SubElement(structure, "InitialUnknown", valueReference=index)
    native_me.structure_event_indicators(structure, ref)


def model_description(target, token: str, variables, unity: str) -> bytes:
    """``modelDescription.xml`` of the FMI 2.0 or FMI 3.0 flavour: ``target`` a
    :class:`fmu_build.native.NativeTarget`, ``variables`` its ``(value reference,
    variable)`` pairs, ``unity`` the one source file the sources list."""
    root = Element("fmiModelDescription", _header_attributes(target, token))
    if target.fmi == 2:
        root.set("numberOfEventIndicators", str(3 * len(native_me.EVENT_INDICATORS)))
    native_me.model_exchange(root, target.fmi, target.model_identifier, unity)
    _cosimulation(root, target, unity)
    _units(root, target)
    cats = SubElement(root, "LogCategories")
    for name in _LOG_CATEGORIES:
        SubElement(cats, "Category", name=name)
    SubElement(root, "DefaultExperiment",
               {k: repr(float(v)) for k, v in interface.DEFAULT_EXPERIMENT.items()})
    mv = SubElement(root, "ModelVariables")
    index = {var.name: vr for vr, var in variables}
    for vr, var in variables:
        _variable_element(mv, target, vr, var)
        if var.name.startswith("der("):  # a Model Exchange state's derivative
            state = index[var.name[4:-1]]
            element = mv[-1] if target.fmi == 3 else mv[-1][0]
            element.set("derivative", str(state + 1 if target.fmi == 2 else state))
    _structure(root, target, variables)
    indent(root)
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def build_description(model_identifier: str, unity: str) -> bytes:
    """``sources/buildDescription.xml`` (FMI 3.0)."""
    root = Element("fmiBuildDescription", fmiVersion="3.0")
    conf = SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier)
    files = SubElement(conf, "SourceFileSet", language="C99")
    SubElement(files, "SourceFile", name=unity)  # the rest is #included
    SubElement(conf, "Library", name="m", description="libm (C math library)")
    indent(root)
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"
