"""SSP 1.0 export of a configuration's mounts (``drymount export-ssp CONFIG --out F``).

The archive holds

* ``SystemStructure.ssd``: one ``ssd:Component`` per mount instance of the
  configuration, all pointing to the one mount FMU under ``resources/`` (the PythonFMU
  build, or with ``native=True`` the FMI 2.0 native build); per component the connectors
  the host drives and reads (inputs ``u_/v_/n_<axis>``, outputs ``F_/Ffr_<axis>`` and
  ``E_fr``, with units) and a parameter binding; OMSimulator's system annotation
  (``org.openmodelica``: a fixed-step master at the FMU's step size, without which it
  refuses the archive); the units (``ssd:Units``); a default experiment (the FMU's);
* ``resources/<mount>.ssv``: the mount's parameters (``<axis>_<field>``, the FMU's
  variables) with the configuration's values and units. Every set carries the same name
  (the configuration's), so an importer applies all of them as one parameter set
  (Ecos: ``init(parameter_set=NAME)``);
* ``documentation/README.txt``: what the host must connect.

The vehicle body (rigid engine, quarter car) is not an FMU: the SSD has no connections;
the host computes each mount's local deflections u, v from its own model (the
configuration's ``B`` / ``G`` matrices, written per mount into the documentation) and
applies ``-F`` to the engine side and ``+F`` to the chassis side of each axis
(docs/fmu.md, sign conventions).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from xml.etree.ElementTree import (
    Element,
    SubElement,
    indent,
    register_namespace,
    tostring,
)

from drymount.fmu_build.native import write_zip
from drymount.fmu_src import interface
from drymount.fmu_src.mount_law import AXES, friction_kind_code, law_code

__all__ = ["SspExport", "SspError", "check_mount_fmu", "export_ssp",
           "fmu_model_description", "parameter_set",
           "system_structure", "CONNECTOR_INPUTS", "CONNECTOR_OUTPUTS", "OMS", "OSP"]

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
#: Open Simulation Platform's annotations (libcosim reads its algorithm from them).
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
#: OMSimulator's annotations (the namespace it writes; it matches the ``oms:`` prefix).
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV), ("osp", OSP),
                      ("oms", OMS)):
    register_namespace(_prefix, _uri)

#: Connectors of each mount component (FMU variable prefixes, per axis).
CONNECTOR_INPUTS = ("u", "v", "n")
CONNECTOR_OUTPUTS = ("F", "Ffr")
_FMU_TYPE = "application/x-fmu-sharedlibrary"


@dataclass(frozen=True)
class SspExport:
    """A written SSP archive."""

    path: Path
    fmu: str                  # the FMU's path inside the archive
    mounts: tuple[str, ...]   # component names, one per mount instance
    parameter_set: str        # name shared by every component's parameter set


def _q(ns: str, tag: str) -> str:
    return f"{{{ns}}}{tag}"


def _units(parent: Element, ns: str) -> None:
    units = SubElement(parent, _q(ns, "Units"))
    for name, exps in interface.BASE_UNITS.items():
        unit = SubElement(units, _q(SSC, "Unit"), name=name)
        SubElement(unit, _q(SSC, "BaseUnit"), {k: str(v) for k, v in exps.items()})


def _fmu_values(params) -> list[tuple[interface.Variable, str]]:
    """(FMU parameter variable, value text) of a mount, in value-reference order."""
    out = []
    for axis, p in zip(AXES, params.axes, strict=True):
        for name, value in p.to_dict().items():
            var = interface.variable(f"{axis}_{name}")
            if name == "law":
                text = str(law_code(value))
            elif name == "friction_kind":
                text = str(friction_kind_code(value))
            elif var.type == "Integer":
                text = str(int(value))
            elif var.type == "Boolean":
                text = "true" if value else "false"
            else:
                text = repr(float(value))
            out.append((var, text))
    order = {v.name: i for i, v in enumerate(interface.VARIABLES)}
    return sorted(out, key=lambda item: order[item[0].name])


def parameter_set(element, set_name: str) -> bytes:
    """The ``.ssv`` of one mount element (``hbm.system.MountElement``)."""
    root = Element(_q(SSV, "ParameterSet"), version="1.0", name=set_name)
    params = SubElement(root, _q(SSV, "Parameters"))
    for var, text in _fmu_values(element.params):
        p = SubElement(params, _q(SSV, "Parameter"), name=var.name)
        attrs = {"value": text}
        if var.unit is not None:
            attrs["unit"] = var.unit
        SubElement(p, _q(SSV, var.type), attrs)
    _units(root, SSV)
    indent(root)
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def _connectors(component: Element) -> None:
    connectors = SubElement(component, _q(SSD, "Connectors"))
    names = [(f"{q}_{a}", "input") for a in AXES for q in CONNECTOR_INPUTS]
    names += [(f"{q}_{a}", "output") for a in AXES for q in CONNECTOR_OUTPUTS]
    names.append(("E_fr", "output"))
    for name, kind in names:
        var = interface.variable(name)
        c = SubElement(connectors, _q(SSD, "Connector"), name=name, kind=kind,
                       description=var.description)
        SubElement(c, _q(SSC, "Real"), unit=var.unit)


def system_structure(cfg, fmu_name: str, set_name: str) -> bytes:
    """``SystemStructure.ssd`` of a configuration (``drymount.config.Config``)."""
    root = Element(_q(SSD, "SystemStructureDescription"), version="1.0",
                   name=cfg.name, generationTool="drymount export-ssp")
    system = SubElement(root, _q(SSD, "System"), name=cfg.name,
                        description=("mount FMU instances of the drymount "
                                     f"configuration {cfg.name!r}; the vehicle body is "
                                     "not an FMU: see documentation/README.txt"))
    elements = SubElement(system, _q(SSD, "Elements"))
    for el in cfg.system.elements:
        comp = SubElement(elements, _q(SSD, "Component"), name=el.name,
                          type=_FMU_TYPE, source=f"resources/{fmu_name}")
        _connectors(comp)
        bindings = SubElement(comp, _q(SSD, "ParameterBindings"))
        SubElement(bindings, _q(SSD, "ParameterBinding"),
                   source=f"resources/{el.name}.ssv")
    _openmodelica_annotation(system)
    _units(root, SSD)
    _default_experiment(root)
    indent(root)
    return tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def _openmodelica_annotation(system: Element) -> None:
    """OMSimulator's simulation information on the system: its fixed-step master
    (``oms-ma``) at the FMU's step size. OMSimulator imports an SSP 1.0 system only
    with it (without: "[NewSystem] internal error", its command-line tool aborts);
    other importers ignore it (``ssc:Annotation`` takes any content)."""
    exp = interface.DEFAULT_EXPERIMENT
    ann = SubElement(SubElement(system, _q(SSD, "Annotations")), _q(SSC, "Annotation"),
                     type="org.openmodelica")
    info = SubElement(SubElement(ann, _q(OMS, "Annotations")),
                      _q(OMS, "SimulationInformation"))
    SubElement(info, _q(OMS, "FixedStepMaster"), description="oms-ma",
               stepSize=repr(exp["stepSize"]),
               relativeTolerance=repr(exp["tolerance"]))


def _default_experiment(root: Element) -> None:
    """The FMU's default experiment, annotated for libcosim (OSP): a fixed-step
    algorithm at the FMU's step size on no worker thread. libcosim's default pool
    runs initialization in worker threads without a catch, so an FMU error there
    (a bad parameter) would end the host; with zero threads it is a failed step with
    the FMU's message (docs/fmu.md 4a). Other importers ignore the annotation."""
    exp = interface.DEFAULT_EXPERIMENT
    de = SubElement(root, _q(SSD, "DefaultExperiment"),
                    startTime=repr(exp["startTime"]), stopTime=repr(exp["stopTime"]))
    ann = SubElement(SubElement(de, _q(SSD, "Annotations")), _q(SSC, "Annotation"),
                     type="com.opensimulationplatform")
    SubElement(SubElement(ann, _q(OSP, "Algorithm")), _q(OSP, "FixedStepAlgorithm"),
               baseStepSize=repr(exp["stepSize"]), numWorkerThreads="0")


