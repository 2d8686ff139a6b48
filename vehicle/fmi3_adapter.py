"""An FMI 3.0 co-simulation FMU behind the FMI 2.0 calls the ``fmu`` backend makes.

:class:`vehicle.backends.FMUBackend` drives its instances through fmpy's ``FMU2Slave``
(``setReal``/``setInteger``/``setBoolean``/``getReal``, ``setupExperiment``,
initialization, ``terminate``/``freeInstance`` and the raw ``fmi2SetReal`` /
``fmi2GetReal`` / ``fmi2DoStep`` with ``component``). :class:`FMU3Adapter` offers the
same names on fmpy's ``FMU3Slave`` (``Float64`` for ``Real``, ``Int32`` for
``Integer``), so an FMI 3.0 build of the mount (``FrictionMountNative3.fmu``) runs in
the harness unchanged. Each raw call costs one extra Python frame.
"""

from __future__ import annotations

import ctypes

__all__ = ["FMU3Adapter"]


class FMU3Adapter:
    """``FMU3Slave`` with the FMI 2.0 method names the harness uses.

    Parameters
    ----------
    md : fmpy ModelDescription (FMI 3.0)
    unzip_dir : str
        Folder of the extracted FMU.
    instance_name : str
    logger : callable(env, instance, status, category, message)
        The harness's FMI 2.0-style logger; FMI 3.0 messages are forwarded to it with
        this instance's name.
    """

    def __init__(self, md, unzip_dir: str, instance_name: str, logger):
        from fmpy.fmi3 import FMU3Slave

        self.instanceName = instance_name
        self._fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzip_dir,
                              modelIdentifier=md.coSimulation.modelIdentifier,
                              instanceName=instance_name)
        self._logger = logger
        self._start = 0.0
        self._flags = [ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool()]
        self._last = ctypes.c_double()
        f = self._fmu
        self._set64, self._get64, self._step = (f.fmi3SetFloat64, f.fmi3GetFloat64,
                                                f.fmi3DoStep)

    def _log(self, env, status, category, message):
        name = self.instanceName.encode()
        text = message or b""
        prefix = name + b": "  # the FMU names the instance in the text (FMI 3.0)
        if text.startswith(prefix):
            text = text[len(prefix):]
        self._logger(env, name, status, category, text)

    # ------------------------------------------------------------------ life cycle
    def instantiate(self, callbacks=None, loggingOn=False) -> None:
        del callbacks  # FMI 3.0 takes the log callback directly
        self._fmu.instantiate(loggingOn=bool(loggingOn), logMessage=self._log)

    @property
    def component(self):
        return self._fmu.component

    def setupExperiment(self, startTime=0.0, **_):
        self._start = float(startTime)

    def enterInitializationMode(self):
        self._fmu.enterInitializationMode(startTime=self._start)

    def exitInitializationMode(self):
        self._fmu.exitInitializationMode()

    def terminate(self):
        self._fmu.terminate()

    def freeInstance(self):
        self._fmu.freeInstance()

    def freeLibrary(self):
        self._fmu.freeLibrary()

    # ------------------------------------------------------------------ values
    def setReal(self, vr, values):
        self._fmu.setFloat64(vr, values)

    def getReal(self, vr):
        return self._fmu.getFloat64(vr)

    def setInteger(self, vr, values):
        self._fmu.setInt32(vr, values)

    def setBoolean(self, vr, values):
        self._fmu.setBoolean(vr, values)

    # ------------------------------------------------------------------ raw calls
    def fmi2SetReal(self, c, vr, n, values):
        return self._set64(c, vr, n, values, n)

    def fmi2GetReal(self, c, vr, n, values):
        return self._get64(c, vr, n, values, n)

    def fmi2DoStep(self, c, t, h, no_set_prior):
        flags = self._flags
        return self._step(c, t, h, bool(no_set_prior), ctypes.byref(flags[0]),
                          ctypes.byref(flags[1]), ctypes.byref(flags[2]),
                          ctypes.byref(self._last))

    def raw_fmi_calls(self, h: float, t_arg):
        """The stepping loop's direct calls (:class:`vehicle.raw_calls.RawFMICalls`):
        ``fmi3SetFloat64`` / ``fmi3GetFloat64`` with their value counts and
        ``fmi3DoStep(instance, t_arg, h, fmi3True, ...)`` with this adapter's flags,
        the FMU's functions without the Python frames of :meth:`fmi2SetReal` & co."""
        from drymount.vehicle.raw_calls import RawFMICalls

        size = ctypes.c_size_t

        def args(c, vr, n, values):
            return (c, vr, size(n), values, size(n))

        r = RawFMICalls(self._fmu.dll, ("fmi3SetFloat64", "fmi3GetFloat64",
                                        "fmi3DoStep"), self.component, args, args, ())
        flags = self._flags
        r.step_args = (r.component, t_arg, ctypes.c_double(h), ctypes.c_bool(True),
                       ctypes.byref(flags[0]), ctypes.byref(flags[1]),
                       ctypes.byref(flags[2]), ctypes.byref(self._last))
        return r
