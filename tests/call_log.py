"""FMI 2.0 call logs of an importer, and their replay in fmpy.

``tests/importers/fmi2_call_log.c`` is a shared library that exports the FMI 2.0
functions, forwards every call to the real FMU binary and writes one line per call of
interest to ``$FMI_CALL_LOG`` (instance, call, arguments; reals as ``%.17g``).
:func:`logging_fmu` puts it into a copy of an FMU (the real binary beside it as
``<id>.real.so``), :func:`logging_ssp` into a copy of an SSP archive. :func:`parse`
reads a log into per-instance call lists; :func:`replay` makes the same calls, in the
same order and with the same arguments, on the real FMU in fmpy and returns what each
``fmi2GetReal`` gave there, to compare with what the importer got.
"""

from __future__ import annotations

import shutil
import subprocess
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

SHIM_SOURCE = Path(__file__).parent / "importers" / "fmi2_call_log.c"


@dataclass
class Call:
    """One logged call: its name and its arguments (``key=value`` pairs in order)."""

    name: str
    args: list[tuple[str, str]] = field(default_factory=list)

    def reals(self) -> tuple[list[int], list[float]]:
        return [int(k) for k, _ in self.args], [float(v) for _, v in self.args]

    def ints(self) -> tuple[list[int], list[int]]:
        return [int(k) for k, _ in self.args], [int(v) for _, v in self.args]

    def arg(self, key: str) -> str:
        return dict(self.args)[key]


def build_shim(folder: Path) -> Path:
    """Compile the call logger into ``folder/fmi2_call_log.so`` (needs gcc)."""
    so = folder / "fmi2_call_log.so"
    subprocess.run(["gcc", "-O1", "-shared", "-fPIC", "-o", str(so), str(SHIM_SOURCE),
                    "-ldl"], check=True, capture_output=True)
    return so


def logging_fmu(fmu: Path, out: Path, shim: Path) -> Path:
    """A copy of ``fmu`` whose linux64 binary is the call logger ``shim``."""
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(out, "w",
                                                      zipfile.ZIP_DEFLATED) as z:
        for name in zin.namelist():
            data = zin.read(name)
            if name.startswith("binaries/linux64/") and name.endswith(".so"):
                z.writestr(name[:-3] + ".real.so", data)
                data = shim.read_bytes()
            z.writestr(name, data)
    return out


def logging_ssp(ssp: Path, out: Path, shim: Path) -> Path:
    """A copy of the SSP archive ``ssp`` with every FMU in it made a logging copy."""
    work = out.parent / (out.stem + "_fmus")
    work.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(ssp) as zin, zipfile.ZipFile(out, "w",
                                                      zipfile.ZIP_DEFLATED) as z:
        for name in zin.namelist():
            data = zin.read(name)
            if name.endswith(".fmu"):
                src = work / Path(name).name
                src.write_bytes(data)
                logged = logging_fmu(src, work / ("logging_" + src.name), shim)
                data = logged.read_bytes()
            z.writestr(name, data)
    return out


def parse(path: Path) -> dict[str, list[Call]]:
    """The log's calls per instance, in order."""
    calls: dict[str, list[Call]] = {}
    for line in Path(path).read_text().splitlines():
        instance, name, *rest = line.split(" ")
        args = [tuple(item.split("=", 1)) for item in rest]
        calls.setdefault(instance, []).append(Call(name, args))
    return calls


def replay(fmu: Path, instance: str, calls: list[Call]) -> list[list[float]]:
    """Make ``calls`` on ``fmu`` in fmpy; the values of every ``getReal`` in order."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    folder = extract(str(fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=folder, instanceName=instance,
                      modelIdentifier=md.coSimulation.modelIdentifier)
    got = []
    try:
        for call in calls:
            got += _replay_one(slave, call)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return got


def _replay_one(slave, call: Call) -> list[list[float]]:
    n = call.name
    if n == "instantiate":
        slave.instantiate()
    elif n == "setupExperiment":
        tol = float(call.arg("tol")) if call.arg("tol_defined") != "0" else None
        stop = float(call.arg("stop")) if call.arg("stop_defined") != "0" else None
        slave.setupExperiment(tolerance=tol, startTime=float(call.arg("start")),
                              stopTime=stop)
    elif n in ("enterInitializationMode", "exitInitializationMode", "terminate",
               "freeInstance", "reset"):
        getattr(slave, n)()
    elif n == "setReal":
        slave.setReal(*call.reals())
    elif n in ("setInteger", "setBoolean"):
        vrs, values = call.ints()
        if n == "setInteger":
            slave.setInteger(vrs, values)
        else:
            slave.setBoolean(vrs, [v != 0 for v in values])
    elif n == "getReal":
        return [slave.getReal(call.reals()[0])]
    elif n == "doStep":
        slave.doStep(float(call.arg("t")), float(call.arg("h")))
    else:
        raise ValueError(f"replay: no replay for the logged call {n!r}")
    return []
