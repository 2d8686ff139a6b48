"""The thesis's design studies (Chapter 4) as commands: ``drymount study NAME``.

Each study computes harmonic-balance (HBM) frequency-response curves of a preset system
for several mount designs, and writes to ``DIR``: a CSV of every curve point, a CSV of
the key numbers, PNG plots (transmissibility or amplitude on a log axis against
frequency in Hz) and a ``summary.md`` with the key numbers. Each is also a Python
function returning those key numbers as a dict:

========================  ============================  ===========================
command                   function                      thesis
========================  ============================  ===========================
``normal-force``          :func:`run_normal_force`      Figs. 4.1-4.4
``optimize-n0``           :func:`run_optimize_n0`       Sec. 4.2 ("about 9 N")
``quarter-car``           :func:`run_quarter_car`       Figs. 4.6-4.9
``six-dof``               :func:`run_six_dof`           Figs. 4.11-4.44
``jump``                  :func:`run_jump`              Figs. 3.5, 3.7
``laws``                  :func:`run_laws`              Fig. 4.5
``six-dof-75``            :func:`run_six_dof_75`        Figs. 4.45-4.50
``hydraulic``             :func:`run_hydraulic`         Sec. 1.1.2.2 (issue 28)
========================  ============================  ===========================

The normal force ``n0`` of a study is applied to every friction element of the system;
``n0 = 0`` means the mount without a friction element (the "original" mount of the

The normal force ``n0`` of a study is applied to every friction element of the system;
``n0 = 0`` means the mount without a friction element (the "original" mount of the
thesis when the stiffness is the original one). The "halved" mount has half the elastic
stiffness (k1, kc, k2) of the original and the same damping and contact stiffness, as
in the thesis (Sec. 4.2: "half of the stiffness of the original system").

Quick mode (``quick=True``) uses fewer designs, fewer harmonics and coarser grids so
that the test suite can run every study in seconds; the numbers it reports are real
HBM results, only coarser.

Modules: :mod:`~drymount.studies.common` (system edits, metrics, the HBM curve of a
design), :mod:`~drymount.studies.output` (plots, CSV, Markdown), one module per study
(:mod:`~drymount.studies.family` shared by normal-force and quarter-car) and
:mod:`~drymount.studies.cli` (the command).

References: thesis Sec. 4.2-4.5, eq. 4.1 (force transmissibility), 4.2 (unbalance
excitation), 4.3 (displacement transmissibility), 4.4 (radial = lambda * axial), 1.3
(crank-mechanism excitation, :mod:`hbm.crank`); PHYSICS.md sections 2-4.
"""

from drymount.studies.cli import STUDIES, ExitStatus, main
from drymount.studies.common import (
    ENGINE_EXCITATION,
    StudyError,
    engine_excited,
    friction_energy,
    load_system,
    mount_position,
    relocate_mount,
    with_friction_of,
    with_normal_force,
    with_stiffness_factor,
)
from drymount.studies.hydraulic import run_hydraulic
from drymount.studies.jump import run_jump
from drymount.studies.laws import run_laws
from drymount.studies.normal_force import run_normal_force
from drymount.studies.optimize_n0 import OPT_PEAK_BAND_HZ, run_optimize_n0
from drymount.studies.quarter_car import run_quarter_car
from drymount.studies.six_dof import run_six_dof
from drymount.studies.six_dof_75 import run_six_dof_75

__all__ = [
    "STUDIES",
    "ENGINE_EXCITATION",
    "ExitStatus",
    "StudyError",
    "main",
    "run_normal_force",
    "run_optimize_n0",
    "run_quarter_car",
    "run_six_dof",
    "run_jump",
    "run_laws",
    "run_six_dof_75",
    "run_hydraulic",
    "load_system",
    "with_normal_force",
    "with_stiffness_factor",
    "with_friction_of",
    "relocate_mount",
    "mount_position",
    "engine_excited",
    "friction_energy",
    "OPT_PEAK_BAND_HZ",
]
