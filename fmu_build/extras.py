"""Files every FrictionMount FMU carries beside its model: the licence and the
reference experiment (FMI-LS-REF, ``extra/org.fmi-standard.fmi-ls-ref/``).

The reference experiment is one run at the FMU's default parameters: a sine of the
deflection on two axes (axial and radial1, different amplitudes and frequencies,
``v = du/dt``), stimuli and results as CSV in the FMI cross-check format (a ``time``
column, then one column per variable). The results are computed here, at build time,
by the mount law in-process (``fmu_src.mount_law.axis_force``) with the protocol of
a co-simulation master that reads outputs after ``doStep`` (fmpy, fmusim, the
cross-check): the row at t_0 holds the outputs after initialisation with the inputs
of t_0, the row at t_k+1 those after ``doStep(t_k, h)`` with the inputs of t_k.
``drymount export-xc`` writes the same run as an FMI cross-check folder.

Examples
--------
>>> from drymount.fmu_build.extras import reference_run
>>> run = reference_run()
>>> run.results_names
('F_axial', 'F_radial1')
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from drymount.fmu_src.mount_law import AxisParameters, axis_force, initial_sliders

__all__ = ["LS_REF_DIR", "REFERENCE", "ReferenceRun", "csv_text", "fmu_extras",
           "opt_text", "reference_run"]

#: Folder of the FMI-LS-REF files inside an FMU.
LS_REF_DIR = "extra/org.fmi-standard.fmi-ls-ref"
#: The reference experiment: start, stop, communication step (s), the tolerance the
#: cross-check's ``_ref.opt`` requires (unused by a co-simulation FMU), and per
#: driven axis (amplitude m, frequency Hz).
REFERENCE = {"startTime": 0.0, "stopTime": 0.1, "stepSize": 1e-4, "tolerance": 1e-6,
             "axes": {"axial": (0.004, 20.0), "radial1": (0.002, 30.0)}}
_LICENSE = Path(__file__).resolve().parent / "fmu_doc" / "licenses" / "LICENSE.txt"


@dataclass(frozen=True)
class ReferenceRun:
    """Stimuli and results of the reference experiment: ``time`` (s) and per row the
    values of ``stimuli_names`` / ``results_names``."""

    time: tuple[float, ...]
    stimuli_names: tuple[str, ...]
    stimuli: tuple[tuple[float, ...], ...]
    results_names: tuple[str, ...]
    results: tuple[tuple[float, ...], ...]


def _stimuli(t: float) -> list[float]:
    row = []
    for x, f in REFERENCE["axes"].values():
        w = 2.0 * math.pi * f
        row += [x * math.sin(w * t), x * w * math.cos(w * t)]
    return row


def reference_run() -> ReferenceRun:
    """The reference experiment computed by the mount law (see the module text)."""
    h, t0 = REFERENCE["stepSize"], REFERENCE["startTime"]
    n = round((REFERENCE["stopTime"] - t0) / h)
    time = [t0 + k * h for k in range(n + 1)]
    stimuli = [_stimuli(t) for t in time]
    p = AxisParameters()  # the FMU's default parameters, every axis
    axes = list(REFERENCE["axes"])
    w = [initial_sliders(p) for _ in axes]

    def outputs(row):
        return tuple(axis_force(row[2 * i], row[2 * i + 1], w[i], p, dt=h).force
                     for i in range(len(axes)))

    results = [outputs(stimuli[0])]
    for row in stimuli[:-1]:
        w = [axis_force(row[2 * i], row[2 * i + 1], w[i], p, dt=h).w_new
             for i in range(len(axes))]
        results.append(outputs(row))
    return ReferenceRun(tuple(time),
                        tuple(f"{q}_{a}" for a in axes for q in ("u", "v")),
                        tuple(tuple(r) for r in stimuli),
                        tuple(f"F_{a}" for a in axes), tuple(results))


def csv_text(time, names, rows) -> str:
    """A CSV of the cross-check rules: a header of quoted names, ``time`` first, the
    values with 17 significant digits (they read back exactly)."""
    lines = [",".join(f'"{n}"' for n in ("time", *names))]
    lines += [",".join(repr(float(x)) for x in (t, *row))
              for t, row in zip(time, rows, strict=True)]
    return "\n".join(lines) + "\n"


def opt_text() -> str:
    """The cross-check ``_ref.opt`` of the reference experiment."""
    return (f"StartTime, {REFERENCE['startTime']!r}\n"
            f"StopTime, {REFERENCE['stopTime']!r}\n"
            f"StepSize, {REFERENCE['stepSize']!r}\n"
            f"RelTol, {REFERENCE['tolerance']!r}\n")


def _manifest() -> bytes:
    r = REFERENCE
    axes = ", ".join(f"{a} {x * 1e3:g} mm at {f:g} Hz"
                     for a, (x, f) in r["axes"].items())
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<fmiReferences xmlns:fmi-ls="http://fmi-standard.org/fmi-ls-manifest"\n'
        '    fmi-ls:fmi-ls-name="org.fmi-standard.fmi-ls-ref"\n'
        '    fmi-ls:fmi-ls-version="1.0.0-rc.1"\n'
        '    fmi-ls:fmi-ls-description="Layered Standard providing reference stimuli '
        'and results for an FMU.">\n'
        f'  <Experiment name="sine" description="default parameters; sine deflection '
        f'({axes}), v = du/dt; results computed by the mount law, outputs read after '
        f'doStep" startTime="{r["startTime"]!r}" stopTime="{r["stopTime"]!r}" '
        f'stepSize="{r["stepSize"]!r}" tolerance="{r["tolerance"]!r}">\n'
        '    <Stimuli source="sine_in.csv"/>\n'
        '    <References source="sine_ref.csv"/>\n'
        '  </Experiment>\n'
        '</fmiReferences>\n').encode()


_LS_REF_DOC = """\
Reference experiment (FMI-LS-REF, extra/org.fmi-standard.fmi-ls-ref/)

