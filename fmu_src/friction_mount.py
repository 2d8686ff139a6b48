"""The FrictionMount FMU's slave class (pythonfmu ``Fmi2Slave``): glue only.

Every force comes from :mod:`mount_law` (imported relatively, so the same file works as
``fmu_src.friction_mount`` in the repository and as ``<unique package>.friction_mount``
inside the FMU, see ``fmu_build``). This module registers the FMI variables and runs
the co-simulation protocol; the model description's units, ranges and structure are
:mod:`model_description`'s, the parameter checks :mod:`parameter_check`'s,
getFMUstate/setFMUstate :mod:`fmu_snapshot`'s:

* per communication step t_n -> t_n + h the master sets ``u_<axis>``, ``v_<axis>`` (and
  ``n_<axis>``) at t_n and may read the outputs at once: they are the trial return map
  ``axis_force(u(t_n), v(t_n), w_{n-1})`` (direct feedthrough, nothing committed by a
  get; thesis eq. 2.10-2.13 and 2.15-2.20);
* ``doStep(t_n, h)`` commits the slider positions ``w := w_new(u(t_n))`` and adds the
  energy the sliders dissipated, ``Fs |w_new - w|``. The FMU integrates nothing in time.

The FMI 2.0 call-order rules (``fmi_state``, docs/fmu.md) are enforced: a call out of
order, a fixed parameter set after initialization, a value that is not finite, a step
size that is not finite and > 0 or a time that does not continue from the last step is
*rejected*: logged (naming the call, the state and the value), nothing changed, and
the call returns fmi2Error; the instance stays usable. pythonfmu 0.7.0 turns any Python
exception into fmi2Fatal and drops the instance, so a rejection does not raise inside
an FMU: it marks the call through the linux64 loader (``drymount_reject_call``), which
returns fmi2Error. Without the loader (win64) a rejection can only raise (fmi2Fatal);
called from Python (no native wrapper) it raises :class:`FMICallError`.

Outputs are a pure function of (parameters, inputs, committed state): evaluations are
cached per axis and invalidated by the setters, so reading all outputs of an axis costs
one law evaluation. The normal-force input is clipped at zero (a negative value means
lost contact): ``Fs = mu * max(n, 0)``. Standard library only (plus pythonfmu, which the
FMU bundles).
"""

from __future__ import annotations

import math
from xml.etree.ElementTree import Element

from pythonfmu import (
    Boolean,
    DefaultExperiment,
    Fmi2Causality,
    Fmi2Initial,
    Fmi2Slave,
    Fmi2Variability,
    Integer,
    Real,
)
from pythonfmu.enums import Fmi2Status

from . import model_description, step_record
from .fmi_guard import (FMICallError, _drop_repeated_path, _fmi_call, _Rejected,
                        _reject_hook)
from .fmi_state import Mode, set_error, setup_error, step_error
from .fmu_snapshot import SnapshotMixin
from .interface import DEFAULT_EXPERIMENT, MODEL_NAME, SLIDER_SLOT_NAMES, VARIABLES
from .mount_law import (AXES, axis_force, conform_state, initial_sliders, mean_slider,
                        normal_forces, slider_position)
from .parameter_check import ParameterError, checked_axes

try:  # written by fmu_build into the FMU's package; absent in the repository
    from . import FMU_VERSION
except ImportError:
    FMU_VERSION = "source"

__all__ = ["FrictionMount", "FMICallError"]

_TYPES = {"Real": Real, "Integer": Integer, "Boolean": Boolean}
_CAUSALITY = {c.name: c for c in Fmi2Causality}
_VARIABILITY = {v.name: v for v in Fmi2Variability}
_INITIAL = {i.name: i for i in Fmi2Initial}
# Indices into the AxisForce result (mount_law.axis_force).
_F, _FFR, _W, _KT, _SLIP, _DISS = range(6)


