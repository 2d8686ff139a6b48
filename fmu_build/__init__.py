"""Builds the FrictionMount FMU (FMI 2.0 Co-Simulation) from ``fmu_src``.

Imports only ``fmu_src`` (and pythonfmu when building), so the harness (``vehicle``)
and the app (``drymount``) can build the FMU without importing each other.
``build_fmu.py`` at the repository root is the script that calls :func:`build_fmu`;
``fmu_doc/`` is the FMU's ``documentation/`` folder.
"""

from fmu_build.builder import (
    FMU_SOURCES,
    build_fmu,
    compile_loader,
    default_fmu_path,
    ensure_fmu,
    fmu_module_names,
    libpython_location,
    source_dir,
)

__all__ = [
    "FMU_SOURCES",
    "build_fmu",
    "compile_loader",
    "libpython_location",
    "default_fmu_path",
    "ensure_fmu",
    "fmu_module_names",
    "source_dir",
]
