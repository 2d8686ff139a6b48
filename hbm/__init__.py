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

from drymount.hbm.lazy import lazy_face

# The names are imported on first use (PEP 562): ``drymount`` binds this package on
# import (``drymount.hbm`` is also the API function), so its face must stay light.
_WHERE = {
    "frequency_response": "analysis",
    "solve_frequencies": "analysis",
    "Status": "continuation",
    "linear_frf": "linear",
    "natural_frequencies": "linear",
    "HBMOptions": "options",
    "FrequencyResponse": "result",
    "Excitation": "system",
    "MountElement": "system",
    "System": "system",
    "Transmissibility": "system",
}

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


__getattr__, __dir__ = lazy_face(__name__, _WHERE, __all__)