def _same_state(a, b) -> bool:
    """Whether two element states are the same, of the same types and bit for bit
    in every float (-0.0 is not 0.0 here): a float, or a tuple (a NamedTuple, a
    MaxwellAxisState) of them, nested. Called on every step of every axis: the
    law hands back the very state object where nothing moved, and a changed state
    fails the one (C) comparison ``a == b``; only equal but distinct states are
    compared value by value."""
    if a is b:
        return True
    if type(a) is not type(b) or not a == b:
        return False
    if isinstance(a, tuple):  # equal tuples: of one length
        return all(_same_state(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return math.copysign(1.0, a) == math.copysign(1.0, b)
    return True


class FrictionMount(SnapshotMixin, Fmi2Slave):
    """Friction-damped engine mount, three local axes (FMI 2.0 Co-Simulation).

    Variables (names as in docs/fmu.md), for each axis in ``AXES``: parameters
    ``<axis>_<field>`` (the fields of :class:`AxisParameters`, ``law`` as its integer
    code), inputs ``u_<axis>`` [m], ``v_<axis>`` [m/s], ``n_<axis>`` [N], outputs
    ``F_<axis>`` [N], ``Ffr_<axis>`` [N], ``kt_<axis>`` [N/m], ``slip_<axis>``,
    ``E_fr_<axis>`` [J], plus ``E_fr`` [J] (all axes) and locals ``w_<axis>`` [m].
    """

    author = "drymount"
    description = ("Friction-damped engine mount: elastic law + viscous damping + "
                   "a friction element (<axis>_friction_kind) on three local axes")
    version = FMU_VERSION
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        # pythonfmu's native wrapper passes a `logger` handle; Python callers do not
        self._native = "logger" in kwargs
        if self._native:
            _drop_repeated_path(self.resources)
        self.default_experiment = DefaultExperiment(
            start_time=DEFAULT_EXPERIMENT["startTime"],
            stop_time=DEFAULT_EXPERIMENT["stopTime"],
            step_size=DEFAULT_EXPERIMENT["stepSize"],
            tolerance=DEFAULT_EXPERIMENT["tolerance"])
        # Parameters as plain attributes named like the FMU variables.
        for var in VARIABLES:
            if var.causality == "parameter":
                setattr(self, var.name, var.start)
        # Inputs, committed state and the per-axis evaluation cache, in AXES order.
        n0 = [self._start(f"n_{axis}") for axis in AXES]
        self._u = [0.0, 0.0, 0.0]
        self._v = [0.0, 0.0, 0.0]
        self._n = n0
        self._n_set = [False, False, False]  # n follows <axis>_n0 until set
        self._w = [0.0, 0.0, 0.0]
        self._e = [0.0, 0.0, 0.0]  # committed dissipated energy per axis, J
        # the increment the trial outputs span (s): the last step's size, 0 before
        # the first (read by rate-dependent friction elements only)
        self._dt = 0.0
        self._res = [None, None, None]
        # per axis, the record of the last step (fmu_src/step_record.py)
        self._rec = [step_record.StepRecord() for _ in AXES]
        self._axes = None  # per-axis checked AxisParameters, see _prepare()
        self._mode = Mode.INSTANTIATED  # FMI state (fmi_state.Mode)
        self._t_next = None  # where the next doStep must start (None: anywhere)
        self._bad_params = None  # why outputs read during initialization are 0
        self._register_all()
        self._var = {vr: next(v for v in VARIABLES if v.name == var.name)
                     for vr, var in self.vars.items()}
        by_name = {var.name: vr for vr, var in self.vars.items()}
        self._fast_inputs = {by_name[f"{q}_{axis}"]: (store, j)
                             for j, axis in enumerate(AXES)
                             for q, store in (("u", self._u), ("v", self._v))}
        self._fast_outputs = {by_name[f"{name}_{axis}"]: (j, idx)
                              for j, axis in enumerate(AXES)
                              for name, idx in (("F", _F), ("Ffr", _FFR), ("kt", _KT))}

    @staticmethod
    def _start(name: str):
        return next(v.start for v in VARIABLES if v.name == name)

    # ------------------------------------------------------------------ variables
    def _accessors(self, name: str):
        """``(getter, setter)`` of the FMU variable ``name`` (setter None: output)."""
        if name == "E_fr":
            return self._energy_total, None
        quantity, _, axis = name.rpartition("_")
        if axis not in AXES:  # a parameter <axis>_<field>
            return ((lambda a=name: getattr(self, a)),
                    (lambda value, a=name: self._set_parameter(a, value)))
        j = AXES.index(axis)
        if quantity == "w":
            return ((lambda: self._position(j)),
                    (lambda value: self._set_sliders(j, value)))
        if quantity in SLIDER_SLOT_NAMES:   # w1_, w2_: one slider of the element
            slot = SLIDER_SLOT_NAMES.index(quantity)
            return ((lambda: self._slider(j, slot)),
                    (lambda value: self._set_slider(j, slot, value)))
        inputs = {"u": self._u, "v": self._v}
        if quantity in inputs:
            store = inputs[quantity]
            return ((lambda: store[j]),
                    (lambda value: self._set_input(store, j, value)))
        if quantity == "n":
            return ((lambda: self._normal_force(j)),
                    (lambda value: self._set_normal_force(j, value)))
        if quantity == "E_fr":
            return (lambda: self._e[j] + self._axis(j)[_DISS]), None
        if quantity in ("N", "N2"):
            return (lambda: self._normal_output(j)[quantity == "N2"]), None
        if quantity in ("slipped", "dE_fr", "ks", "kt", "slip"):
            return self._record_getter(quantity, j), None
        idx = {"F": _F, "Ffr": _FFR, "kt": _KT, "slip": _SLIP}[quantity]
        return (lambda: self._axis(j)[idx]), None

    def _register_all(self) -> None:
        """Register every variable of the interface table, in its order."""
        for var in VARIABLES:
            getter, setter = self._accessors(var.name)
            extra = {} if var.initial is None else {"initial": _INITIAL[var.initial]}
            self.register_variable(_TYPES[var.type](
                var.name, causality=_CAUSALITY[var.causality],
                variability=_VARIABILITY[var.variability],
                description=var.description, getter=getter, setter=setter, **extra))

    def _record_getter(self, quantity: str, j: int):
        """Getter of an output that reads the record of the last step
        (fmu_src/step_record.py): ``slipped_``, ``dE_fr_``, ``ks_`` and, while no
        input of the axis changed since ``doStep``, ``kt_`` and ``slip_``."""
        rec = self._rec
        if quantity == "slipped":
            return lambda: rec[j].slipped
        if quantity == "dE_fr":
            return lambda: rec[j].de
        idx = _KT if quantity in ("kt", "ks") else _SLIP
        field = "kt" if quantity == "kt" else "slipped"

        def getter():
            if quantity == "ks":
                if self._mode in (Mode.INSTANTIATED, Mode.INITIALIZATION):
                    return self._axis(j)[_KT]  # before the first step: the tangent
                return rec[j].ks
            if rec[j].post:
                return getattr(rec[j], field)
            return self._axis(j)[idx]

        return getter

    def _set_parameter(self, attr: str, value) -> None:
        setattr(self, attr, value)
        self._axes = None
        self._res = [None, None, None]
        for rec in self._rec:
            rec.post = False

    def _set_input(self, store: list, j: int, value: float) -> None:
        if store[j] != value:
            self._rec[j].post = False
        store[j] = value
        self._res[j] = None

    def _set_sliders(self, j: int, value: float) -> None:
        """``w_<axis>`` = value: the axis's friction element relaxed at ``value``
        (m; every slider there). Before the parameters are checked the number is
        kept and becomes the element's state in _prepare (conform_state)."""
        self._w[j] = value
        self._rec[j].post = False
        if self._axes is not None:  # checked parameters: the state of the axis's kind
            self._w[j] = initial_sliders(self._axes[j], value)
        self._res[j] = None

    def _slot_problem(self, name: str, value) -> str | None:
        """Why ``w<k>_<axis>`` = ``value`` is refused (checked before any value of
        a call is set): the parameters must be valid (set them in an earlier call)
        and the axis's element must have slider k."""
        quantity, _, axis = name.rpartition("_")
        j, slot = AXES.index(axis), SLIDER_SLOT_NAMES.index(quantity)
        if self._axes is None:
            try:
                self._prepare()
            except _Rejected as exc:
                return (f"`{name}` = {value!r} sets a slider of the axis's friction "
                        f"element, which needs valid parameters first ({exc})")
        p = self._axes[j]
        slots = p.element.slider_slots(p) if p.friction else ()
        if slot >= len(slots):
            what = (f"the {p.friction_kind} element of axis {axis} has "
                    f"{len(slots)} settable slider(s)" if p.friction else
                    f"axis {axis} has no friction element")
            return f"`{name}` = {value!r}: {what}; no slider {slot + 1} to set"
        return None

    def _slider(self, j: int, slot: int) -> float:
        """``w<slot+1>_<axis>``: that slider of the committed state (0 where the
        element has none, or while the parameters are invalid)."""
        if self._axes is None:
            try:
                self._prepare()
            except _Rejected:
                return 0.0
        p = self._axes[j]
        values = p.element.slider_values(p, self._w[j]) if p.friction else ()
        return values[slot] if slot < len(values) else 0.0

    def _set_slider(self, j: int, slot: int, value: float) -> None:
        """``w<slot+1>_<axis>`` = value (checked by :meth:`_slot_problem`): the
        element's state with that slider there (``FrictionElement.with_sliders``),
        the rest of the state kept."""
        p = self._axes[j]
        self._w[j] = p.element.with_sliders(p, self._w[j], {slot: float(value)})
        self._rec[j].post = False
        self._res[j] = None

    def _position(self, j: int) -> float:
        """``w_<axis>``: the element's position of the committed state."""
        if self._axes is None:
            return mean_slider(self._w[j])
        return slider_position(self._axes[j], self._w[j])

    def _normal_output(self, j: int) -> tuple[float, float]:
        """``(N, N2)`` of axis ``j`` at the trial state (mount_law.normal_forces)."""
        return normal_forces(self._axes[j], self._axis(j)[_W], self._n[j])

    def _set_normal_force(self, j: int, value: float) -> None:
        if not self._n_set[j] and value == self._start(f"n_{AXES[j]}") \
                and self._mode in (Mode.INSTANTIATED, Mode.INITIALIZATION):
            return  # an importer writing the declared start: n keeps following n0
        if value != self._normal_force(j):
            self._rec[j].post = False
        self._n[j] = value
        self._n_set[j] = True
        self._res[j] = None

    def _normal_force(self, j: int) -> float:
        return self._n[j] if self._n_set[j] else getattr(self, f"{AXES[j]}_n0")

    def _energy_total(self) -> float:
        total = (self._e[0] + self._axis(0)[_DISS] + self._e[1] + self._axis(1)[_DISS]
                 + self._e[2] + self._axis(2)[_DISS])
        if not math.isfinite(total):
            raise self._fail(f"output E_fr would be {total!r} (the sum of the axes' "
                             f"energies overflows)")
        return total

    # ------------------------------------------------------------------ checks
    def _reject(self, message: str, value):
        """Reject the current FMI call: log ``message`` (status error), leave
        everything as it was and return ``value`` with the call marked fmi2Error
        through the loader; raise :class:`FMICallError` where that is impossible."""
        text = f"{MODEL_NAME}: {message}"  # the logger names the instance
        self.log(text, Fmi2Status.error)
        hook = _reject_hook(self.resources) if self._native else None
        if hook is None:
            raise FMICallError(text)
        hook()
        return value

    def _fail(self, message: str):
        return _Rejected(message)

    def _prepare(self) -> None:
        """Check every parameter once (parameter_check); keep the checked
        AxisParameters per axis."""
        try:
            axes = checked_axes(lambda name: getattr(self, name))
        except ParameterError as exc:
            raise self._fail(str(exc)) from None
        # an input n never set follows its parameter <axis>_n0
        for j, axis in enumerate(AXES):
            if not self._n_set[j]:
                self._n[j] = getattr(self, f"{axis}_n0")
            # a micro-slip axis keeps one position per slider, an inclined one its
            # InclinedState (a float otherwise)
            self._w[j] = conform_state(axes[j], self._w[j])
        self._axes = axes

    # ------------------------------------------------------------------ the law
    def _axis(self, j: int) -> tuple:
        """Trial return map of axis ``j`` at the current inputs (cached; commits
        nothing)."""
        res = self._res[j]
        if res is None:
            res = self._evaluate(j)
        return res

    def _evaluate(self, j: int) -> tuple:
        if self._axes is None:
            self._prepare()
        u, v, n = self._u[j], self._v[j], self._n[j]  # n synced by _prepare()
        if not (math.isfinite(u) and math.isfinite(v) and math.isfinite(n)):
            axis = AXES[j]
            raise self._fail(
                f"inputs of axis {axis} must be finite, got "
                f"u_{axis}={u!r}, v_{axis}={v!r}, n_{axis}={n!r}")
        p = self._axes[j]
        try:
            res = axis_force(u, v, self._w[j], p, n, self._dt)
        except ValueError as exc:  # the inclined element lost contact (ContactLost)
            raise self._fail(f"axis {AXES[j]} at u_{AXES[j]}={u!r}: {exc}") from None
        if not (math.isfinite(res[_F]) and math.isfinite(res[_KT])):
            axis = AXES[j]
            raise self._fail(f"the force of axis {axis} overflowed at "
                             f"u_{axis}={u!r}, v_{axis}={v!r}: F={res[_F]!r}")
        self._check_outputs(j, res)
        self._res[j] = res
        return res

    def _check_outputs(self, j: int, res) -> None:
        """Refuse (naming the output) a trial result whose other outputs would not be
        finite: parameters at their extremes (mu n overflowing, fs_ratio near the
        largest float, energies past it). No NaN or infinity reaches an output."""
        n1, n2 = normal_forces(self._axes[j], res[_W], self._n[j])
        w = res[_W] if isinstance(res[_W], tuple) else (res[_W],)
        for name, value in (("Ffr", res[_FFR]), ("E_fr", self._e[j] + res[_DISS]),
                            ("N", n1), ("N2", n2), ("w", math.fsum(w))):
            if not math.isfinite(value):
                axis = AXES[j]
                raise self._fail(f"output {name}_{axis} would be {value!r} at "
                                 f"u_{axis}={self._u[j]!r} (a parameter or input too "
                                 f"large for a finite result; nothing committed)")

    # ------------------------------------------------------------------ FMI calls
    @_fmi_call("fmi2SetupExperiment")
    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        why = setup_error(start_time)
        if why is not None:
            raise _Rejected(why)
        self._t_next = float(start_time)

    @_fmi_call("fmi2EnterInitializationMode")
    def enter_initialization_mode(self):
        self._mode = Mode.INITIALIZATION

    @_fmi_call("fmi2ExitInitializationMode")
    def exit_initialization_mode(self):
        self._prepare()  # invalid parameters: rejected, still initializationMode
        for j in range(3):  # the start outputs must be finite too
            self._axis(j)
        for j in range(3):  # where the first step's secant starts
            r = self._res[j]
            self._rec[j] = step_record.start_record(r[_F], r[_KT], self._u[j],
                                                    self._v[j], self._axes[j].c)
        self._mode = Mode.STEP_COMPLETE

    @_fmi_call("fmi2DoStep", rejected=lambda args: True)
    def do_step(self, current_time: float, step_size: float) -> bool:
        why = step_error(current_time, step_size, self._t_next)
        if why is not None:
            raise _Rejected(why)
        res = self._res
        results = [res[j] if res[j] is not None else self._evaluate(j)
                   for j in range(3)]
        rec = self._rec
        # Outputs now follow the committed state: re-evaluated on the next get,
        # except where the step changed nothing the trial depends on (an axis whose
        # inputs stay, e.g. one the host does not drive: the same call again).
        kept = [None, None, None]
        same_dt = float(step_size) == self._dt
        for j in range(3):
            r = results[j]
            if same_dt and r[_DISS] == 0.0 and _same_state(r[_W], self._w[j]):
                kept[j] = r
            self._w[j] = r[_W]
            self._e[j] += r[_DISS]
            rec[j] = step_record.step_record(rec[j], r[_F], r[_KT], r[_SLIP],
                                             r[_DISS], self._u[j], self._v[j],
                                             self._axes[j].c)
        self._res = kept
        self._t_next = current_time + step_size
        self._dt = float(step_size)
        return True

    @_fmi_call("fmi2Terminate")
    def terminate(self):
        self._mode = Mode.TERMINATED

    def _read(self, vr, kind: str):
        """Value of ``vr`` for fmi2Get<kind>; outputs read in initialization mode
        with invalid parameters are 0 (the error comes at
        fmi2ExitInitializationMode)."""
        var = self._var.get(vr)
        if var is None:
            raise _Rejected(f"fmi2Get{kind}: unknown value reference {vr!r}")
        if var.type != kind:
            raise _Rejected(f"fmi2Get{kind}: `{var.name}` (value reference {vr}) is "
                            f"a {var.type}; use fmi2Get{var.type}")
        if var.causality == "output" and self._mode in (Mode.INSTANTIATED,
                                                         Mode.INITIALIZATION):
            try:
                self._prepare() if self._axes is None else None
            except _Rejected as exc:
                if self._bad_params != str(exc):
                    self._bad_params = str(exc)
                    self.log(f"{MODEL_NAME}: outputs are 0 until the parameters "
                             f"are valid ({exc})", Fmi2Status.warning)
                return {"Real": 0.0, "Integer": 0, "Boolean": False}[kind]
        return self.vars[vr].getter()

    @_fmi_call("fmi2GetReal", rejected=lambda args: [0.0] * len(args[0]))
    def get_real(self, vrs):
        # Per-step fast path for the Real outputs (one dict lookup and a cached
        # evaluation per value); everything else goes through _read.
        fast, res, out = self._fast_outputs, self._res, []
        ready = self._axes is not None or self._mode in (Mode.STEP_COMPLETE,
                                                          Mode.TERMINATED)
        for vr in vrs:
            key = fast.get(vr) if ready else None
            if key is None:
                out.append(float(self._read(vr, "Real")))
            else:
                j, idx = key
                if idx == _KT and self._rec[j].post:  # after doStep: its tangent
                    out.append(self._rec[j].kt)
                    continue
                r = res[j]
                out.append((r if r is not None else self._evaluate(j))[idx])
        return out

    @_fmi_call("fmi2GetInteger", rejected=lambda args: [0] * len(args[0]))
    def get_integer(self, vrs):
        return [int(self._read(vr, "Integer")) for vr in vrs]

    @_fmi_call("fmi2GetBoolean", rejected=lambda args: [False] * len(args[0]))
    def get_boolean(self, vrs):
        return [bool(self._read(vr, "Boolean")) for vr in vrs]

    def _write(self, kind: str, vrs, values) -> None:
        """fmi2Set<kind>: every value is checked before any is set (a rejected call
        changes nothing)."""
        call = f"fmi2Set{kind}"
        if len(vrs) != len(values):
            raise _Rejected(f"{call}: {len(vrs)} value references, {len(values)} "
                            f"values")
        setters = []
        for vr, value in zip(vrs, values):
            var = self._var.get(vr)
            if var is None:
                raise _Rejected(f"{call}: unknown value reference {vr!r}")
            if var.type != kind:
                raise _Rejected(f"{call}: `{var.name}` (value reference {vr}) is a "
                                f"{var.type}; use fmi2Set{var.type}")
            why = set_error(call, var.name, var.causality, var.variability,
                            self._mode, value)
            if why is None and var.name.partition("_")[0] in SLIDER_SLOT_NAMES:
                why = self._slot_problem(var.name, value)
            if why is not None:
                raise _Rejected(why)
            setters.append((self.vars[vr].setter, value))
        for setter, value in setters:
            setter(value)

    @_fmi_call("fmi2SetReal")
    def set_real(self, vrs, values):
        # Per-step fast path for finite u and v in stepComplete; everything else is
        # checked by _write.
        fast, res = self._fast_inputs, self._res
        if self._mode is Mode.STEP_COMPLETE and all(
                vr in fast and math.isfinite(x) for vr, x in zip(vrs, values)) \
                and len(vrs) == len(values):
            rec = self._rec
            for vr, value in zip(vrs, values):
                store, j = fast[vr]
                if store[j] != value:
                    rec[j].post = False
                store[j] = value
                res[j] = None
            return
        self._write("Real", vrs, [float(x) for x in values])

    @_fmi_call("fmi2SetInteger")
    def set_integer(self, vrs, values):
        self._write("Integer", vrs, [int(x) for x in values])

    @_fmi_call("fmi2SetBoolean")
    def set_boolean(self, vrs, values):
        self._write("Boolean", vrs, [bool(x) for x in values])

    # ------------------------------------------------------------------ description
    def to_xml(self, model_options=None) -> Element:
        """pythonfmu's model description plus units, capabilities, model structure
        (model_description.complete)."""
        return model_description.complete(super().to_xml(model_options or {}))
