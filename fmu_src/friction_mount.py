"""The FrictionMount FMU's slave class (pythonfmu ``Fmi2Slave``): glue only.

Every force comes from :mod:`mount_law` (imported relatively, so the same file works as
``fmu_src.friction_mount`` in the repository and as ``<unique package>.friction_mount``
inside the FMU, see ``drymount.fmu_build``). This module adds the FMI variables, their
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

from .mount_law import AXES, LAWS, AxisParameters, axis_force

try:  # written by drymount.fmu_build into the FMU's package; absent in the repository
    from . import FMU_VERSION
except ImportError:
    FMU_VERSION = "source"

__all__ = ["FrictionMount", "UNITS", "BASE_UNITS"]

#: SI exponents of every unit the model description uses (FMI 2.0 ``BaseUnit``).
BASE_UNITS = {
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "N/m3": {"kg": 1, "m": -2, "s": -2},
    "N.s/m": {"kg": 1, "s": -1},
    "J": {"kg": 1, "m": 2, "s": -2},
    "1": {},
}

# (field, FMI type, unit, description) of the parameters, in AxisParameters' order.
_PARAMETERS = (
    ("law", "Integer", None,
     "elastic law: 0 = linear, 1 = cubic, 2 = piecewise, 3 = piecewise_asym"),
    ("k1", "Real", "N/m", "linear (small-deflection) stiffness, >= 0"),
    ("kc", "Real", "N/m3", "cubic stiffness (law 1), >= 0"),
    ("k2", "Real", "N/m", "stiffness beyond the knee (laws 2, 3), >= 0"),
    ("delta", "Real", "m", "knee deflection for u > 0 (and u < 0 with law 2), > 0"),
    ("delta_neg", "Real", "m", "knee deflection magnitude for u < 0 with law 3, > 0"),
    ("c", "Real", "N.s/m", "viscous damping, >= 0"),
    ("friction", "Boolean", None, "whether the macro-slip (Jenkins) element exists"),
    ("kf", "Real", "N/m", "contact stiffness of the Jenkins element, > 0 if friction"),
    ("mu", "Real", "1", "friction coefficient, >= 0 (slip force Fs = mu * n)"),
    ("n0", "Real", "N", "normal force on the contact, >= 0; start value of n_<axis>"),
)

#: Unit of every Real variable, by name (Integer and Boolean variables have none).
UNITS: dict[str, str] = {}
for _axis in AXES:
    UNITS.update({f"{_axis}_{name}": unit for name, typ, unit, _ in _PARAMETERS
                  if typ == "Real"})
    UNITS.update({f"u_{_axis}": "m", f"v_{_axis}": "m/s", f"n_{_axis}": "N",
                  f"F_{_axis}": "N", f"Ffr_{_axis}": "N", f"kt_{_axis}": "N/m",
                  f"E_fr_{_axis}": "J", f"w_{_axis}": "m"})
UNITS["E_fr"] = "J"

# Declared ranges of the parameters (strict bounds such as delta > 0 and the rule for
# kf are in the descriptions and checked at initialization).
_BOUNDS = {"law": {"min": "0", "max": str(len(LAWS) - 1)}}
_BOUNDS.update({name: {"min": "0"} for name, typ, *_ in _PARAMETERS if typ == "Real"})

# Indices into the axis_force result tuple.
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
            start_time=0.0, stop_time=1.0, step_size=1e-4)
        defaults = AxisParameters()
        # Parameters as plain attributes named like the FMU variables.
        for axis in AXES:
            for name, _, _, _ in _PARAMETERS:
                value = defaults.law_code if name == "law" else getattr(defaults, name)
                setattr(self, f"{axis}_{name}", value)
        # Inputs, committed state and the per-axis evaluation cache, in AXES order.
        self._u = [0.0, 0.0, 0.0]
        self._v = [0.0, 0.0, 0.0]
        self._n = [float(defaults.n0)] * 3
        self._n_set = [False, False, False]  # n follows <axis>_n0 until set
        self._w = [0.0, 0.0, 0.0]
        self._e = [0.0, 0.0, 0.0]  # committed dissipated energy per axis, J
        self._res = [None, None, None]
        self._coef = None  # per-axis tuples of checked parameters, see _prepare()
        self._register_all()
        by_name = {var.name: vr for vr, var in self.vars.items()}
        self._fast_inputs = {by_name[f"{q}_{axis}"]: (store, j)
                             for j, axis in enumerate(AXES)
                             for q, store in (("u", self._u), ("v", self._v))}
        self._fast_outputs = {by_name[f"{name}_{axis}"]: (j, idx)
                              for j, axis in enumerate(AXES)
                              for name, idx in (("F", _F), ("Ffr", _FFR), ("kt", _KT))}

    # ------------------------------------------------------------------ variables
    def _register_all(self) -> None:
        fixed, par = Fmi2Variability.fixed, Fmi2Causality.parameter
        types = {"Real": Real, "Integer": Integer, "Boolean": Boolean}
        for axis in AXES:
            for name, typ, _, text in _PARAMETERS:
                attr = f"{axis}_{name}"
                self.register_variable(types[typ](
                    attr, causality=par, variability=fixed,
                    description=f"{axis}: {text}",
                    getter=(lambda a=attr: getattr(self, a)),
                    setter=(lambda value, a=attr: self._set_parameter(a, value))))
        inp, cont = Fmi2Causality.input, Fmi2Variability.continuous
        for j, axis in enumerate(AXES):
            self.register_variable(Real(
                f"u_{axis}", causality=inp, variability=cont,
                description=f"{axis}: deflection, engine side minus chassis side",
                getter=lambda j=j: self._u[j],
                setter=lambda value, j=j: self._set_input(self._u, j, value)))
            self.register_variable(Real(
                f"v_{axis}", causality=inp, variability=cont,
                description=f"{axis}: deflection rate d(u_{axis})/dt",
                getter=lambda j=j: self._v[j],
                setter=lambda value, j=j: self._set_input(self._v, j, value)))
            self.register_variable(Real(
                f"n_{axis}", causality=inp, variability=cont,
                description=(f"{axis}: normal force of the friction contact; equals "
                             f"{axis}_n0 until set; negative = lost contact (Fs = 0)"),
                getter=lambda j=j: self._normal_force(j),
                setter=lambda value, j=j: self._set_normal_force(j, value)))
        out = Fmi2Causality.output
        for j, axis in enumerate(AXES):
            for name, idx, text in (
                ("F", _F, "total force, positive = tension (chassis pulled along "
                          "+axis, engine feels -F)"),
                ("Ffr", _FFR, "friction force of the Jenkins element"),
                ("kt", _KT, "tangent stiffness dF/du (damping tangent dF/dv is c)"),
            ):
                self.register_variable(Real(
                    f"{name}_{axis}", causality=out, variability=cont,
                    description=f"{axis}: {text}",
                    getter=lambda j=j, idx=idx: self._axis(j)[idx]))
            self.register_variable(Boolean(
                f"slip_{axis}", causality=out, variability=Fmi2Variability.discrete,
                description=f"{axis}: true while the friction slider slips",
                getter=lambda j=j: self._axis(j)[_SLIP]))
            self.register_variable(Real(
                f"E_fr_{axis}", causality=out, variability=cont,
                description=f"{axis}: cumulative energy dissipated by friction",
                getter=lambda j=j: self._e[j] + self._axis(j)[_DISS]))
        self.register_variable(Real(
            "E_fr", causality=out, variability=cont,
            description="cumulative energy dissipated by friction, all axes",
            getter=self._energy_total))
        for j, axis in enumerate(AXES):
            self.register_variable(Real(
                f"w_{axis}", causality=Fmi2Causality.local, variability=cont,
                initial=Fmi2Initial.exact,
                description=f"{axis}: committed slider position of the Jenkins element",
                getter=lambda j=j: self._w[j],
                setter=lambda value, j=j: self._set_input(self._w, j, value)))

    def _set_parameter(self, attr: str, value) -> None:
        setattr(self, attr, value)
        self._coef = None
        self._res = [None, None, None]

    def _set_input(self, store: list, j: int, value: float) -> None:
        store[j] = value
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
        """Check every parameter once; keep plain tuples for the per-step law calls."""
        problems, coef = [], []
        for axis in AXES:
            values = {name: getattr(self, f"{axis}_{name}") for name, *_ in _PARAMETERS}
            code = values["law"]
            if isinstance(code, int) and not isinstance(code, bool) and 0 <= code < len(
                    LAWS):
                values["law"] = LAWS[code]
            else:
                allowed = ", ".join(f"{i} = {name}" for i, name in enumerate(LAWS))
                problems.append(f"`{axis}_law` must be one of {allowed}, got {code!r}")
                values["law"] = LAWS[0]
            # problems() only reads attributes: run it on the raw values so that every
            # problem of every axis is reported with the FMU variable name.
            problems += AxisParameters.problems(SimpleNamespace(**values), f"{axis}_")
            if not problems:
                p = AxisParameters(**values)
                coef.append((p.law_code, p.k1, p.kc, p.k2, p.delta, p.delta_neg, p.c,
                             p.kf if p.friction else 0.0, p.mu if p.friction else 0.0))
        if problems:
            raise self._fail(
                "FrictionMount: invalid parameters: " + "; ".join(problems))
        # an input n never set follows its parameter <axis>_n0
        for j, axis in enumerate(AXES):
            if not self._n_set[j]:
                self._n[j] = getattr(self, f"{axis}_n0")
        self._coef = coef

    # ------------------------------------------------------------------ the law
    def _axis(self, j: int) -> tuple:
        """Trial return map of axis ``j`` at the current inputs (cached; commits
        nothing)."""
        res = self._res[j]
        if res is None:
            res = self._evaluate(j)
        return res

    def _evaluate(self, j: int) -> tuple:
        if self._coef is None:
            self._prepare()
        u, v, n = self._u[j], self._v[j], self._n[j]  # n synced by _prepare()
        if not (math.isfinite(u) and math.isfinite(v) and math.isfinite(n)):
            axis = AXES[j]
            raise self._fail(
                f"FrictionMount: inputs of axis {axis} must be finite, got "
                f"u_{axis}={u!r}, v_{axis}={v!r}, n_{axis}={n!r}")
        law, k1, kc, k2, delta, delta_neg, c, kf, mu = self._coef[j]
        # A negative normal force means lost contact: Fs = mu * max(n, 0).
        fs = mu * n if n > 0.0 else 0.0
        res = axis_force(u, v, self._w[j], law, k1, kc, k2, delta, delta_neg, c, kf, fs)
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
        return state

    @_guarded
    def _set_fmu_state(self, state: dict) -> None:
        by_name = {var.name: var for var in self.vars.values()}
        for name, value in state.items():
            if name in by_name:
                by_name[name].setter(value)
        self._e = [float(x) for x in state["_E_committed"]]
        self._n_set = [bool(x) for x in state["_n_set"]]
        self._coef = None
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
        cosim.set("needsExecutionTool", "false")
        cosim.set("canHandleVariableCommunicationStepSize", "true")
        cosim.set("canBeInstantiatedOnlyOncePerProcess", "false")
        cosim.set("canGetAndSetFMUstate", "true")
        cosim.set("canSerializeFMUstate", "true")
        # UnitDefinitions follows the CoSimulation element (FMI 2.0 schema order).
        units = Element("UnitDefinitions")
        for name, exps in BASE_UNITS.items():
            SubElement(SubElement(units, "Unit", name=name), "BaseUnit",
                       {k: str(e) for k, e in exps.items()})
        root.insert(list(root).index(cosim) + 1, units)
        index = {}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = str(i)
            unit = UNITS.get(sv.get("name"))
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