fmi-ls-manifest.xml describes one experiment, "sine": the FMU's default parameters,
the inputs of sine_in.csv (u_/v_ of the axial and radial1 axes; a time column, then
one column per input, linear between rows), a communication step of 1e-4 s from 0 to
0.1 s, and the outputs of sine_ref.csv computed by drymount's mount law at build time.
A master that sets the inputs at t_k, calls doStep(t_k, h) and reads the outputs at
t_k+1 (fmpy, fmusim) reproduces sine_ref.csv to rounding.
"""


def _license() -> bytes:
    """drymount's MIT licence (the block of the PythonFMU build's LICENSE.txt),
    without the PythonFMU part that build needs."""
    text = _LICENSE.read_text()
    start = text.index("MIT License")
    end = text.index("SOFTWARE.\n", start) + len("SOFTWARE.\n")
    return ("FrictionMount native FMU (sources/, binaries/, documentation/, extra/): "
            "drymount\n\n" + text[start:end]).encode()


def fmu_extras() -> dict[str, bytes]:
    """Files (zip name -> bytes) to add to a FrictionMount FMU: the licence
    (``documentation/licenses/``) and the reference experiment (``extra/``)."""
    run = reference_run()
    return {
        "documentation/licenses/LICENSE.txt": _license(),
        "documentation/fmi-ls-ref.txt": _LS_REF_DOC.encode(),
        f"{LS_REF_DIR}/fmi-ls-manifest.xml": _manifest(),
        f"{LS_REF_DIR}/sine_in.csv": csv_text(run.time, run.stimuli_names,
                                              run.stimuli).encode(),
        f"{LS_REF_DIR}/sine_ref.csv": csv_text(run.time, run.results_names,
                                               run.results).encode(),
    }
