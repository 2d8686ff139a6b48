"""The InclinedMount FMU's slave class (pythonfmu ``Fmi2Slave``): glue only.

One axis carrying the inclined two-surface friction element of thesis Chapter 5;
every force comes from :func:`inclined.inclined_update` (imported relatively, so the
file works as ``fmu_src.inclined_mount`` and inside the FMU, see ``fmu_build``).

Protocol, as the FrictionMount FMU: per communication step the master sets ``u`` (and
``v``) at t_n and may read the outputs at once: the trial return map from the
committed deflection ``u_c`` and sliders ``w1``, ``w2`` to ``u`` (nothing committed by
a get); ``doStep`` commits ``u_c := u``, the sliders and the dissipated energy. The
element is quasi-static (inertia ignored, as in the thesis): ``v`` is accepted for
the harness's conventions and affects no output. The element is assembled at
``u_c = 0`` with relaxed sliders. Lost contact (a normal force < 0) is an error of
the get, and ``doStep`` returns fmi2Discard.
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import (
    Boolean,
    DefaultExperiment,
    Fmi2Causality,
    Fmi2Slave,
    Fmi2Variability,
    Real,
)
from pythonfmu.enums import Fmi2Status

from .friction_mount import _guarded
from .inclined import ContactLost, InclinedParameters, inclined_update
from .interface import BASE_UNITS, CAPABILITIES, DEFAULT_EXPERIMENT, Variable

try:  # written by fmu_build into the FMU's package; absent in the repository
    from . import FMU_VERSION
except ImportError:
    FMU_VERSION = "source"

__all__ = ["InclinedMount", "INCLINED_MODEL_NAME", "INCLINED_VARIABLES"]

INCLINED_MODEL_NAME = "InclinedMount"

_DEFAULTS = InclinedParameters()
_PARAMS = (("theta_deg", "deg",
            "angle of the inclined surface to the plate, in (0, 90]"),
           ("k", "N/m", "stiffness of the elastic pieces pushing the wedge, >= 0"),
           ("kf", "N/m", "tangential contact stiffness of the inclined surface, > 0"),
           ("kf2", "N/m", "tangential contact stiffness of the flat surface, > 0"),
           ("mu1", "1", "friction coefficient of the inclined surface, >= 0"),
           ("mu2", "1", "friction coefficient of the flat surface, >= 0"),
           ("preload", "N", "force of the elastic pieces at u = 0, >= 0"))

#: Every variable of the InclinedMount FMU, in value-reference order.
INCLINED_VARIABLES: tuple[Variable, ...] = (
    *(Variable(name, "Real", "parameter", "fixed", getattr(_DEFAULTS, name), unit, text)
      for name, unit, text in _PARAMS),
    Variable("u", "Real", "input", "continuous", 0.0, "m",
             "deflection along the mount axis, positive = into the wedge"),
    Variable("v", "Real", "input", "continuous", 0.0, "m/s",
             "deflection rate du/dt (quasi-static element: affects no output)"),
    Variable("F", "Real", "output", "continuous", None, "N",
             "force of the element along the mount axis (= N2)"),
    Variable("N", "Real", "output", "continuous", None, "N",
             "normal force on the inclined surface"),
    Variable("N2", "Real", "output", "continuous", None, "N",
             "normal force on the flat surface"),
    Variable("f1", "Real", "output", "continuous", None, "N",
             "friction force of the inclined surface"),
    Variable("f2", "Real", "output", "continuous", None, "N",
             "friction force of the flat surface"),
    Variable("kt", "Real", "output", "continuous", None, "N/m",
             "tangent stiffness dF/du in the direction of the last increment"),
    Variable("slip1", "Boolean", "output", "discrete", None, None,
             "true while the inclined surface slips"),
    Variable("slip2", "Boolean", "output", "discrete", None, None,
             "true while the flat surface slips"),
    Variable("E_fr", "Real", "output", "continuous", None, "J",
             "cumulative energy dissipated by both friction surfaces"),
    Variable("w1", "Real", "local", "continuous", 0.0, "m",
             "committed slider position of the inclined surface"),
    Variable("w2", "Real", "local", "continuous", 0.0, "m",
             "committed slider position of the flat surface"),
    Variable("u_c", "Real", "local", "continuous", 0.0, "m",
             "committed deflection (start of the next increment)"),
)

_UNIT_OF = {v.name: v.unit for v in INCLINED_VARIABLES}
_DEG = ("deg", {"rad": "1", "factor": repr(math.pi / 180)})
_OUT = {"F": "force", "N": "n1", "N2": "n2", "f1": "f1", "f2": "f2", "kt": "tangent",
        "slip1": "slip1", "slip2": "slip2"}


class InclinedMount(Fmi2Slave):
    """Inclined two-surface friction mount, one axis (FMI 2.0 Co-Simulation)."""

    author = "drymount"
    description = ("Inclined two-surface friction element of thesis Ch. 5 (exact "
                   "return map of both stick/slip states), one mount axis")
    version = FMU_VERSION
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._native = "logger" in kwargs
        self.default_experiment = DefaultExperiment(
            start_time=DEFAULT_EXPERIMENT["startTime"],
            stop_time=DEFAULT_EXPERIMENT["stopTime"],
            step_size=DEFAULT_EXPERIMENT["stepSize"])
        for name, *_ in _PARAMS:
            setattr(self, name, getattr(_DEFAULTS, name))
        self.u = self.v = 0.0
        self.w1 = self.w2 = self.u_c = 0.0
        self._e = 0.0
        self._res = None
        self._p = None
        for var in INCLINED_VARIABLES:
            self._register(var)

    def _register(self, var: Variable) -> None:
        typ = Boolean if var.type == "Boolean" else Real
        if var.causality == "output":
            if var.name == "E_fr":
                getter = lambda: self._e + self._step().dissipated  # noqa: E731
            else:
                getter = lambda f=_OUT[var.name]: getattr(self._step(), f)  # noqa: E731
            setter = None
        else:
            getter = lambda a=var.name: getattr(self, a)  # noqa: E731
            setter = lambda value, a=var.name: self._set(a, value)  # noqa: E731
        self.register_variable(typ(
            var.name, causality=Fmi2Causality[var.causality],
            variability=Fmi2Variability[var.variability],
            description=var.description, getter=getter, setter=setter))

    def _set(self, name: str, value) -> None:
        setattr(self, name, value)
        self._res = None
        if name in _UNIT_OF and name not in ("u", "v", "w1", "w2", "u_c"):
            self._p = None

    def _fail(self, message: str) -> ValueError:
        self.log(message, Fmi2Status.error)
        return ValueError(message)

    def _prepare(self) -> None:
        """Check every parameter; report all problems with the variable names."""
        values = {name: getattr(self, name) for name, *_ in _PARAMS}
        problems = InclinedParameters.problems(
            SimpleNamespace(**values, sc=_sc(values["theta_deg"]),
                            self_locking_margin=lambda: _margin(values)))
        if problems:
            raise self._fail("InclinedMount: invalid parameters: "
                             + "; ".join(problems))
        self._p = InclinedParameters(**values)

    def _step(self):
        """Trial return map from the committed state to the input ``u`` (cached)."""
        if self._res is None:
            if self._p is None:
                self._prepare()
            if not (math.isfinite(self.u) and math.isfinite(self.v)):
                raise self._fail(f"InclinedMount: inputs must be finite, got "
                                 f"u={self.u!r}, v={self.v!r}")
            try:
                self._res = inclined_update(self.u, self.u_c, self.w1, self.w2, self._p)
            except ContactLost as exc:
                raise self._fail(f"InclinedMount: {exc}") from None
        return self._res

    @_guarded
    def exit_initialization_mode(self):
        self._prepare()

    @_guarded
    def do_step(self, current_time: float, step_size: float) -> bool:
        try:
            st = self._step()
        except ValueError:
            return False   # logged by _fail: fmi2Discard
        self.u_c, self.w1, self.w2 = self.u, st.w1, st.w2
        self._e += st.dissipated
        self._res = None
        return True

    @_guarded
    def _get_fmu_state(self) -> dict:
        state = {v.name: getattr(self, v.name) for v in INCLINED_VARIABLES
                 if v.causality != "output"}
        state["_E_committed"] = self._e
        return state

    @_guarded
    def _set_fmu_state(self, state: dict) -> None:
        for v in INCLINED_VARIABLES:
            if v.causality != "output":
                setattr(self, v.name, state[v.name])
        self._e = float(state["_E_committed"])
        self._p = self._res = None

    get_real = _guarded(Fmi2Slave.get_real)
    get_boolean = _guarded(Fmi2Slave.get_boolean)
    set_real = _guarded(Fmi2Slave.set_real)

    def to_xml(self, model_options=None) -> Element:
        """pythonfmu's model description plus units, capabilities, model structure."""
        root = super().to_xml(model_options or {})
        cosim = root.find("CoSimulation")
        for flag, value in CAPABILITIES.items():
            cosim.set(flag, "true" if value else "false")
        units = Element("UnitDefinitions")
        for name, exps in (*BASE_UNITS.items(), _DEG):
            SubElement(SubElement(units, "Unit", name=name), "BaseUnit",
                       {k: str(e) for k, e in exps.items()})
        root.insert(list(root).index(cosim) + 1, units)
        index = {}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = str(i)
            if _UNIT_OF.get(sv.get("name")):
                sv.find("Real").set("unit", _UNIT_OF[sv.get("name")])
        root.remove(root.find("ModelStructure"))
        structure = SubElement(root, "ModelStructure")
        outputs = SubElement(structure, "Outputs")
        initial = SubElement(structure, "InitialUnknowns")
        for v in INCLINED_VARIABLES:
            if v.causality == "output":
                SubElement(outputs, "Unknown", index=index[v.name],
                           dependencies=index["u"])
                SubElement(initial, "Unknown", index=index[v.name])
        return root


def _sc(theta) -> tuple[float, float]:
    try:
        return InclinedParameters.sc.fget(SimpleNamespace(theta_deg=theta))
    except TypeError:
        return math.nan, math.nan


def _margin(values: dict) -> float:
    ns = SimpleNamespace(**values)
    ns.sc = _sc(values["theta_deg"])
    return InclinedParameters.self_locking_margin(ns)
