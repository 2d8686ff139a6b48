"""One process-wide FMI 2.0 logger for the FMUs drymount drives through fmpy.

fmpy's ``addLoggerProxy`` (a small C shim that formats an FMU's variadic log message,
which ctypes cannot hand to Python) keeps ONE process-wide pointer to the Python logger
it wraps: the struct proxied last redirects every later message, and once that Python
callback has been garbage collected the next message of any FMU calls freed memory and
the host process dies (seen as a segfault in ``fmi2Instantiate`` of an FMU that logs).
So every callback struct made here wraps the same immortal logger, which hands each
message to the handler registered under the struct's ``componentEnvironment`` (FMI 2.0
passes it back with every message).
"""

from __future__ import annotations

import ctypes
import itertools
from collections.abc import Callable

__all__ = ["callbacks", "release"]

#: ``handler(env, instance, status, category, message)``, fmpy's logger signature
#: (bytes for the strings, the message already formatted)
Handler = Callable[..., None]

_handlers: dict[int, Handler] = {}
_keys = itertools.count(1)
_immortal: dict[str, object] = {}  # the ctypes thunks, alive for the whole process


def _dispatch(env, instance, status, category, message) -> None:
    handler = _handlers.get(env or 0)
    if handler is not None:
        handler(env, instance, status, category, message)


def _thunks() -> dict:
    if not _immortal:
        from fmpy import calloc, free
        from fmpy.fmi2 import (
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackLoggerTYPE,
        )

        _immortal.update(logger=fmi2CallbackLoggerTYPE(_dispatch),
                         allocate=fmi2CallbackAllocateMemoryTYPE(calloc),
                         free=fmi2CallbackFreeMemoryTYPE(free))
    return _immortal


def callbacks(handler: Handler):
    """An ``fmi2CallbackFunctions`` for ``FMU2Slave.instantiate(callbacks=...)`` whose
    messages (formatted) reach ``handler``. Keep the returned struct alive while the
    instance lives; :func:`release` it after ``fmi2FreeInstance``."""
    from fmpy.fmi2 import fmi2CallbackFunctions
    from fmpy.logging import addLoggerProxy

    t = _thunks()
    key = next(_keys)
    _handlers[key] = handler
    cb = fmi2CallbackFunctions()
    cb.logger = t["logger"]
    cb.allocateMemory = t["allocate"]
    cb.freeMemory = t["free"]
    cb.componentEnvironment = key
    addLoggerProxy(ctypes.byref(cb))  # the shim's global now wraps the immortal logger
    return cb


def release(cb) -> None:
    """Forget the handler of ``cb`` (its messages are dropped from now on)."""
    if cb is not None:
        _handlers.pop(cb.componentEnvironment or 0, None)
