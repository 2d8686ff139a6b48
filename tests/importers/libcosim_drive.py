"""Drive the mount FMU through libcosim (libcosimpy), a C++ FMI 2.0 importer.

Run as a script: ``python libcosim_drive.py FMU``; prints one JSON object. Other
modes (one JSON object each):

* ``--ssp-bad NAME=VALUE[,NAME=VALUE...] ...``: each argument a bad-parameter case,
  all in this one process: an SSP (a folder with ``SystemStructure.ssd`` and the FMU)
  with one instance, friction on and those parameter values, whose default experiment
  asks libcosim for a fixed-step algorithm with ``numWorkerThreads="0"`` (the OSP
  annotation libcosim's SSP parser reads), loaded with
  ``CosimExecution.from_ssp_file``; one step each. Then the run of the default mode.
  ``{"cases": [{"step_ok": ..., "message": ...}, ...], "after": {...}}``.
* ``--bad NAME=VALUE ...``: the same through ``CosimExecution.from_step_size``, whose
  algorithm has libcosimc's default thread pool: libcosim runs initialization in a
  worker thread without a catch and the FMU's fmi2Error there is std::terminate
  (docs/fmu.md 4a); this mode documents that.
* ``--exported FOLDER``: an archive of ``drymount export-ssp``, extracted to FOLDER,
  loaded with ``CosimExecution.from_ssp_file`` as it is (its default experiment's
  OSP annotation: fixed step, no worker thread): 3 steps.
  ``{"instances": ..., "steps_ok": [...], "messages": [...]}`` (a failed step's
  error message, else "").
* ``--nan-input``: a good run of a few steps, then ``u_axial = NaN`` through the
  override manipulator: the FMU refuses the fmi2SetReal (fmi2Error) inside libcosim's
  step, which libcosimc catches: ``cosim_execution_step`` fails and
  ``cosim_last_error_message`` names the value; then the run of the default mode in
  the same process.

Used by ``tests/test_fmu_libcosim.py`` in a subprocess, so that the importer's
process holds nothing but libcosim, the FMU and (for the reference) the mount law.

Two instances of the FMU in one execution (different normal forces), the axial
deflection a sine ``X sin(omega t)`` set through libcosim's override manipulator before
each step, the outputs read with its last-value observer after each step. The
reference is :mod:`fmu_src.mount_law` stepped in-process with the same inputs.
"""

from __future__ import annotations

import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave
from libcosimpy._internal import get_last_error_message

H = 1e-4           # s, communication step
X, FREQ = 0.002, 5.0   # m, Hz: the sine deflection
KF = 60000.0       # N/m
N0 = (20.0, 10.0)  # N, normal force of each instance (mu = 1)
CYCLES = 3


def main(fmu: str) -> dict:
    from drymount.fmu_src.mount_law import AxisParameters, axis_force

    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_step_size(step_size=int(round(H * 1e9)))
    idx = [ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name=f"mount{i}"))
           for i in range(len(N0))]
    ref = {v.name.decode(): v.reference for v in ex.slave_variables(idx[0])}
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    man = CosimManipulator.create_override()
    ex.add_manipulator(man)
    for i, n0 in zip(idx, N0, strict=True):
        ex.boolean_initial_value(i, ref["axial_friction"], True)
        ex.real_initial_value(i, ref["axial_n0"], n0)
        ex.real_initial_value(i, ref["axial_kf"], KF)
    params = [AxisParameters(friction=True, n0=n0, kf=KF) for n0 in N0]
    w_law = [0.0 for _ in N0]
    omega = 2 * math.pi * FREQ
    n_per = int(round(1 / (FREQ * H)))
    worst, peak = 0.0, 0.0
    energy = [[] for _ in N0]
    for k in range(CYCLES * n_per + 1):
        t = k * H
        u, v = X * math.sin(omega * t), X * omega * math.cos(omega * t)
        for i in idx:
            man.slave_real_values(i, [ref["u_axial"], ref["v_axial"]], [u, v])
        if not ex.step(1):
            raise RuntimeError(f"libcosim step failed at t = {t}")
        for j, i in enumerate(idx):
            F, E = obs.last_real_values(i, [ref["F_axial"], ref["E_fr_axial"]])
            f_law, _, w_law[j], _, _, _ = axis_force(u, v, w_law[j], params[j])
            worst = max(worst, abs(F - f_law))
            peak = max(peak, abs(f_law))
            energy[j].append(E)
    loops = [e[-1] - e[-1 - n_per] for e in energy]
    closed = [4 * n0 * (X - n0 / KF) for n0 in N0]
    return dict(steps=CYCLES * n_per + 1, instances=len(idx),
                max_abs_force_diff=worst, peak_force=peak, loop_energy=loops,
                closed_form=closed,
                time=ex.status().current_time * 1e-9)


