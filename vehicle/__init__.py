"""Vehicle harness: engines and vehicles as rigid bodies co-simulating mount FMUs.

- ``sdof``, ``quarter_car``, ``rigid_engine``: the system builders of
  :mod:`hbm.systems`, re-exported for convenience.
- :mod:`vehicle.inputs`: harmonic, crank-mechanism, road and base inputs.
- :mod:`vehicle.master`: fixed-step master (leapfrog with a velocity predictor, one
  mount-force evaluation per step), :func:`simulate`.
- :mod:`vehicle.backends`: ``inproc`` (the mount law in-process) and ``fmu`` (one
  ``FrictionMount.fmu`` instance per mount through fmpy).
- :mod:`vehicle.sampled`: measured (sampled) base displacement and DOF forces,
  resampled to the step by a cubic spline.
- :mod:`vehicle.steady`: periodic steady state, :func:`steady_state`.
- :mod:`vehicle.sweep`: stepped-sine sweeps, :func:`sweep`.
"""

from .backends import FMUError
from .inputs import (
    BaseSine,
    BumpRoad,
    CrankInput,
    CrankRunUp,
    HarmonicInput,
    Input,
    RandomRoad,
    SineRoad,
    SumInput,
    SweptSineRoad,
)
from drymount.hbm.systems import quarter_car, rigid_engine, sdof

from .master import DivergenceError, Master, simulate
from .results import TimeHistory
from .sampled import SampledBase, SampledForce
from .steady import SteadyState, steady_state
from .sweep import SweepResult, sweep

__all__ = [
    "BaseSine",
    "BumpRoad",
    "CrankInput",
    "CrankRunUp",
    "DivergenceError",
    "FMUError",
    "HarmonicInput",
    "Input",
    "Master",
    "RandomRoad",
    "SampledBase",
    "SampledForce",
    "SineRoad",
    "SteadyState",
    "SumInput",
    "SweepResult",
    "SweptSineRoad",
    "TimeHistory",
    "quarter_car",
    "rigid_engine",
    "sdof",
    "simulate",
    "steady_state",
    "sweep",
]
