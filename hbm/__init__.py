"""Harmonic balance with arc-length continuation for friction-damped engine mounts.

Public API (thesis Chapter 3):

- :func:`frequency_response` - steady-state curve from fmin to fmax (arc length).
- :func:`solve_frequencies` - Newton at given frequencies (validation).
- :class:`HBMOptions` (the one source of the defaults), :class:`FrequencyResponse`,
  :class:`Status` (how a curve ended).
- :func:`linear_frf`, :func:`natural_frequencies` - linear analysis.
- :class:`System`, :class:`MountElement`, :class:`Excitation`,
  :class:`Transmissibility` - the shared system description (:mod:`hbm.system`).
- :func:`hbm.reference.periodic_response` - independent time integration (scipy)
  with event-exact stick-slip, for validation.
"""

from hbm.analysis import frequency_response, solve_frequencies
from hbm.continuation import Status
from hbm.linear import linear_frf, natural_frequencies
from hbm.options import HBMOptions
from hbm.result import FrequencyResponse
from hbm.system import Excitation, MountElement, System, Transmissibility

__all__ = [
    "frequency_response",
    "solve_frequencies",
    "HBMOptions",
    "FrequencyResponse",
    "Status",
    "linear_frf",
    "natural_frequencies",
    "System",
    "MountElement",
    "Excitation",
    "Transmissibility",
]
