"""Co-simulated check of the best designs of an exploration (``--cosim-check K``).

The exploration ranks designs on HBM curves with few harmonics (often H = 1). For the
K best feasible designs by the first objective, a stepped-sine sweep co-simulates the
design in the time domain (:func:`vehicle.sweep`, in-process mount law, the same law as
the FMU) at :data:`CHECK_POINTS` frequencies over that objective's band, and each
steady-state fundamental amplitude is compared with the HBM solution of the same
branch at the design's H (:func:`drymount.validation.hbm_matching`). The error is
relative to each DOF's largest HBM amplitude, on stable HBM points and DOFs with a
response (as ``drymount validate`` does). Written to ``cosim_check.csv`` and the
summary.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from drymount.design.space import DesignSpace, apply_values

__all__ = ["CheckResult", "cosim_check", "CHECK_POINTS"]

#: Frequencies of each checking sweep.
CHECK_POINTS = 12


@dataclass(frozen=True)
class CheckResult:
    """One checked design.

    Attributes
    ----------
    index : int
        Design number.
    objective : float
        Its first objective (HBM).
    max_error : float
        Largest |co-simulated - HBM| fundamental amplitude over the compared points,
        relative to the DOF's HBM peak (NaN when nothing could be compared).
    worst : str
        ``"<dof> at <f> Hz"`` of that error.
    converged : bool
        Every sweep frequency reached a steady state.
    seconds : float
    message : str
    """

    index: int
    objective: float
    max_error: float
    worst: str
    converged: bool
    seconds: float
    message: str = ""


def _best(space: DesignSpace, results, k: int) -> list:
    sign = -1.0 if space.objectives[0].sense == "max" else 1.0
    ok = [r for r in results if r.feasible and math.isfinite(r.objectives[0])]
    return sorted(ok, key=lambda r: sign * r.objectives[0])[:k]


def _check_one(cfg, space: DesignSpace, r) -> CheckResult:
    import drymount.vehicle as vehicle
    from drymount.config import config_from_dict
    from drymount.validation import compared_dofs, hbm_matching

    t0 = time.perf_counter()
    system = config_from_dict(apply_values(cfg.data, space.variables, r.values),
                              source=cfg.source, name=cfg.name).system
    freqs = np.linspace(*space.objectives[0].band_hz, CHECK_POINTS)
    sw = vehicle.sweep(system, freqs, direction="up", backend="inproc", workers=1,
                       progress=False)
    a_h, stable, msg = hbm_matching(system, freqs, sw, space.harmonics)
    a_co = np.asarray(sw.amplitude)
    peak = np.nanmax(a_h, axis=0)
    best, worst = math.nan, ""
    for i in compared_dofs(system, a_h):
        for k in np.flatnonzero(stable & np.isfinite(a_h[:, i])):
            err = abs(a_co[k, i] - a_h[k, i]) / peak[i]
            if math.isnan(best) or err > best:
                best, worst = float(err), f"{system.dof_names[i]} at {freqs[k]:.3g} Hz"
    return CheckResult(r.index, r.objectives[0], best, worst,
                       bool(np.all(sw.converged)), time.perf_counter() - t0, msg)


def cosim_check(cfg, space: DesignSpace, results, k: int, progress: bool = True
                ) -> list[CheckResult]:
    """Co-simulate the ``k`` best feasible designs (see the module docstring)."""
    import sys

    from tqdm import tqdm

    picks = _best(space, results, k)
    return [_check_one(cfg, space, r) for r in tqdm(
        picks, desc="co-simulated check", unit="design", disable=not progress,
        file=sys.stderr)]