def bad_parameters(fmu: str, settings: list[str]) -> dict:
    """One instance with friction on and ``NAME=VALUE`` parameter start values: the
    first step (initialization) must fail cleanly."""
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_step_size(step_size=int(round(H * 1e9)))
    i = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name="bad"))
    ref = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
    ex.boolean_initial_value(i, ref["axial_friction"], True)
    for item in settings:
        name, _, value = item.partition("=")
        ex.real_initial_value(i, ref[name], float(value))
    ok = bool(ex.step(1))
    second = bool(ex.step(1))
    return dict(step_ok=ok, second_step_ok=second, survived=True,
                time=ex.status().current_time * 1e-9)


SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription name="bad-parameters" version="1.0"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations">
  <ssd:System name="mounts">
    <ssd:Elements>
      <ssd:Component name="mount" source="{fmu}">
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="case">
                <ssv:Parameters>
{parameters}
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm>
          <osp:FixedStepAlgorithm baseStepSize="{h!r}" numWorkerThreads="0"/>
        </osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def _ssp_folder(folder: Path, fmu: str, settings: list[str]) -> Path:
    """An SSP folder: the FMU and a SystemStructure.ssd setting friction on and the
    given ``NAME=VALUE`` reals, with a fixed-step algorithm on no worker thread."""
    shutil.copy(fmu, folder / Path(fmu).name)
    lines = ['<ssv:Parameter name="axial_friction"><ssv:Boolean value="true"/>'
             '</ssv:Parameter>']
    for item in settings:
        name, _, value = item.partition("=")
        lines.append(f'<ssv:Parameter name="{name}">'
                     f'<ssv:Real value="{float(value)!r}"/></ssv:Parameter>')
    (folder / "SystemStructure.ssd").write_text(SSD.format(
        fmu=Path(fmu).name, parameters="\n".join(lines), h=H))
    return folder


def ssp_bad(fmu: str, cases: list[str]) -> dict:
    """Each bad-parameter case in an SSP with numWorkerThreads = 0: the first step
    fails with the FMU's message; then the default run in the same process. (Log
    level debug: libcosim logs each FMI call it makes, so the test sees which call
    failed.)"""
    log_output_level(CosimLogLevel.DEBUG)
    results = []
    for case in cases:
        with tempfile.TemporaryDirectory(prefix="drymount-ssp-") as tmp:
            ex = CosimExecution.from_ssp_file(str(_ssp_folder(Path(tmp), fmu,
                                                              case.split(","))))
            ok = bool(ex.step(1))
            results.append(dict(step_ok=ok, message=get_last_error_message()))
            del ex  # cosim_execution_destroy: frees the instance before the folder
    return dict(cases=results, after=main(fmu))


def nan_input(fmu: str) -> dict:
    """Three good steps, then a NaN input: the step fails with the FMU's message;
    then the default run in the same process."""
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_step_size(step_size=int(round(H * 1e9)))
    i = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name="nan"))
    ref = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
    man = CosimManipulator.create_override()
    ex.add_manipulator(man)
    good = []
    for k in range(3):
        man.slave_real_values(i, [ref["u_axial"]], [1e-4 * k])
        good.append(bool(ex.step(1)))
    man.slave_real_values(i, [ref["u_axial"]], [math.nan])
    failed_step_ok = bool(ex.step(1))
    message = get_last_error_message()
    return dict(good_steps_ok=good, nan_step_ok=failed_step_ok, message=message,
                after=main(fmu))


def exported(folder: str) -> dict:
    """Three steps of an extracted ``drymount export-ssp`` archive, as exported."""
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_ssp_file(folder)
    n = len(ex.slave_infos())
    steps, messages = [], []
    for _ in range(3):
        steps.append(bool(ex.step(1)))
        messages.append(get_last_error_message() if not steps[-1] else "")
    return dict(instances=n, steps_ok=steps, messages=messages)


if __name__ == "__main__":
    if "--ssp-bad" in sys.argv:
        print(json.dumps(ssp_bad(sys.argv[1],
                                 sys.argv[sys.argv.index("--ssp-bad") + 1:])))
    elif "--exported" in sys.argv:
        print(json.dumps(exported(sys.argv[sys.argv.index("--exported") + 1])))
    elif "--nan-input" in sys.argv:
        print(json.dumps(nan_input(sys.argv[1])))
    elif "--bad" in sys.argv:
        print(json.dumps(bad_parameters(sys.argv[1],
                                        sys.argv[sys.argv.index("--bad") + 1:])))
    else:
        print(json.dumps(main(sys.argv[1])))
