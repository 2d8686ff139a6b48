"""Drive the mount FMU through fmpy with sequences of FMI calls read from stdin.

Run as a script: ``python fmi_sequence_drive.py UNZIPDIR``; reads one JSON list of
calls per line, answers one JSON object per line. Used by
``tests/test_fmu_calls.py`` in a subprocess, so that a crash of the importer process
(a fatal error, a segfault) is seen by the test instead of killing it.

A call is ``[name, *args]``: ``setup t0``, ``enter``, ``exit``, ``terminate``,
``reset``, ``setReal var value``, ``setInteger var value``, ``setBoolean var value``,
``getReal var...``, ``doStep t h``, ``getState``, ``setState k`` (the k-th saved
state). The answer lists ``[status, values]`` per call (status 0 ok, 3 error, 4
fatal; values for getReal), the probe after every rejected call (getReal of every
output: the instance must still answer, with finite values) and ``usable``: after
the sequence, fmi2Reset and a valid run (setup, enter, exit, three steps, outputs)
all succeeded with finite outputs; ``errors_logged``: the messages of status error the
instance logged (instantiated with loggingOn, as pythonfmu forwards nothing otherwise;
to a logger of the driver: fmpy's default logger would print them
to stdout, this protocol's channel).
"""

from __future__ import annotations

import json
import math
import sys

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from drymount.vehicle.fmi_logging import callbacks, release

OUTPUTS = ("F_axial", "Ffr_axial", "kt_axial", "E_fr_axial", "E_fr", "F_radial1")


def _status(call) -> tuple[int, list | None]:
    try:
        out = call()
    except FMICallException as exc:
        return int(exc.status), None
    return 0, (list(out) if out is not None and not isinstance(out, int) else None)


def run_sequence(slave: FMU2Slave, vr: dict, calls: list) -> dict:
    states, answers, probes = [], [], []
    for name, *args in calls:
        if name == "setup":
            st = _status(lambda: slave.setupExperiment(startTime=args[0]))
        elif name == "enter":
            st = _status(slave.enterInitializationMode)
        elif name == "exit":
            st = _status(slave.exitInitializationMode)
        elif name == "terminate":
            st = _status(slave.terminate)
        elif name == "reset":
            st = _status(slave.reset)
        elif name in ("setReal", "setInteger", "setBoolean"):
            fn = getattr(slave, name)
            st = _status(lambda fn=fn: fn([vr[args[0]]], [args[1]]))
        elif name == "getReal":
            st = _status(lambda: slave.getReal([vr[v] for v in args]))
        elif name == "doStep":
            st = _status(lambda: slave.doStep(args[0], args[1]))
        elif name == "getState":
            try:
                states.append(slave.getFMUstate())
                st = (0, None)
            except FMICallException as exc:
                st = (int(exc.status), None)
        elif name == "setState":
            st = _status(lambda: slave.setFMUstate(states[args[0]]))
        else:
            raise ValueError(f"unknown call {name!r}")
        answers.append(list(st))
        if st[0] == 4:
            break  # fatal: only fmi2FreeInstance is allowed
        if st[0] != 0:
            probe = _status(lambda: slave.getReal([vr[v] for v in OUTPUTS]))
            probes.append(list(probe))
    return {"answers": answers, "probes": probes, "usable": usable(slave, vr)}


def usable(slave: FMU2Slave, vr: dict) -> bool:
    """fmi2Reset, then a valid run: every call OK and the outputs finite."""
    try:
        slave.reset()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        for k in range(3):
            slave.setReal([vr["u_axial"], vr["v_axial"]], [1e-3 * k, 0.1])
            values = slave.getReal([vr[v] for v in OUTPUTS])
            if not all(math.isfinite(x) for x in values):
                return False
            slave.doStep(k * 1e-4, 1e-4)
        slave.terminate()
    except FMICallException:
        return False
    return True


def main(unzipdir: str) -> None:
    md = read_model_description(unzipdir)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    n = 0
    for line in sys.stdin:
        calls = json.loads(line)
        slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                          modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName=f"seq{n}")
        logged = []
        cb = callbacks(lambda env, inst, status, cat, msg: logged.append(status))
        slave.instantiate(callbacks=cb, loggingOn=True)
        result = run_sequence(slave, vr, calls)
        slave.freeInstance()
        release(cb)
        result["errors_logged"] = logged.count(3)
        n += 1
        sys.stdout.write(json.dumps(result) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main(sys.argv[1])
