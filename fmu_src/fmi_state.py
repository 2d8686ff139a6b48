"""The FMI 2.0 Co-Simulation call-order rules of the FrictionMount FMU, as data.

docs/fmu.md ("Call-order rules") states them for every implementation of the FMU (the
PythonFMU slave in ``friction_mount.py`` reads them from here; the native C FMU
implements the same table). Each check returns ``None`` for an accepted call or the
message of the rejection (naming the call, the state and the offending value); a
rejected call returns ``fmi2Error`` and changes nothing, so the instance stays usable
in the state it was in. Standard library only: this module ships inside the FMU.
"""

from __future__ import annotations

import math
from enum import Enum

from .mount_law import MAX_SLIDERS

__all__ = ["Mode", "ALLOWED", "SETTABLE", "MAX_STEP_SIZE", "TIME_RTOL",
           "INFINITE_ALLOWED", "call_error", "set_error", "step_error", "setup_error"]


class Mode(str, Enum):
    """States of an instance (FMI 2.0 section 4.2.4 names)."""

    INSTANTIATED = "instantiated"
    INITIALIZATION = "initializationMode"
    STEP_COMPLETE = "stepComplete"
    TERMINATED = "terminated"


_I, _INIT, _STEP, _TERM = Mode.INSTANTIATED, Mode.INITIALIZATION, \
    Mode.STEP_COMPLETE, Mode.TERMINATED

#: The states in which each FMI function may be called. fmi2Reset and
#: fmi2FreeInstance are allowed in every state (reset returns to ``instantiated``);
#: fmi2GetFMUstate/fmi2SetFMUstate too (the state carries the mode and the time).
#: The getters are allowed in every state, also ``instantiated`` (FMI 2.0 allows them
#: from initializationMode on; pythonfmu reads the start values there, and reading
#: changes nothing). Before initialization ends, outputs read 0 while the parameters
#: are invalid: the error is reported by fmi2ExitInitializationMode.
ALLOWED: dict[str, frozenset] = {
    "fmi2SetupExperiment": frozenset({_I}),
    "fmi2EnterInitializationMode": frozenset({_I}),
    "fmi2ExitInitializationMode": frozenset({_INIT}),
    "fmi2DoStep": frozenset({_STEP}),
    "fmi2Terminate": frozenset({_STEP}),
    "fmi2GetReal": frozenset(Mode),
    "fmi2GetInteger": frozenset(Mode),
    "fmi2GetBoolean": frozenset(Mode),
    "fmi2SetReal": frozenset({_I, _INIT, _STEP}),
    "fmi2SetInteger": frozenset({_I, _INIT, _STEP}),
    "fmi2SetBoolean": frozenset({_I, _INIT, _STEP}),
    "fmi2GetFMUstate": frozenset(Mode),
    "fmi2SetFMUstate": frozenset(Mode),
}

#: Which variables fmi2Set* may change in which state, by causality: the parameters
#: are ``fixed`` (only before initialization ends), the inputs any time before
#: fmi2Terminate. The locals ``w_<axis>`` (the committed slider positions, initial =
#: exact) may be set before fmi2Terminate too: a drymount extension to FMI 2.0 (which
#: would use fmi2SetFMUstate), the harness moves a steady state between instances and
#: backends with it. Outputs are never set.
SETTABLE: dict[str, frozenset] = {
    "parameter": frozenset({_I, _INIT}),
    "input": frozenset({_I, _INIT, _STEP}),
    "local": frozenset({_I, _INIT, _STEP}),
    "output": frozenset(),
}

#: Largest communication step accepted, s (about 11.6 days: larger is a unit or
#: overflow error of the importer; the FMU integrates nothing, any smaller step is
#: exact).
MAX_STEP_SIZE = 1e6
#: doStep's currentCommunicationPoint must equal the end of the previous step to this
#: relative tolerance (importers compute t = t0 + k h or accumulate t += h; both
#: round at the 1e-16 level).
TIME_RTOL = 1e-9


def _allowed_text(call: str) -> str:
    return ", ".join(m.value for m in Mode if m in ALLOWED[call])


def call_error(call: str, mode: Mode) -> str | None:
    """The rejection of ``call`` in ``mode``, or None if it is allowed there."""
    if mode in ALLOWED[call]:
        return None
    return (f"{call} is not allowed in state {mode.value} (allowed in: "
            f"{_allowed_text(call)})")


#: Suffixes of the Real variables that also take +inf: the inclined element's
#: friction coefficients ``<axis>_mu1``, ``<axis>_mu2`` (inf = a bonded surface, one
#: that never slips; :class:`fmu_src.inclined.InclinedParameters`). Every other Real
#: must be finite.
INFINITE_ALLOWED = ("_mu1", "_mu2")


def set_error(call: str, name: str, causality: str, variability: str, mode: Mode,
              value) -> str | None:
    """The rejection of setting variable ``name`` to ``value`` in ``mode``, or None."""
    if causality == "output":
        return f"{call}: `{name}` is an output and cannot be set (value {value!r})"
    if mode not in SETTABLE[causality]:
        when = ("after fmi2ExitInitializationMode" if causality != "input"
                else "after fmi2Terminate")
        return (f"{call}: `{name}` is a {variability} {causality} and cannot be set "
                f"{when} (state {mode.value}, value {value!r})")
    if isinstance(value, float) and not math.isfinite(value) \
            and not (value == math.inf and name.endswith(INFINITE_ALLOWED)):
        return f"{call}: `{name}` must be finite, got {value!r}"
    for suffix, (low, high) in INTEGER_RANGES.items():
        if name.endswith(suffix) and not low <= value <= high:
            return (f"{call}: `{name}` must be an integer from {low} to {high}, got "
                    f"{value!r}")
    return None


#: Integer parameters whose range is checked when they are set (not only at
#: fmi2ExitInitializationMode): the number of sliders of the micro-slip element,
#: 1..mount_law.MAX_SLIDERS (an unchecked count allocated without limit, issue 25).
INTEGER_RANGES = {"_sliders": (1, MAX_SLIDERS)}


def step_error(t: float, h: float, expected: float | None) -> str | None:
    """The rejection of ``fmi2DoStep(t, h)`` when the previous step ended at
    ``expected`` (None: the first step after initialization without
    fmi2SetupExperiment), or None."""
    if not (isinstance(h, float) and math.isfinite(h) and h > 0.0):
        return (f"fmi2DoStep: the step size must be finite and > 0, got "
                f"communicationStepSize = {h!r}")
    if h > MAX_STEP_SIZE:
        return (f"fmi2DoStep: the step size must be <= {MAX_STEP_SIZE:g} s, got "
                f"communicationStepSize = {h!r}")
    if not math.isfinite(t):
        return (f"fmi2DoStep: the time must be finite, got currentCommunicationPoint "
                f"= {t!r}")
    if not t + h > t:
        return (f"fmi2DoStep: communicationStepSize = {h!r} does not advance "
                f"currentCommunicationPoint = {t!r} (below its resolution)")
    if expected is not None and abs(t - expected) > TIME_RTOL * max(1.0, abs(expected),
                                                                    h):
        return (f"fmi2DoStep: currentCommunicationPoint = {t!r} does not continue "
                f"from the end of the previous step, {expected!r}")
    return None


def setup_error(start: float) -> str | None:
    """The rejection of ``fmi2SetupExperiment(startTime)``, or None. (stopTime is
    not checked: pythonfmu does not pass whether it is defined.)"""
    if not (isinstance(start, float) and math.isfinite(start)):
        return f"fmi2SetupExperiment: startTime must be finite, got {start!r}"
    return None
