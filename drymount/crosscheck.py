"""FMI cross-check folder of a FrictionMount FMU (``drymount export-xc FMU --out DIR``).

Writes, following the rules of the FMI cross-check (modelica/fmi-cross-check),

    DIR/<fmiVersion>/cs/<platform>/drymount/<drymount version>/<Model>/
        <Model>.fmu        a copy of the FMU
        <Model>_in.csv     the stimuli: time, u_/v_ of the axial and radial1 axes
        <Model>_ref.csv    the reference results: time, F_axial, F_radial1
        <Model>_ref.opt    StartTime, StopTime, StepSize, RelTol
        ReadMe.txt         what the run is

``<Model>`` is the FMU's ``modelName``, ``<platform>`` the platform of this machine
(``linux64``; FMI 3.0: ``x86_64-linux``). The run is the reference experiment the
native FMUs carry in ``extra/org.fmi-standard.fmi-ls-ref/`` (:mod:`fmu_build.extras`):
the FMU's default parameters, results by the mount law with the outputs read after
``doStep``, as a cross-check importer reads them.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from drymount.fmu_build.extras import REFERENCE, csv_text, opt_text, reference_run
from drymount.ssp import fmu_model_description

__all__ = ["XcError", "XcExport", "export_xc", "fmu_identity"]


class XcError(ValueError):
    """An FMU the cross-check folder cannot be written for."""


@dataclass(frozen=True)
class XcExport:
    """A written cross-check folder."""

    folder: Path        # DIR/<fmiVersion>/cs/<platform>/drymount/<version>/<Model>
    model: str          # <Model>
    fmi_version: str    # "2.0" or "3.0"
    rows: int           # time steps in _in.csv and _ref.csv


def fmu_identity(path) -> tuple[str, str]:
    """``(modelName, fmiVersion)`` of a FrictionMount co-simulation FMU, else
    :class:`XcError` naming the file and what is wrong."""
    root = fmu_model_description(path, where := f"FMU {str(path)!r}", XcError)
    version = root.get("fmiVersion", "")
    if version not in ("2.0", "3.0"):
        raise XcError(f"{where} is an FMI {version or '?'} FMU; FMI 2.0 or 3.0 "
                      f"is needed")
    if root.find("CoSimulation") is None:
        raise XcError(f"{where} has no co-simulation interface (the cross-check "
                      f"folder is written under cs/)")
    tag = "ScalarVariable" if version == "2.0" else "Float64"
    names = {v.get("name") for v in root.iter(tag)}
    run = reference_run()
    missing = [n for n in (*run.stimuli_names, *run.results_names) if n not in names]
    if missing:
        raise XcError(f"{where} is not a FrictionMount FMU: it lacks "
                      f"{', '.join(missing)}")
    model = root.get("modelName", "")
    if not model or any(c in model for c in '/\\:*?"<>|'):
        raise XcError(f"{where} has an unusable modelName {model!r}")
    return model, version


def _platform(fmi_version: str) -> str:
    from fmpy import platform, platform_tuple

    return platform if fmi_version == "2.0" else platform_tuple


def _readme(model: str, version: str) -> str:
    axes = ", ".join(f"{a}: {x * 1e3:g} mm at {f:g} Hz"
                     for a, (x, f) in REFERENCE["axes"].items())
    return (f"{model} (FMI {version} co-simulation), exported by drymount "
            f"export-xc.\nDefault parameters; inputs {model}_in.csv: sine "
            f"deflections ({axes})\nand their rates v = du/dt. Reference "
            f"{model}_ref.csv: the total forces by\ndrymount's mount law, outputs "
            f"read after doStep (the row at t_k+1 holds\nthe outputs after "
            f"doStep(t_k, h) with the inputs of t_k).\n")


def export_xc(fmu, out) -> XcExport:
    """Write the cross-check folder of ``fmu`` under ``out`` (see the module text)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as dist_version

    try:
        tool_version = dist_version("drymount")
    except PackageNotFoundError:  # a source tree that is not installed
        tool_version = "0+unknown"
    fmu = Path(fmu)
    model, version = fmu_identity(fmu)
    folder = (Path(out) / version / "cs" / _platform(version) / "drymount" /
              tool_version / model)
    folder.mkdir(parents=True, exist_ok=True)
    run = reference_run()
    shutil.copyfile(fmu, folder / f"{model}.fmu")
    (folder / f"{model}_in.csv").write_text(csv_text(run.time, run.stimuli_names,
                                                     run.stimuli))
    (folder / f"{model}_ref.csv").write_text(csv_text(run.time, run.results_names,
                                                      run.results))
    (folder / f"{model}_ref.opt").write_text(opt_text())
    (folder / "ReadMe.txt").write_text(_readme(model, version))
    return XcExport(folder, model, version, len(run.time))
