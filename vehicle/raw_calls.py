"""The FMU's own set/get/step functions as the stepping loop calls them
(:class:`RawFMICalls`), shared by :mod:`vehicle.backends` (FMI 2.0) and
:mod:`vehicle.fmi3_adapter` (FMI 3.0)."""

from __future__ import annotations

import ctypes

__all__ = ["RawFMICalls", "raw_fmi_calls"]


class RawFMICalls:
    """An FMU instance's own set/get/step functions for the stepping loop.

    ``set_real(*set_args(vr, n, values))``, ``get_real(*get_args(vr, n, values))`` and
    ``do_step(*step_args)`` call the FMU's shared library directly: fresh ctypes
    function pointers without ``argtypes`` and every argument prebuilt as a ctypes
    object (the component, the counts, the step size and ``t_arg``, the one
    ``c_double`` that carries the step's time), so a call converts nothing and makes
    no Python object. fmpy's ``fmi2SetReal`` & co. (a Python method, a dictionary
    look-up and a conversion of each argument) cost about 1 us more per call.
    :meth:`failed` gives the exception fmpy's wrapper raises for a status above
    ``fmi2Warning``. The function names and arguments are FMI 2.0's (``fmi2SetReal``,
    ``fmi2GetReal``, ``fmi2DoStep``) or, for :class:`vehicle.fmi3_adapter.
    FMU3Adapter`, FMI 3.0's (``fmi3SetFloat64``, ``fmi3GetFloat64``, ``fmi3DoStep``).
    """

    def __init__(self, dll, names, component, set_args, get_args, step_args):
        self.names = dict(zip(("set", "get", "step"), names, strict=True))
        self.set_real, self.get_real, self.do_step = (dll[n] for n in names)
        for fn in (self.set_real, self.get_real, self.do_step):
            fn.restype = ctypes.c_int
        self.component = ctypes.c_void_p(component)
        self._set_args, self._get_args = set_args, get_args
        self.step_args = step_args

    def set_args(self, vr, n: int, values) -> tuple:
        return self._set_args(self.component, vr, n, values)

    def get_args(self, vr, n: int, values) -> tuple:
        return self._get_args(self.component, vr, n, values)

    def failed(self, which: str, status: int) -> Exception:
        from fmpy.fmi1 import FMICallException

        return FMICallException(function=self.names[which], status=status)


def raw_fmi_calls(fmu, h: float, t_arg) -> RawFMICalls:
    """:class:`RawFMICalls` of an fmpy ``FMU2Slave`` (or of an object with its own
    ``raw_fmi_calls(h, t_arg)``, as :class:`vehicle.fmi3_adapter.FMU3Adapter`);
    ``doStep(component, t_arg, h, fmi2True)``."""
    own = getattr(fmu, "raw_fmi_calls", None)
    if own is not None:
        return own(h, t_arg)
    size = ctypes.c_size_t

    def args(c, vr, n, values):
        return (c, vr, size(n), values)

    r = RawFMICalls(fmu.dll, ("fmi2SetReal", "fmi2GetReal", "fmi2DoStep"),
                    fmu.component, args, args, ())
    r.step_args = (r.component, t_arg, ctypes.c_double(h), ctypes.c_int(1))
    return r
