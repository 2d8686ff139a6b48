"""The configuration's numeric bounds, importable without NumPy (the command line's
parser states them in its ``--help``)."""

from __future__ import annotations

from drymount.hbm.options import MAX_HARMONICS as _HBM_MAX_HARMONICS

__all__ = ["MAX_HARMONICS", "MAX_N_SAMPLES", "MAX_POINTS"]

#: Largest number of harmonics accepted: the HBM's one bound (hbm.options).
MAX_HARMONICS = _HBM_MAX_HARMONICS
#: Largest number of AFT samples per period (64..1024 are used; 8192 resolves the
#: sharpest kink of the friction law at H = 50 many times over).
MAX_N_SAMPLES = 8192
#: Largest number of sweep frequencies (a 10 000-point co-simulated sweep takes
#: hours; more is a typo).
MAX_POINTS = 10_000
