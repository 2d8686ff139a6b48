"""The configuration's numeric bounds, importable without NumPy (the command line's
parser states them in its ``--help``)."""

from __future__ import annotations

from drymount.hbm.options import MAX_HARMONICS, MAX_N_SAMPLES  # the one bound of each

__all__ = ["MAX_HARMONICS", "MAX_N_SAMPLES", "MAX_POINTS"]

#: Largest number of sweep frequencies (a 10 000-point co-simulated sweep takes
#: hours; more is a typo).
MAX_POINTS = 10_000
