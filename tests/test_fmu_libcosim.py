"""The mount FMUs (PythonFMU and native) in libcosim (Open Simulation Platform), a C++
FMI 2.0 importer that is not fmpy.

* libcosimpy (Python bindings of libcosimc, libcosim's C API): two instances side by
  side, inputs through the override manipulator, outputs through the last-value
  observer, against the in-process law; an FMU error during a step (a NaN input
  refused by fmi2SetReal) is a failed ``cosim_execution_step`` with the FMU's message
  and the process goes on.
* issue 11, bad parameters, with libcosim's fixed-step algorithm on zero worker
  threads, the setting under which libcosim lets an FMU error during initialization
  reach the host: (a) libcosimpy loading an SSP whose default experiment says
  ``numWorkerThreads="0"``; (b) a C++ host on libcosim's C++ API
  (``tests/importers/libcosim_host.cpp``). Every bad-parameter case is refused by
  fmi2ExitInitializationMode, the host gets an error status (a failed step, a
  ``cosim::error``) with the FMU's message and survives, and a good run in the same
  process afterwards equals the law.
* with its default thread pool (``hardware_concurrency() - 1`` threads, what
  ``cosim_execution_create`` and so ``CosimExecution.from_step_size`` use) libcosim
  runs initialization in a worker thread without a catch: a bad parameter ends the
  host with std::terminate, whatever the FMU returns. Pinned here so that a libcosim
  that changes it is noticed (docs/fmu.md 4a names the source lines).

libcosimpy ships wheels for CPython >= 3.11 on linux x86_64 only (the `test` extra
installs it there); elsewhere this module is skipped and the plain C importer of
``tests/test_fmu.py`` remains the non-fmpy check. The C++ host also needs g++ and the
Boost and GSL headers (``apt-get install libboost-dev libmsgsl-dev``): its tests are
skipped without them. Runtime ~35 s (two FMU builds, one C++ compile, 10 libcosim
runs).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from drymount.fmu_build import build_fmu

pytest.importorskip("libcosimpy", reason="libcosimpy is not installed (the test extra "
                    "installs it on CPython >= 3.11, linux x86_64)")

IMPORTERS = Path(__file__).parent / "importers"
DRIVER = IMPORTERS / "libcosim_drive.py"
REPO = Path(__file__).resolve().parent.parent

# the FMU's force equals the in-process law's step for step (issue 2: 1e-12
# relative, here to the peak force of the run); measured 2.8e-14 N of 204 N (1.4e-16)
RTOL_FORCE = 1e-12
# friction energy over the last of 3 cycles against 4 Fs (X - Fs/kf): the loop is
# exact (piecewise-linear return map, no sampling error); measured 3e-15
RTOL_LOOP = 1e-12


@pytest.fixture(scope="module", params=["pythonfmu", "native"])
def fmu(request, tmp_path_factory):
    """The PythonFMU build (with the linux64 loader) or the native FMI 2.0 build."""
    folder = tmp_path_factory.mktemp(request.param)
    if request.param == "pythonfmu":
        return build_fmu(folder / "FrictionMount.fmu")
    from drymount.fmu_build.native import build_native_fmu

    return build_native_fmu(folder / "FrictionMountNative.fmu").path


def _run(args, cwd) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return subprocess.run(args, capture_output=True, text=True, timeout=300, env=env,
                          cwd=cwd)


def _check_good_run(res: dict) -> None:
    """The default run of libcosim_drive.py: forces equal the law, exact loops."""
    assert res["instances"] == 2 and res["steps"] == 6001
    assert res["time"] == pytest.approx(0.6001, rel=1e-9)
    assert res["max_abs_force_diff"] <= RTOL_FORCE * res["peak_force"]
    assert res["peak_force"] > 100.0  # k1 X + c omega X + Fs = 204 N: it moved
    for got, ref in zip(res["loop_energy"], res["closed_form"], strict=True):
        assert got == pytest.approx(ref, rel=RTOL_LOOP)


def test_fmu_runs_in_libcosim(fmu, tmp_path):
    out = _run([sys.executable, str(DRIVER), str(fmu)], tmp_path)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    _check_good_run(json.loads(out.stdout.strip().splitlines()[-1]))


def test_error_during_a_step_is_a_failed_step_not_a_crash(fmu, tmp_path):
    """libcosimc catches what happens in a step: the FMU refuses u_axial = NaN
    (fmi2SetReal -> fmi2Error), cosim_execution_step fails with the FMU's message, the
    host process goes on and a new execution in it runs correctly."""
    out = _run([sys.executable, str(DRIVER), str(fmu), "--nan-input"], tmp_path)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["good_steps_ok"] == [True, True, True] and not res["nan_step_ok"], res
    assert "fmi2SetReal: `u_axial` must be finite, got nan" in res["message"], res
    _check_good_run(res["after"])




def _exported_folder(fmu, folder: Path, kf: float | None = None) -> Path:
    """``drymount export-ssp`` of sdof_halved with this FMU inside, extracted; with
    ``kf`` the parameter set's ``axial_kf`` edited to it (as a user might)."""
    import zipfile
    from xml.etree import ElementTree as ET

    from drymount.config import load_preset
    from drymount.ssp import SSV, export_ssp

    archive = export_ssp(load_preset("sdof_halved"), folder / "sdof.ssp",
                         fmu_path=fmu).path
    out = folder / "extracted"
    zipfile.ZipFile(archive).extractall(out)
    if kf is not None:
        (ssv,) = (out / "resources").glob("*.ssv")
        tree = ET.parse(ssv)
        (par,) = [p for p in tree.iter(f"{{{SSV}}}Parameter")
                  if p.get("name") == "axial_kf"]
        par.find(f"{{{SSV}}}Real").set("value", repr(kf))
        tree.write(ssv, xml_declaration=True, encoding="UTF-8")
    return out