def _readme(cfg, fmu_name: str, set_name: str) -> bytes:
    lines = [
        f"SSP export of the drymount configuration {cfg.name!r} ({cfg.model}).",
        "",
        f"Components: one instance of resources/{fmu_name} per mount; parameter set "
        f"{set_name!r} (resources/<mount>.ssv, apply it before initialization).",
        "The vehicle body is not an FMU, so the system has no connections. Per mount",
        "and communication step t_k the host must:",
        "  1. set u_<axis> = B q - G y (m) and v_<axis> = B q' - G y' (m/s) of its",
        "     axes, and n_<axis> (N) when it controls the normal force (else n =",
        "     <axis>_n0);",
        "  2. read F_<axis> (N): the chassis side feels +F, the engine side -F along",
        "     the axis; Ffr_<axis> is the friction part, E_fr the dissipated",
        "     energy (J);",
        "  3. call doStep(t_k, h) (commits the friction sliders).",
        "",
        "B and G of each mount (rows axial, radial1, radial2; DOFs "
        f"{', '.join(cfg.system.dof_names)}):",
    ]
    for el in cfg.system.elements:
        lines.append(f"  {el.name}: B = {el.B.tolist()}, G = {el.G.tolist()}")
    lines += ["", "Variables, units and the coupling advice: docs/fmu.md of drymount."]
    return ("\n".join(lines) + "\n").encode()


