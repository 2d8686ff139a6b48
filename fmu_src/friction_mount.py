"""The FrictionMount FMU's slave class (pythonfmu ``Fmi2Slave``): glue only.

Every force comes from :mod:`mount_law` (imported relatively, so the same file works as
``fmu_src.friction_mount`` in the repository and as ``<unique package>.friction_mount``
inside the FMU, see ``fmu_build``). This module adds the FMI variables, their
units, the model structure, parameter checks and the co-simulation protocol:

* per communication step t_n -> t_n + h the master sets ``u_<axis>``, ``v_<axis>`` (and
  ``n_<axis>``) at t_n and may read the outputs at once: they are the trial return map
  ``axis_force(u(t_n), v(t_n), w_{n-1})`` (direct feedthrough, nothing committed by a
  get; thesis eq. 2.10-2.13 and 2.15-2.20);
* ``doStep(t_n, h)`` commits the slider positions ``w := w_new(u(t_n))`` and adds the
  energy the sliders dissipated, ``Fs |w_new - w|``. The FMU integrates nothing in time.

Outputs are a pure function of (parameters, inputs, committed state): evaluations are
cached per axis and invalidated by the setters, so reading all outputs of an axis costs
one law evaluation. The normal-force input is clipped at zero (a negative value means
lost contact): ``Fs = mu * max(n, 0)``. Standard library only (plus pythonfmu, which the
FMU bundles).
"""

from __future__ import annotations

import functools
import math
from types import SimpleNamespace
from xml.etree.ElementTree import Element, SubElement

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

from .interface import (
    BASE_UNITS,
    CAPABILITIES,
    DEFAULT_EXPERIMENT,
    PARAMETER_FIELDS,
    VARIABLES,
)
from .mount_law import (AXES, LAWS, AxisParameters, axis_force, initial_sliders,
                        law_code, law_name, mean_slider)

try:  # written by fmu_build into the FMU's package; absent in the repository
    from . import FMU_VERSION
except ImportError:
    FMU_VERSION = "source"

__all__ = ["FrictionMount"]

_TYPES = {"Real": Real, "Integer": Integer, "Boolean": Boolean}
_CAUSALITY = {c.name: c for c in Fmi2Causality}
_VARIABILITY = {v.name: v for v in Fmi2Variability}
_INITIAL = {i.name: i for i in Fmi2Initial}
_PARAMETER_NAMES = tuple(name for name, *_ in PARAMETER_FIELDS)

# Declared ranges of the parameters (strict bounds such as delta > 0 and the rule for
# kf are in the descriptions and checked at initialization).
_BOUNDS = {"law": {"min": "0", "max": str(len(LAWS) - 1)}}
_BOUNDS.update({name: {"min": "0"} for name, typ, *_ in PARAMETER_FIELDS
                if typ == "Real"})

# Indices into the AxisForce result (mount_law.axis_force).
_F, _FFR, _W, _KT, _SLIP, _DISS = range(6)


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


def _guarded(method):
    """Wrap an FMI entry point: an escaping exception first calls
    :func:`_hold_native_references` when pythonfmu's native wrapper is the caller."""

    @functools.wraps(method)
    def entry(self, *args):
        try:
            return method(self, *args)
        except BaseException:
            if self._native:
                _hold_native_references(self)
            raise

    return entry


