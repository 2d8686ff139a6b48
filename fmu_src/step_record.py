"""What the FrictionMount FMU reports about the step just taken (issue 30 item 4).

Every generic co-simulation master (fmusim, the Compliance Checker, libcosim, Ecos,
OMSimulator, ``fmpy.simulate_fmu``) reads outputs *after* ``doStep``. The trial
outputs re-evaluated then, at the committed slider and the same inputs, sit exactly on
the slip limit after a slipping step, so ``slip_<axis>`` and ``kt_<axis>`` would come
out as rounding decides. Per axis the FMU therefore keeps a record of its last step:

* ``slipped_<axis>``: whether the friction element slipped during the last
  ``doStep`` (false before the first);
* ``dE_fr_<axis>``: the energy it dissipated during that step, J (0 before the
  first): the increment of ``E_fr_<axis>`` the step committed;
* ``ks_<axis>``: the secant stiffness of the step, N/m, ``(R_n - R_{n-1}) / (u_n -
  u_{n-1})`` with ``R = F_<axis> - <axis>_c v_<axis>`` (the force less the viscous
  damper) at the inputs the steps committed (the first step measures from the
  inputs and trial outputs at the end of initialization). A step with ``u_n ==
  u_{n-1}`` (or a quotient that is not finite) has no secant: it reports the tangent
  it started from (``kt_<axis>`` read after the previous step, or at the end of
  initialization). Before the first step: that tangent.
* after ``doStep`` and until an input of the axis (``u_``, ``v_``, the effective
  ``n_``) is set to another value or ``w_<axis>`` is set, ``kt_<axis>`` and
  ``slip_<axis>`` describe that step: its slipping and its tangent at the end of the
  step (the consistent tangent of the return map: the slip tangent if it slipped,
  the stuck one otherwise), i.e. **the tangent the next step starts from when it
  continues the motion of the last step**; a reversal starts stuck (the elastic
  tangent plus ``kf``). Once an input changes they are again the trial values of the
  new inputs. Forces and energies are not affected (they are the same either way, up
  to the rounding of the re-evaluation).

The same record, with the same floating-point operations, is kept by the native C
builds (``fmu_src/native/model.c``). Standard library only: this module ships inside
the FMU.
"""

from __future__ import annotations

import math

__all__ = ["StepRecord", "start_record", "step_record", "record_to_state",
           "record_from_state", "record_problem"]


class StepRecord:
    """One axis's record of the last step (see the module text).

    Attributes
    ----------
    post : bool
        No input of the axis changed since the last ``doStep``.
    slipped : bool
        The last step slipped.
    kt : float
        Tangent the step ended with (N/m): what ``kt_<axis>`` reads while ``post``.
    de : float
        Energy dissipated in the last step, J.
    ks : float
        Secant stiffness of the last step, N/m.
    u, r : float
        Deflection (m) and force less the damper (N) the last step committed (or at
        the end of initialization).
    """

    __slots__ = ("post", "slipped", "kt", "de", "ks", "u", "r")

    def __init__(self, post=False, slipped=False, kt=0.0, de=0.0, ks=0.0, u=0.0,
                 r=0.0):
        self.post, self.slipped, self.kt, self.de = post, slipped, kt, de
        self.ks, self.u, self.r = ks, u, r


def start_record(force: float, tangent: float, u: float, v: float,
                 c: float) -> StepRecord:
    """The record at the end of initialization from the trial outputs there
    (``force``, ``tangent``) at the inputs ``u``, ``v`` of an axis of damping ``c``."""
    return StepRecord(False, False, tangent, 0.0, tangent, u, force - c * v)


def step_record(prev: StepRecord, force: float, tangent: float, slipping: bool,
                dissipated: float, u: float, v: float, c: float) -> StepRecord:
    """The record after a step committed at inputs ``u``, ``v`` with the result
    (``force``, ``tangent``, ``slipping``, ``dissipated``), from the previous one."""
    r = force - c * v
    du = u - prev.u
    ks = (r - prev.r) / du if du != 0.0 else prev.kt
    if not math.isfinite(ks):  # a step below the resolution of the forces
        ks = prev.kt
    return StepRecord(True, bool(slipping), tangent, dissipated, ks, u, r)


def record_to_state(rec: StepRecord) -> list:
    """The record as a JSON-able list (the FMU state)."""
    return [rec.post, rec.slipped, rec.kt, rec.de, rec.ks, rec.u, rec.r]


def record_problem(value) -> str | None:
    """Why ``value`` is not a record of :func:`record_to_state`, or None."""
    if not (isinstance(value, list) and len(value) == 7):
        return f"`_step` entry {value!r:.80} is not a list of 7 values"
    if not all(isinstance(x, bool) for x in value[:2]):
        return f"`_step` entry {value!r:.80}: its first two values are not flags"
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool)
               and math.isfinite(x) for x in value[2:]):
        return f"`_step` entry {value!r:.80}: a value is not a finite number"
    return None


def record_from_state(value) -> StepRecord:
    """The record of a checked state entry (:func:`record_problem`)."""
    return StepRecord(bool(value[0]), bool(value[1]), *(float(x) for x in value[2:]))