class SspError(ValueError):
    """An FMU that an SSP 1.0 archive of the mounts cannot carry."""


def fmu_model_description(path, where: str, error: type[Exception]):
    """The parsed ``modelDescription.xml`` (an ElementTree root) of the FMU file
    ``path``; ``error`` naming ``where`` if it is not a zip holding one or not XML."""
    import zipfile
    from xml.etree.ElementTree import ParseError, fromstring

    try:
        with zipfile.ZipFile(path) as z:
            return fromstring(z.read("modelDescription.xml"))
    except (OSError, zipfile.BadZipFile, KeyError) as exc:
        raise error(f"{where} is not an FMU (a zip with modelDescription.xml): "
                    f"{exc}") from None
    except ParseError as exc:
        raise error(f"{where}: its modelDescription.xml is not XML ({exc})") from None


def check_mount_fmu(path) -> None:
    """:class:`SspError` unless ``path`` is an FMI 2.0 FrictionMount FMU: a zip whose
    ``modelDescription.xml`` parses, says ``fmiVersion="2.0"`` (SSP 1.0 predates
    FMI 3.0) and declares every variable the archive's parameter sets and connectors
    name."""
    where = f"--fmu: {str(path)!r}"
    root = fmu_model_description(path, where, SspError)
    version = root.get("fmiVersion")
    if version != "2.0":
        raise SspError(f"{where} is an FMI {version} FMU; an SSP 1.0 archive carries "
                       f"FMI 2.0 FMUs (build one with `drymount build-fmu` or "
                       f"`build-fmu --native --fmi 2`)")
    names = {v.get("name") for v in root.iter("ScalarVariable")}
    missing = [v.name for v in interface.VARIABLES if v.name not in names]
    if missing:
        raise SspError(f"{where} is not a FrictionMount FMU: it lacks "
                       f"{len(missing)} of its variables ({', '.join(missing[:4])}"
                       f"{', ...' if len(missing) > 4 else ''})")


def _fmu_file(native: bool, fmu_path) -> Path:
    if fmu_path is not None:
        return Path(fmu_path)
    if native:
        from drymount.fmu_build.native import (
            build_native_fmu,
            default_native_path,
            is_native_fmu,
        )

        path = default_native_path(2)
        if not is_native_fmu(path):
            build_native_fmu(path, fmi=2)
        return path
    from drymount.fmu_build import ensure_fmu

    return ensure_fmu()


def export_ssp(cfg, out, *, native: bool = False, fmu_path=None) -> SspExport:
    """Write the SSP archive of ``cfg`` to ``out`` (see the module docstring).

    ``native`` packs the FMI 2.0 native FMU (dist/FrictionMountNative.fmu, built if
    missing) instead of the PythonFMU build (dist/FrictionMount.fmu, built if missing
    or stale); ``fmu_path`` packs the given FMU.
    """
    out = Path(out)
    fmu = _fmu_file(native, fmu_path)
    set_name = cfg.name
    files = {"SystemStructure.ssd": system_structure(cfg, fmu.name, set_name),
             f"resources/{fmu.name}": fmu.read_bytes(),
             "documentation/README.txt": _readme(cfg, fmu.name, set_name)}
    for el in cfg.system.elements:
        files[f"resources/{el.name}.ssv"] = parameter_set(el, set_name)
    write_zip(out, files, first="SystemStructure.ssd")
    return SspExport(out, f"resources/{fmu.name}",
                     tuple(el.name for el in cfg.system.elements), set_name)
