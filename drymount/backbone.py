"""The backbone beside a forced curve (``drymount hbm --backbone``).

The backbone of a mode is its nonlinear mode (EPMC, :mod:`hbm.modes`): frequency and
the DOF amplitudes of the free periodic motion against amplitude. The resonance peaks
of forced curves at different force levels lie on it: exactly for a conservative
nonlinearity with light damping (the Duffing tests of ``tests/test_modes.py``: within
4e-6 at H = 7), approximately where the damping is nonlinear (friction), since the
EPMC's artificial damping then only balances the dissipation on average over the
period.

Which modes: those whose small-amplitude frequency (contacts stuck) lies within a factor
of 2 of the curve's band; which amplitudes: the modal amplitudes
``a = sqrt(Q1^H M Q1)`` the curve itself reaches, from ``AMPLITUDE_FLOOR`` times its
largest to ``AMPLITUDE_HEADROOM`` times it. H and N are the curve's own.
"""

from __future__ import annotations

import numpy as np

from drymount.hbm.modes import NonlinearModes, linear_modes, nonlinear_modes
from drymount.hbm.options import HBMOptions
from drymount.hbm.result import FrequencyResponse
from drymount.hbm.system import System

__all__ = ["AMPLITUDE_FLOOR", "AMPLITUDE_HEADROOM", "BAND_FACTOR", "backbones",
           "curve_modal_amplitudes"]

#: The backbone starts at this fraction of the curve's largest modal amplitude.
AMPLITUDE_FLOOR = 1e-3
#: ... and ends at this multiple of it.
AMPLITUDE_HEADROOM = 1.2
#: Modes whose small-amplitude frequency lies in [fmin / BAND_FACTOR,
#: fmax * BAND_FACTOR].
BAND_FACTOR = 2.0


def curve_modal_amplitudes(fr: FrequencyResponse, M: np.ndarray) -> np.ndarray:
    """``sqrt(Q1^T M Q1)`` (cosine and sine parts) of each curve point, kg^0.5 m."""
    c, s = fr.coefficients[:, :, 1], fr.coefficients[:, :, 2]
    quad = np.einsum("pi,ij,pj->p", c, M, c) + np.einsum("pi,ij,pj->p", s, M, s)
    return np.sqrt(quad)


def backbones(system: System, fr: FrequencyResponse, options: HBMOptions | None = None
              ) -> NonlinearModes:
    """The nonlinear modes of ``system`` near the band of ``fr``, over its amplitudes.

    Raises
    ------
    ValueError
        When no mode lies near the band, or the curve has no finite amplitude.
    """
    a = curve_modal_amplitudes(fr, system.M)
    a = a[np.isfinite(a) & (a > 0)]
    if a.size == 0:
        raise ValueError("--backbone: the curve has no finite amplitude to span")
    f = fr.freq_hz[np.isfinite(fr.freq_hz)]
    lo, hi = float(f.min()) / BAND_FACTOR, float(f.max()) * BAND_FACTOR
    chosen = [m.index for m in linear_modes(system)
              if lo <= m.omega / (2 * np.pi) <= hi]
    if not chosen:
        raise ValueError(f"--backbone: no mode of {system.name} has its "
                         f"small-amplitude frequency in {lo:.4g}..{hi:.4g} Hz")
    top = float(a.max())
    span = (AMPLITUDE_FLOOR * top, AMPLITUDE_HEADROOM * top)
    parts = [nonlinear_modes(system, k, span, harmonics=fr.harmonics,
                             n_samples=fr.n_samples or None,
                             closed_form=fr.closed_form, options=options)
             for k in chosen]
    out = parts[0]
    out.modes = [m for p in parts for m in p.modes]
    return out
