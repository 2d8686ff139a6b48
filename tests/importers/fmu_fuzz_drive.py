"""Drive one mount FMU (FMI 2.0 or 3.0, any build) through one sequence of FMI calls,
corrupted serialized states included; used by tests/test_fmu_fuzz.py and
tests/test_fmu_paths.py, one process per sequence, so that a crash is seen by the test.

``python fmu_fuzz_drive.py UNZIPDIR`` reads one JSON list of calls per line from
stdin and prints one JSON object per line. A call is ``[name, *args]``: ``setup
t0``, ``enter``, ``exit``, ``terminate``, ``reset``, ``setReal|setInteger|setBoolean
var value``, ``getReal var...`` (none: every Real output), ``doStep t h``,
``getState`` (saved as the next state index), ``setState k``, ``serialize k`` (the
bytes of state k, saved as the next blob index), ``load k kind *args``: blob k
corrupted by ``kind``, deserialized and set. Kinds: ``asis``, ``empty``, ``truncate
n``, ``random seed length``, ``word offset what [fix]`` (the 4 bytes at ``offset``
become 0x7fffffff, or the 8 bytes the double ``nan``/``inf``/``-inf``; ``fix``
recomputes the checksum).

Answer: ``answers`` (``[status, values, messages]`` per call: status 0 ok, 1
warning, 3 error, 4 fatal; the Real values read; the number of messages of status
error the call logged), ``probes`` (after every refused call: getReal of every Real
output, ``[status, values]``), ``usable`` (after the sequence: reset, a valid run
with finite outputs), ``blob_sizes``.
"""

from __future__ import annotations

import json
import math
import random
import struct
import sys

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException


class Slave:
    """FMU2Slave or FMU3Slave behind one set of names."""

    def __init__(self, unzipdir: str):
        self.md = md = read_model_description(unzipdir)
        self.fmi3 = md.fmiVersion.startswith("3")
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.outputs = [v.valueReference for v in md.modelVariables
                        if v.causality == "output" and v.type in ("Real", "Float64")]
        self.errors = 0
        kw = dict(guid=md.guid, unzipDirectory=unzipdir,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="fuzz")
        if self.fmi3:
            from fmpy.fmi3 import FMU3Slave

            self.fmu = FMU3Slave(**kw)
            self.fmu.instantiate(loggingOn=True, logMessage=self._log3)
        else:
            from fmpy.fmi2 import FMU2Slave

            from drymount.vehicle.fmi_logging import callbacks

            self.fmu = FMU2Slave(**kw)
            self._cb = callbacks(self._log2)
            self.fmu.instantiate(callbacks=self._cb, loggingOn=True)
        self.start = 0.0

    def _log2(self, env, inst, status, cat, msg):
        self.errors += status >= 3 and bool(msg)

    def _log3(self, env, status, cat, msg):
        self.errors += status >= 3 and bool(msg)

    def free(self):
        self.fmu.freeInstance()
        if not self.fmi3:
            from drymount.vehicle.fmi_logging import release

            release(self._cb)

    # one method per call name
    def setup(self, t0):
        if self.fmi3:  # FMI 3.0 takes the start time at initialization
            self.start = t0
            return None
        return self.fmu.setupExperiment(startTime=t0)

    def enter(self):
        if self.fmi3:
            return self.fmu.enterInitializationMode(startTime=self.start)
        return self.fmu.enterInitializationMode()

    def exit(self):
        return self.fmu.exitInitializationMode()

    def terminate(self):
        return self.fmu.terminate()

    def reset(self):
        return self.fmu.reset()

    def set(self, kind, name, value):
        fn = {"setReal": "setFloat64", "setInteger": "setInt32",
              "setBoolean": "setBoolean"}[kind] if self.fmi3 else kind
        return getattr(self.fmu, fn)([self.vr[name]], [value])

    def get_real(self, vrs):
        return list((self.fmu.getFloat64 if self.fmi3 else self.fmu.getReal)(vrs))

    def do_step(self, t, h):
        self.fmu.doStep(t, h)

    def get_state(self):
        return (self.fmu.getFMUState if self.fmi3 else self.fmu.getFMUstate)()

    def set_state(self, s):
        (self.fmu.setFMUState if self.fmi3 else self.fmu.setFMUstate)(s)

    def serialize(self, s) -> bytes:
        if self.fmi3:
            return bytes(self.fmu.serializeFMUState(s))
        return bytes(self.fmu.serializeFMUstate(s))

    def deserialize(self, blob: bytes):
        if self.fmi3:
            return self.fmu.deserializeFMUState(blob)
        return self.fmu.deSerializeFMUstate(blob)