class FrictionMount(Fmi2Slave):
    """Friction-damped engine mount, three local axes (FMI 2.0 Co-Simulation).

    Variables (names as in docs/fmu.md), for each axis in ``AXES``: parameters
    ``<axis>_<field>`` (the fields of :class:`AxisParameters`, ``law`` as its integer
    code), inputs ``u_<axis>`` [m], ``v_<axis>`` [m/s], ``n_<axis>`` [N], outputs
    ``F_<axis>`` [N], ``Ffr_<axis>`` [N], ``kt_<axis>`` [N/m], ``slip_<axis>``,
    ``E_fr_<axis>`` [J], plus ``E_fr`` [J] (all axes) and locals ``w_<axis>`` [m].
    """

    author = "drymount"
    description = ("Friction-damped engine mount: elastic law + viscous damping + "
                   "macro-slip (Jenkins) friction element on three local axes")
    version = FMU_VERSION
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        # pythonfmu's native wrapper passes a `logger` handle; Python callers do not
        self._native = "logger" in kwargs
        self.default_experiment = DefaultExperiment(
            start_time=DEFAULT_EXPERIMENT["startTime"],
            stop_time=DEFAULT_EXPERIMENT["stopTime"],
            step_size=DEFAULT_EXPERIMENT["stepSize"])
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
        self._res = [None, None, None]
        self._axes = None  # per-axis checked AxisParameters, see _prepare()
        self._register_all()
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
            return ((lambda: mean_slider(self._w[j])),
                    (lambda value: self._set_sliders(j, value)))
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

    def _set_parameter(self, attr: str, value) -> None:
        setattr(self, attr, value)
        self._axes = None
        self._res = [None, None, None]

    def _set_input(self, store: list, j: int, value: float) -> None:
        store[j] = value
        self._res[j] = None

    def _set_sliders(self, j: int, value: float) -> None:
        """``w_<axis>`` = value: every slider of the axis at ``value`` (m)."""
        n = getattr(self, f"{AXES[j]}_sliders")
        multi = isinstance(n, int) and not isinstance(n, bool) and n > 1
        self._w[j] = tuple([float(value)] * n) if multi else value
        self._res[j] = None

    def _set_normal_force(self, j: int, value: float) -> None:
        self._n[j] = value
        self._n_set[j] = True
        self._res[j] = None

    def _normal_force(self, j: int) -> float:
        return self._n[j] if self._n_set[j] else getattr(self, f"{AXES[j]}_n0")

    def _energy_total(self) -> float:
        return (self._e[0] + self._axis(0)[_DISS] + self._e[1] + self._axis(1)[_DISS]
                + self._e[2] + self._axis(2)[_DISS])

    # ------------------------------------------------------------------ checks
    def _fail(self, message: str, status: Fmi2Status = Fmi2Status.error):
        self.log(message, status)
        return ValueError(message)

    def _prepare(self) -> None:
        """Check every parameter once; keep the checked AxisParameters per axis."""
        problems, axes = [], []
        for axis in AXES:
            values = {name: getattr(self, f"{axis}_{name}")
                      for name in _PARAMETER_NAMES}
            code = values["law"]
            values["law"] = law_name(code)
            if values["law"] is None:
                allowed = ", ".join(f"{law_code(name)} = {name}" for name in LAWS)
                problems.append(f"`{axis}_law` must be one of {allowed}, got {code!r}")
                values["law"] = LAWS[0]
            # problems() only reads attributes: run it on the raw values so that every
            # problem of every axis is reported with the FMU variable name.
            problems += AxisParameters.problems(SimpleNamespace(**values), f"{axis}_")
            if not problems:
                axes.append(AxisParameters(**values))
        if problems:
            raise self._fail(
                "FrictionMount: invalid parameters: " + "; ".join(problems))
        # an input n never set follows its parameter <axis>_n0
        for j, axis in enumerate(AXES):
            if not self._n_set[j]:
                self._n[j] = getattr(self, f"{axis}_n0")
            # a micro-slip axis keeps one position per slider (float otherwise)
            w, p = self._w[j], axes[j]
            if len(w if isinstance(w, tuple) else (w,)) != (
                    p.sliders if p.micro_slip else 1):
                self._w[j] = initial_sliders(p, mean_slider(w))
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
                f"FrictionMount: inputs of axis {axis} must be finite, got "
                f"u_{axis}={u!r}, v_{axis}={v!r}, n_{axis}={n!r}")
        p = self._axes[j]
        # A negative normal force means lost contact: Fs = mu * max(n, 0).
        fs = p.mu * n if n > 0.0 else 0.0
        res = axis_force(u, v, self._w[j], p, fs)
        if not (math.isfinite(res[_F]) and math.isfinite(res[_KT])):
            axis = AXES[j]
            raise self._fail(f"FrictionMount: force of axis {axis} overflowed at "
                             f"u_{axis}={u!r}, v_{axis}={v!r}: F={res[_F]!r}")
        self._res[j] = res
        return res

    # ------------------------------------------------------------------ FMI calls
    @_guarded
    def exit_initialization_mode(self):
        self._prepare()

    @_guarded
    def do_step(self, current_time: float, step_size: float) -> bool:
        res = self._res
        try:
            results = [res[j] if res[j] is not None else self._evaluate(j)
                       for j in range(3)]
        except ValueError:
            # already logged by _fail; fmi2Discard lets the master stop or retry
            return False
        for j in range(3):
            r = results[j]
            self._w[j] = r[_W]
            self._e[j] += r[_DISS]
        # Outputs now follow the committed state: re-evaluated on the next get.
        self._res = [None, None, None]
        return True

    # getFMUstate/setFMUstate: everything settable plus the committed energy.
    @_guarded
    def _get_fmu_state(self) -> dict:
        state = {var.name: var.getter() for var in self.vars.values()
                 if var.setter is not None}
        state["_E_committed"] = [float(x) for x in self._e]
        state["_n_set"] = list(self._n_set)
        state["_w"] = [list(w) if isinstance(w, tuple) else w for w in self._w]
        return state

    @_guarded
    def _set_fmu_state(self, state: dict) -> None:
        by_name = {var.name: var for var in self.vars.values()}
        for name, value in state.items():
            if name in by_name:
                by_name[name].setter(value)
        self._e = [float(x) for x in state["_E_committed"]]
        self._n_set = [bool(x) for x in state["_n_set"]]
        self._w = [tuple(float(x) for x in w) if isinstance(w, list) else float(w)
                   for w in state["_w"]]
        self._axes = None
        self._res = [None, None, None]

    @_guarded
    def get_real(self, vrs):
        # Per-step fast path for the Real outputs (one dict lookup and a cached
        # evaluation per value); everything else goes through pythonfmu's getter.
        fast, res, out = self._fast_outputs, self._res, []
        for vr in vrs:
            key = fast.get(vr)
            if key is None:
                out.extend(Fmi2Slave.get_real(self, [vr]))
            else:
                j, idx = key
                r = res[j]
                out.append((r if r is not None else self._evaluate(j))[idx])
        return out

    get_integer = _guarded(Fmi2Slave.get_integer)
    get_boolean = _guarded(Fmi2Slave.get_boolean)

    @_guarded
    def set_real(self, vrs, values):
        # Per-step fast path for u and v; parameters and n take pythonfmu's setters.
        fast, res = self._fast_inputs, self._res
        for vr, value in zip(vrs, values):
            key = fast.get(vr)
            if key is None:
                Fmi2Slave.set_real(self, [vr], [value])
            else:
                store, j = key
                store[j] = value
                res[j] = None

    set_integer = _guarded(Fmi2Slave.set_integer)
    set_boolean = _guarded(Fmi2Slave.set_boolean)

    # ------------------------------------------------------------------ description
    def to_xml(self, model_options=None) -> Element:
        """pythonfmu's model description plus units, capabilities, model structure."""
        root = super().to_xml(model_options or {})
        cosim = root.find("CoSimulation")
        for flag, value in CAPABILITIES.items():
            cosim.set(flag, "true" if value else "false")
        # UnitDefinitions follows the CoSimulation element (FMI 2.0 schema order).
        units = Element("UnitDefinitions")
        for name, exps in BASE_UNITS.items():
            SubElement(SubElement(units, "Unit", name=name), "BaseUnit",
                       {k: str(e) for k, e in exps.items()})
        root.insert(list(root).index(cosim) + 1, units)
        index = {}
        unit_of = {var.name: var.unit for var in VARIABLES}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = str(i)
            unit = unit_of.get(sv.get("name"))
            if unit is not None:
                sv.find("Real").set("unit", unit)
            bounds = _BOUNDS.get(sv.get("name").partition("_")[2])
            if bounds is not None and sv.get("causality") == "parameter":
                sv[0].attrib.update(bounds)
        root.remove(root.find("ModelStructure"))
        structure = SubElement(root, "ModelStructure")
        outputs = SubElement(structure, "Outputs")
        initial = SubElement(structure, "InitialUnknowns")
        for axis in AXES:
            deps = {"F": ("u", "v", "n")}
            for name in ("F", "Ffr", "kt", "slip", "E_fr"):
                refs = " ".join(index[f"{d}_{axis}"]
                                for d in deps.get(name, ("u", "n")))
                SubElement(outputs, "Unknown", index=index[f"{name}_{axis}"],
                           dependencies=refs)
        SubElement(outputs, "Unknown", index=index["E_fr"], dependencies=" ".join(
            index[f"{d}_{axis}"] for axis in AXES for d in ("u", "n")))
        # Initial values of the outputs depend on inputs, parameters and the start
        # value of w: no `dependencies` attribute = depends on all knowns (FMI 2.0).
        for unknown in outputs:
            SubElement(initial, "Unknown", index=unknown.get("index"))
        return root
