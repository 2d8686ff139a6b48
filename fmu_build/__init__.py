"""Builds the FrictionMount FMU (FMI 2.0 Co-Simulation) from ``fmu_src``.

Imports only ``fmu_src`` (and pythonfmu when building), so the harness (``vehicle``)
and the app (``drymount``) can build the FMU without importing each other.
``build_fmu.py`` at the repository root is the script that calls :func:`build_fmu`;
``fmu_doc/`` is the FMU's ``documentation/`` folder.
"""

from drymount.fmu_build import builder
from drymount.fmu_build.builder import *  # noqa: F403 - the package's API is the builder's

__all__ = list(builder.__all__)