def test_exported_ssp_runs_in_libcosim_and_survives_a_bad_parameter(fmu, tmp_path):
    """The archive of ``drymount export-ssp`` loads in libcosim as it is and steps;
    its default experiment's annotation (fixed step, no worker thread) makes an
    edited bad parameter a failed step with the FMU's message, not the end of the
    host (libcosim's default pool would std::terminate, pinned below)."""
    good = _exported_folder(fmu, tmp_path / "good")
    out = _run([sys.executable, str(DRIVER), "--exported", str(good)], tmp_path)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["instances"] == 1 and res["steps_ok"] == [True, True, True], res
    bad = _exported_folder(fmu, tmp_path / "bad", kf=-5.0)
    out = _run([sys.executable, str(DRIVER), "--exported", str(bad)], tmp_path)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-3000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    assert res["steps_ok"][0] is False, res
    assert "`axial_kf` must be finite and > 0 when friction is on, got -5.0" in \
        res["messages"][0], res


# ======================================================================================
# Bad parameters (issue 11): libcosim hosts without worker threads survive them
# ======================================================================================

HOST_SOURCE = IMPORTERS / "libcosim_host.cpp"
#: libcosim 0.11's public headers, vendored unmodified (see its README.md)
LIBCOSIM_INCLUDE = IMPORTERS / "libcosim_include"
#: what the host's libcosim needs besides its own headers: (header, Debian package)
SYSTEM_HEADERS = (("boost/functional/hash.hpp", "libboost-dev"),
                  ("gsl/span", "libmsgsl-dev"))

