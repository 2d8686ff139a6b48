"""How the PythonFMU slave's FMI entry points protect their host (pythonfmu 0.7.0's
native wrapper): a rejected call returns fmi2Error through the linux64 loader's
``drymount_reject_call`` (no exception inside the FMU), any other exception first
holds the references pythonfmu releases twice, and the resources folder is not
prepended to ``sys.path`` once per instantiate. :class:`FrictionMount
<friction_mount.FrictionMount>` wraps its entry points with :func:`_fmi_call` /
:func:`_guarded`. Standard library only; imported relatively, like every module the
FMU bundles.
"""

from __future__ import annotations

import functools
import os

from .fmi_state import call_error
from .interface import MODEL_NAME

__all__ = ["FMICallError"]


def _hold_native_references(slave) -> None:
    """Compensate pythonfmu 0.7.0's double release after a Python exception.

    Its native wrapper (PySlaveInstance.cpp) turns an exception into fmi2Fatal and
    Py_DECREFs the slave class, the instance and its log queue at once; fmi2FreeInstance
    releases them a second time, which corrupts the host interpreter (measured: SIGSEGV
    at the next garbage collection). One extra reference each makes both releases
    safe; if the importer never frees the instance they leak, which FMI allows after
    fmi2Fatal.
    """
    try:
        import ctypes

        incref = ctypes.pythonapi.Py_IncRef
    except (ImportError, AttributeError, OSError):  # pragma: no cover - no ctypes
        _LEAKED.append((type(slave), slave, slave.log_queue))  # a real reference each
        return
    for obj in (type(slave), slave, slave.log_queue):
        incref(ctypes.py_object(obj))


_LEAKED: list = []


def _drop_repeated_path(resources) -> None:
    """pythonfmu 0.7.0 inserts the resources folder at the front of ``sys.path`` at
    every fmi2Instantiate: keep that first entry, drop the copies further back
    (``sys.path`` grew by one entry per instantiate/free cycle)."""
    import sys

    if resources and sys.path[:1] == [resources]:
        sys.path[1:] = [p for p in sys.path[1:] if p != resources]


class FMICallError(ValueError):
    """A rejected FMI call (the message names the call, the state and the value)."""


class _Rejected(Exception):
    """Raised inside an entry point to reject the call (see :func:`_fmi_call`)."""


_REJECT_HOOKS: dict = {}


def _reject_hook(resources):
    """``drymount_reject_call`` of this FMU's linux64 loader, or None (no loader:
    win64, an FMU built without a C compiler, or the class used from Python)."""
    if not resources:
        return None
    path = os.path.join(os.path.dirname(os.path.normpath(resources)), "binaries",
                        "linux64", f"{MODEL_NAME}.so")
    if path not in _REJECT_HOOKS:
        hook = None
        try:
            import ctypes

            hook = ctypes.CDLL(path).drymount_reject_call
            hook.restype, hook.argtypes = None, []
        except (ImportError, OSError, AttributeError):
            hook = None
        _REJECT_HOOKS[path] = hook
    return _REJECT_HOOKS[path]


def _fmi_call(call: str, rejected=lambda args: None, check_state: bool = True):
    """Wrap the entry point of the FMI function ``call``.

    Rejects the call (see :meth:`FrictionMount._reject`) when the instance's state
    does not allow it (``check_state``) or when the method raises :class:`_Rejected`;
    ``rejected(args)`` is then the value returned to pythonfmu (finite placeholders of
    the right length for the getters). Any other escaping exception first calls
    :func:`_hold_native_references` when pythonfmu's native wrapper is the caller.
    """

    def wrap(method):
        @functools.wraps(method)
        def entry(self, *args):
            try:
                if check_state:
                    why = call_error(call, self._mode)
                    if why is not None:
                        raise _Rejected(why)
                return method(self, *args)
            except _Rejected as exc:
                return self._reject(str(exc), rejected(args))
            except BaseException:
                if self._native:
                    _hold_native_references(self)
                raise

        return entry

    return wrap


def _guarded(method):
    """An entry point without state rules (fmi2Get/SetFMUstate)."""
    return _fmi_call(method.__name__, check_state=False)(method)
