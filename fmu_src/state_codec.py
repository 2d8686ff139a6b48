"""Serialized FMU states of the PythonFMU build: bytes with a checksum, and the schema
and range check of a state dict (docs/fmu.md, "FMU state").

pythonfmu 0.7.0 calls ``_fmu_state_to_bytes`` / ``_fmu_state_from_bytes`` on the slave
*class* (no instance, so no logger and no way to return an error status), and any
exception there is fmi2Fatal outside the slave's guard. So :func:`decode` never
raises: bytes that are not a state of this FMU decode to a :class:`Corrupt` marker,
which :func:`state_problem` (called by ``fmi2SetFMUstate``, inside the guard) refuses
with its reason. A state is ``MAGIC`` + the SHA-256 hex digest of the payload + the
payload (JSON, UTF-8); the payload is parsed only when its digest matches. Standard
library only: this module ships inside the FMU.
"""

from __future__ import annotations

import hashlib
import json
import math

from .fmi_state import INFINITE_ALLOWED, Mode
from .linear_branches import FLUID_STATE
from .mount_law import MAX_MAXWELL, MAX_SLIDERS
from .step_record import record_problem

__all__ = ["MAGIC", "Corrupt", "encode", "decode", "state_problem"]

MAGIC = b"DMPYST01"
_DIGEST = 64  # hex characters of SHA-256


class Corrupt(dict):
    """What :func:`decode` returns for bytes that are not a state (a dict, as
    pythonfmu expects one): ``reason`` says why."""

    def __init__(self, reason: str):
        super().__init__()
        self.reason = reason


def encode(state: dict) -> bytes:
    payload = json.dumps(state, sort_keys=True).encode("utf-8")
    return MAGIC + hashlib.sha256(payload).hexdigest().encode("ascii") + payload


def decode(data) -> dict:
    """The state dict of ``data`` (bytes), or a :class:`Corrupt`; never raises."""
    try:
        data = bytes(data)
        head, payload = data[:len(MAGIC) + _DIGEST], data[len(MAGIC) + _DIGEST:]
        if len(head) < len(MAGIC) + _DIGEST or not head.startswith(MAGIC):
            return Corrupt(f"not a state serialized by this FMU ({len(data)} bytes)")
        if hashlib.sha256(payload).hexdigest().encode("ascii") != head[len(MAGIC):]:
            return Corrupt("corrupt serialized state (checksum mismatch)")
        state = json.loads(payload.decode("utf-8"))
    except (ValueError, TypeError, RecursionError, MemoryError) as exc:
        return Corrupt(f"corrupt serialized state ({type(exc).__name__})")
    return state if isinstance(state, dict) else Corrupt("corrupt serialized state")


def _real_ok(name: str, x) -> bool:
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return False
    return math.isfinite(x) or (x == math.inf and name.endswith(INFINITE_ALLOWED))


def _value_problem(var, x) -> str | None:
    """Why ``x`` cannot be the value of the interface variable ``var``, or None."""
    if var.type == "Real":
        ok = _real_ok(var.name, x)
    elif var.type == "Integer":
        ok = isinstance(x, int) and not isinstance(x, bool) and -2**31 <= x < 2**31
        if ok and var.name.endswith("_sliders"):
            ok = 1 <= x <= MAX_SLIDERS
    else:
        ok = isinstance(x, bool)
    return None if ok else f"`{var.name}` = {x!r:.60} is not a valid {var.type}"


def _three(state: dict, key: str, check) -> str | None:
    v = state.get(key)
    if not (isinstance(v, list) and len(v) == 3 and all(check(x) for x in v)):
        return f"`{key}` = {v!r:.80} is not three valid entries"
    return None


def _slider_state(w) -> bool:
    if isinstance(w, list):
        # the element's state, plus uc and the strokes of the Maxwell branches and
        # the hydraulic fluid's states
        return 1 <= len(w) <= MAX_SLIDERS + 1 + MAX_MAXWELL + FLUID_STATE \
            and all(_real_ok("w", x) for x in w)
    return _real_ok("w", w)


def state_problem(state, settable) -> str | None:
    """Why ``state`` is not a state of this FMU, or None. ``settable``: the interface
    variables a state holds (by name). Checks the keys, every value's type and range
    (finite Reals but `_mu1`/`_mu2`; `<axis>_sliders` in 1..MAX_SLIDERS), the
    committed energies, the slider states, the mode and the time."""
    if isinstance(state, Corrupt):
        return state.reason
    if not isinstance(state, dict):
        return f"not a state of this FMU (a {type(state).__name__})"
    extra = {"_E_committed", "_n_set", "_w", "_mode", "_t_next", "_dt"}
    optional = {"_step"}  # the records of the last step (step_record.py)
    missing = sorted(set(settable) - set(state)) + sorted(extra - set(state))
    unknown = sorted(set(state) - set(settable) - extra - optional)
    if missing or unknown:
        return f"not a state of this FMU (missing {missing[:5]}, unknown {unknown[:5]})"
    for name, var in settable.items():
        why = _value_problem(var, state[name])
        if why is not None:
            return why
    why = (_three(state, "_E_committed", lambda x: _real_ok("E", x))
           or _three(state, "_n_set", lambda x: isinstance(x, bool))
           or _three(state, "_w", _slider_state))
    if why is not None:
        return why
    if state["_mode"] not in [m.value for m in Mode]:
        return f"`_mode` = {state['_mode']!r:.60} is not a state of the FMU"
    t = state["_t_next"]
    if t is not None and not _real_ok("t", t):
        return f"`_t_next` = {t!r:.60} is not a finite time"
    dt = state["_dt"]
    if not _real_ok("dt", dt) or dt < 0.0:
        return f"`_dt` = {dt!r:.60} is not a finite step size >= 0"
    if "_step" in state:
        steps = state["_step"]
        if not (isinstance(steps, list) and len(steps) == 3):
            return f"`_step` = {steps!r:.80} is not three records"
        for rec in steps:
            why = record_problem(rec)
            if why is not None:
                return why
    return None