#: (parameter settings with friction on, the FMU's message for them)
BAD_CASES = [
    (["axial_kf=-5"],
     "`axial_kf` must be finite and > 0 when friction is on, got -5.0"),
    (["radial1_delta=0"], "`radial1_delta` must be finite and > 0, got 0.0"),
    (["axial_mu=-1", "axial_n0=-2"],
     "`axial_mu` must be finite and >= 0, got -1.0; `axial_n0` must be finite and >= "
     "0, got -2.0"),
]
#: the good run after them: normal force [N], kf [N/m], amplitude [m], frequency [Hz],
#: step [s], cycles
GOOD = dict(n0=20.0, kf=60000.0, x=0.002, freq=5.0, h=1e-4, cycles=3)

FMI_ERROR_LOG = "[FMI status=error, category=logStatusError]"


def _has_header(gxx: str, header: str) -> bool:
    probe = subprocess.run([gxx, "-std=c++17", "-E", "-x", "c++", "-", "-o",
                            os.devnull], input=f"#include <{header}>\n",
                           capture_output=True, text=True)
    return probe.returncode == 0


@pytest.fixture(scope="module")
def cpp_host(tmp_path_factory) -> Path:
    """tests/importers/libcosim_host.cpp compiled against the vendored headers and
    linked with the libcosimc.so of the libcosimpy wheel (it exports the C++ API)."""
    gxx = shutil.which("g++")
    if gxx is None:
        pytest.skip("g++ not found: cannot compile tests/importers/libcosim_host.cpp")
    for header, package in SYSTEM_HEADERS:
        if not _has_header(gxx, header):
            pytest.skip(f"<{header}> not found: apt-get install {package}")
    libdir = Path(importlib.util.find_spec("libcosimpy").origin).parent / "libcosimc"
    exe = tmp_path_factory.mktemp("cpp_host") / "libcosim_host"
    build = subprocess.run([gxx, "-std=c++17", "-O1", "-Wall", "-Werror",
                            f"-I{LIBCOSIM_INCLUDE}", "-o", str(exe), str(HOST_SOURCE),
                            f"-L{libdir}", "-l:libcosimc.so", f"-Wl,-rpath,{libdir}"],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stderr[-3000:]
    return exe


def _law_forces(t: list[float]) -> list[float]:
    """The in-process law along the good run's sine (protocol of libcosim_drive)."""
    from drymount.fmu_src.mount_law import AxisParameters, axis_force

    p = AxisParameters(friction=True, n0=GOOD["n0"], kf=GOOD["kf"])
    omega, x, w, forces = 2 * math.pi * GOOD["freq"], GOOD["x"], 0.0, []
    for tk in t:
        f, _, w, _, _, _ = axis_force(x * math.sin(omega * tk),
                                      x * omega * math.cos(omega * tk), w, p)
        forces.append(f)
    return forces


def _failed_calls(log: str) -> list[str]:
    """For each error message of the FMU in libcosim's debug log, the FMI call
    libcosim had made last (its log line ``Calling fmi2...``)."""
    calls, end = [], log.find(FMI_ERROR_LOG)
    while end >= 0:
        calls.append(log[:end].rsplit("Calling ", 1)[1].split()[0])
        end = log.find(FMI_ERROR_LOG, end + 1)
    return calls


def test_bad_parameters_in_libcosimpy_are_failed_steps_via_ssp(fmu, tmp_path):
    """issue 11 in libcosimpy itself: each bad-parameter case as an SSP whose default
    experiment gives libcosim's fixed-step algorithm no worker thread (the OSP
    annotation ``numWorkerThreads="0"``), all in one process: fmi2ExitInitializationMode
    refuses with fmi2Error, ``ex.step()`` fails, ``cosim_last_error_message`` is the
    FMU's message; nothing is fatal; a run afterwards in the same process equals the
    law."""
    cases = [",".join(settings) for settings, _ in BAD_CASES]
    out = _run([sys.executable, str(DRIVER), str(fmu), "--ssp-bad", *cases], tmp_path)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    res = json.loads(out.stdout.strip().splitlines()[-1])
    for (_, message), case in zip(BAD_CASES, res["cases"], strict=True):
        assert not case["step_ok"] and case["message"].startswith("Model error: "), case
        assert message in case["message"], case
    assert _failed_calls(text) == ["fmi2ExitInitializationMode"] * len(BAD_CASES), \
        text[-3000:]
    assert "status=fatal" not in text and "Fatal Python error" not in text
    _check_good_run(res["after"])


def test_bad_parameters_are_an_error_the_libcosim_host_survives(cpp_host, fmu,
                                                                tmp_path):
    """issue 11: each bad-parameter case, in one host process, is refused by
    fmi2ExitInitializationMode with fmi2Error and the parameter, its value and the
    rule; libcosim hands the host a cosim::error (``Model error``) with that message;
    nothing is fatal; a good run afterwards in the same process equals the law."""
    good = "good:" + ",".join(str(GOOD[k]) for k in ("n0", "kf", "x", "freq", "h",
                                                      "cycles"))
    cases = ["bad:" + ",".join(settings) for settings, _ in BAD_CASES] + [good]
    out = _run([str(cpp_host), str(fmu), *cases], tmp_path)
    text = out.stdout + out.stderr
    assert out.returncode == 0 and out.stdout.rstrip().endswith("DONE"), text[-3000:]
    results = [json.loads(line) for line in out.stdout.splitlines()
               if line.startswith('{"case"')]
    assert [r["case"] for r in results] == list(range(len(cases)))
    for (_, message), res in zip(BAD_CASES, results, strict=False):
        assert not res["ok"] and res["errc"] == "Model error", res
        assert message in res["error"], res
    assert _failed_calls(text) == ["fmi2ExitInitializationMode"] * len(BAD_CASES), \
        text[-3000:]
    assert "status=fatal" not in text and "Fatal Python error" not in text
    res = results[-1]
    assert res["ok"], res
    law = _law_forces(res["t"])
    peak = max(abs(f) for f in law)
    assert peak > 100.0  # k1 X + c omega X + Fs = 204 N: it moved
    assert max(abs(a - b) for a, b in zip(res["F"], law, strict=True)) \
        <= RTOL_FORCE * peak
    n_per = round(1 / (GOOD["freq"] * GOOD["h"]))
    loop = res["E"][-1] - res["E"][-1 - n_per]
    closed = 4 * GOOD["n0"] * (GOOD["x"] - GOOD["n0"] / GOOD["kf"])
    assert loop == pytest.approx(closed, rel=RTOL_LOOP)


#: libcosim's thread pool lets the exception out of a worker thread (docs/fmu.md, 7)
LIBCOSIM_TERMINATES = "terminate called after throwing an instance of 'cosim::error'"


def test_libcosimc_initialization_error_is_still_std_terminate(fmu, tmp_path):
    """Pins libcosim 0.11's behaviour behind libcosimc/libcosimpy: its default thread
    pool (hardware_concurrency() - 1 workers) runs initialization without a catch, so
    the FMU's correct fmi2Error at fmi2ExitInitializationMode ends the process with
    SIGABRT; on one CPU the pool has no thread and the step fails cleanly. If this
    fails, libcosim changed (update docs/fmu.md 4a)."""
    out = _run([sys.executable, str(DRIVER), str(fmu), "--bad", "axial_kf=-5"],
               tmp_path)
    text = out.stdout + out.stderr
    assert FMI_ERROR_LOG in text and BAD_CASES[0][1] in text, text[-3000:]
    assert "status=fatal" not in text and "Fatal Python error" not in text
    if (os.cpu_count() or 1) > 1:
        assert out.returncode == -6 and LIBCOSIM_TERMINATES in text, text[-3000:]
        assert f"what():  Model error: FrictionMount: invalid parameters: " \
               f"{BAD_CASES[0][1]}" in text
    else:
        res = json.loads(out.stdout.strip().splitlines()[-1])
        assert out.returncode == 0 and not res["step_ok"], text[-3000:]