def corrupt(blob: bytes, kind: str, *args) -> bytes:
    if kind == "asis":
        return blob
    if kind == "empty":
        return b""
    if kind == "truncate":
        return blob[:args[0]]
    if kind == "random":
        rng = random.Random(args[0])
        return bytes(rng.randrange(256) for _ in range(args[1]))
    if kind == "word":  # word offset what [fix]: fix = recompute the checksum
        offset, what = args[:2]
        out = bytearray(blob)
        if what == "int":
            out[offset:offset + 4] = struct.pack("<i", 0x7FFFFFFF)
        else:
            out[offset:offset + 8] = struct.pack("<d", float(what))
        out = out[:len(blob)]
        return fix_checksum(bytes(out)) if args[2:] == ["fix"] else bytes(out)
    raise ValueError(f"unknown corruption {kind!r}")


def fix_checksum(blob: bytes) -> bytes:
    """``blob`` with its checksum recomputed (docs/fmu.md "FMU state"), so that a
    corrupted field reaches the range checks: native ``DMNTST07`` + data + FNV-1a
    64 (little endian) of the data; PythonFMU ``DMPYST01`` + SHA-256 hex + payload."""
    import hashlib

    if blob.startswith(b"DMNTST"):
        h = 14695981039346656037
        for byte in blob[8:-8]:
            h = ((h ^ byte) * 1099511628211) % 2**64
        return blob[:-8] + struct.pack("<Q", h)
    if blob.startswith(b"DMPYST"):
        payload = blob[72:]
        return blob[:8] + hashlib.sha256(payload).hexdigest().encode() + payload
    return blob


def _call(slave: Slave, states: list, blobs: list, name: str, args: list):
    if name in ("setup", "enter", "exit", "terminate", "reset"):
        getattr(slave, name)(*args)
    elif name.startswith("set") and name != "setState":
        slave.set(name, *args)
    elif name == "getReal":  # no names: every Real output
        return slave.get_real([slave.vr[v] for v in args] if args else slave.outputs)
    elif name == "doStep":
        slave.do_step(*args)
    elif name == "getState":
        states.append(slave.get_state())
    elif name == "setState":
        slave.set_state(states[args[0]])
    elif name == "serialize":
        blobs.append(slave.serialize(states[args[0]]))
    elif name == "load":
        state = slave.deserialize(corrupt(blobs[args[0]], *args[1:]))
        states.append(state)
        slave.set_state(state)
    else:
        raise ValueError(f"unknown call {name!r}")
    return None


def run(slave: Slave, calls: list) -> dict:
    states, blobs, answers, probes = [], [], [], []
    for name, *args in calls:
        before = slave.errors
        try:
            values, status = _call(slave, states, blobs, name, args), 0
        except FMICallException as exc:
            values, status = None, int(exc.status)
        answers.append([status, values, slave.errors - before])
        if status >= 4:
            break
        if status:
            try:
                probes.append([0, slave.get_real(slave.outputs)])
            except FMICallException as exc:
                probes.append([int(exc.status), None])
    return {"answers": answers, "probes": probes, "usable": usable(slave),
            "blob_sizes": [len(b) for b in blobs]}


def usable(slave: Slave) -> bool:
    """reset, then a valid run: every call OK and every Real output finite."""
    try:
        slave.reset()
        slave.setup(0.0)
        slave.enter()
        slave.exit()
        for k in range(3):
            slave.set("setReal", "u_axial", 1e-3 * k)
            if not all(math.isfinite(x) for x in slave.get_real(slave.outputs)):
                return False
            slave.do_step(k * 1e-4, 1e-4)
        slave.terminate()
    except FMICallException:
        return False
    return True


def main(unzipdir: str) -> None:
    slave = Slave(unzipdir)
    for line in sys.stdin:
        result = run(slave, json.loads(line))
        result["errors_logged"] = slave.errors
        sys.stdout.write(json.dumps(result) + "\n")
        sys.stdout.flush()
        slave.errors = 0
    slave.free()


if __name__ == "__main__":
    main(sys.argv[1])
