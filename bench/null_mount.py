"""NullMount: a pythonfmu slave with the FrictionMount variables that does nothing.

It registers exactly the variable names of ``FrictionMount.fmu`` (see the agreed
interface: inputs ``u_<axis>``, ``v_<axis>``, ``n_<axis>``; outputs ``F_<axis>``,
``Ffr_<axis>``, ``kt_<axis>``, ``slip_<axis>``, ``E_fr``, ``E_fr_<axis>``,
``slipped_<axis>``, ``dE_fr_<axis>``, ``ks_<axis>``; parameters
``<axis>_<field>``; locals ``w_<axis>``), so the vehicle harness can drive it
unchanged. Its ``do_step`` returns at once and its outputs stay at their start
values (zero force). The benchmark (``bench/bench_cosim.py``) builds it into a
temporary folder and times a raw loop over it: the floor of the FMI calls on this
machine (fmpy wrapper + ctypes + pythonfmu dispatch), with no model work at all.

One extra parameter, ``fail_at`` [s] (default -1: never), makes ``do_step`` log an
error and return False (fmi2Discard) at the first communication point
``t >= fail_at``; the tests use it
to check that the harness names the mount and the time of an FMU failure and frees
every instance.

This file is self-contained (pythonfmu only, no project imports) because pythonfmu
loads the script inside the host interpreter under its module name.
"""

try:
    import ctypes as _ctypes

    # pythonfmu 0.7.0's loader re-runs this file at every fmi2Instantiate and then
    # releases one reference to the module namespace it does not own (see
    # fmu_build/builder.py): hand it that reference, or a second instance crashes.
    _ctypes.pythonapi.Py_IncRef(_ctypes.py_object(globals()))
except (ImportError, AttributeError, OSError):  # no ctypes: hold a real reference
    globals().setdefault("_namespace_refs", []).append(globals())

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability  # noqa: E402
from pythonfmu.enums import Fmi2Status  # noqa: E402
from pythonfmu.variables import Boolean, Integer, Real  # noqa: E402
from drymount.fmu_src.interface import ALL_PARAMETER_FIELDS, AxisParameters  # noqa: E402

_AXES = ("axial", "radial1", "radial2")
# The real parameters of every axis, from the FMU interface (the registry of elastic
# laws and friction elements), at their defaults: the same set the harness asks for.
_DEFAULTS = AxisParameters()
_REAL_PARAMS = tuple((name, float(getattr(_DEFAULTS, name)))
                     for name, kind, *_ in ALL_PARAMETER_FIELDS if kind == "Real")


class NullMount(Fmi2Slave):
    """Do-nothing slave with the FrictionMount variable set (benchmark floor)."""

    author = "drymount"
    description = "FrictionMount variable set, no model (FMI-call floor benchmark)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.fail_at = -1.0
        self.register_variable(Real(
            "fail_at", causality=Fmi2Causality.parameter,
            variability=Fmi2Variability.tunable, start=self.fail_at,
            description="raise in do_step at the first t >= fail_at [s]; < 0: never"))
        out = dict(causality=Fmi2Causality.output,
                   variability=Fmi2Variability.continuous, initial=Fmi2Initial.exact)
        for a in _AXES:
            for name, descr in (("u", "deflection [m]"), ("v", "deflection rate [m/s]"),
                                ("n", "normal force [N]")):
                setattr(self, f"{name}_{a}", 0.0)
                self.register_variable(Real(
                    f"{name}_{a}", causality=Fmi2Causality.input,
                    variability=Fmi2Variability.continuous, start=0.0,
                    description=descr))
            for name, descr in (("F", "total force [N]"), ("Ffr", "friction force [N]"),
                                ("kt", "tangent stiffness [N/m]"),
                                ("E_fr", "energy dissipated on this axis [J]"),
                                ("N", "normal force [N]"),
                                ("N2", "second normal force [N]")):
                setattr(self, f"{name}_{a}", 0.0)
                self.register_variable(Real(f"{name}_{a}", start=0.0,
                                            description=descr, **out))
            for name in ("slip", "slipped"):
                setattr(self, f"{name}_{a}", False)
                self.register_variable(Boolean(
                    f"{name}_{a}", causality=Fmi2Causality.output,
                    variability=Fmi2Variability.discrete, initial=Fmi2Initial.exact,
                    start=False, description="slipping"))
            # the record of the last step (fmu_src/step_record.py)
            for name, descr in (("dE_fr", "energy dissipated in the last step [J]"),
                                ("ks", "secant stiffness of the last step [N/m]")):
                setattr(self, f"{name}_{a}", 0.0)
                self.register_variable(Real(
                    f"{name}_{a}", causality=Fmi2Causality.output,
                    variability=Fmi2Variability.discrete, initial=Fmi2Initial.exact,
                    start=0.0, description=descr))
            setattr(self, f"{a}_law", 0)
            self.register_variable(Integer(
                f"{a}_law", causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed, start=0, description="law code"))
            setattr(self, f"{a}_friction_kind", 0)
            self.register_variable(Integer(
                f"{a}_friction_kind", causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed, start=0,
                description="friction kind code"))
            setattr(self, f"{a}_sliders", 1)
            self.register_variable(Integer(
                f"{a}_sliders", causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed, start=1, description="sliders"))
            for name, value in _REAL_PARAMS:
                setattr(self, f"{a}_{name}", value)
                self.register_variable(Real(
                    f"{a}_{name}", causality=Fmi2Causality.parameter,
                    variability=Fmi2Variability.fixed, start=value, description=name))
            setattr(self, f"{a}_friction", False)
            self.register_variable(Boolean(
                f"{a}_friction", causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed, start=False, description="friction"))
            setattr(self, f"w_{a}", 0.0)
            self.register_variable(Real(
                f"w_{a}", causality=Fmi2Causality.local,
                variability=Fmi2Variability.continuous, initial=Fmi2Initial.exact,
                start=0.0, description="slider position [m]"))
        self.E_fr = 0.0
        self.register_variable(Real("E_fr", start=0.0,
                                    description="energy dissipated [J]", **out))

    def do_step(self, current_time, step_size):
        if 0.0 <= self.fail_at <= current_time:
            # Log and return False (fmi2Discard) rather than raise: a Python exception
            # escaping pythonfmu 0.7.0's do_step (fmi2Fatal path) was seen to corrupt
            # the host interpreter (segfault at a later garbage collection).
            self.log(f"NullMount: requested failure at t = {current_time}",
                     Fmi2Status.error)
            return False
        return True
