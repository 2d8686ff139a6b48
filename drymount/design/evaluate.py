"""One design -> one HBM curve -> its objectives and constraint margins.

:func:`evaluate_design` sets the variables on the configuration's document, checks and
builds it like a file (:func:`drymount.config.config_from_dict`), computes one
frequency response (:func:`hbm.frequency_response`) over the design band and reduces it
to the objectives and constraints of the :class:`~drymount.design.space.DesignSpace`.
:func:`evaluate_chunk` does that for a list of designs; it is what local processes and
Dask workers run, so it only takes picklable arguments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from drymount.design.space import BoxConstraint, DesignSpace, Measure, Metric, Quantity

__all__ = ["DesignStatus", "DesignResult", "Task", "evaluate_design", "evaluate_chunk",
           "metric_value", "band_rms", "RMS_GRID_POINTS"]

#: Frequencies of the uniform grid the RMS measure integrates on (per band).
RMS_GRID_POINTS = 401


class DesignStatus(str, Enum):
    """What happened to a design."""
    OK = "ok"               # curve complete; objectives and margins valid
    FAILED = "failed"       # the continuation stopped; values from the partial curve
    INVALID = "invalid"     # the configuration rejects these values (message says why)


@dataclass(frozen=True)
class DesignResult:
    """One evaluated design (one table row).

    Attributes
    ----------
    index : int
        Design number in the sample (0-based); the table is ordered by it.
    values : tuple of float
        Variable values, in the order of ``DesignSpace.variables``.
    objectives, margins : tuple of float
        Objective values and constraint margins (>= 0 satisfied), NaN if unknown.
    status : DesignStatus
    message : str
        Why a design failed or is invalid ("" when OK).
    n_points : int
        Points of its HBM curve.
    """

    index: int
    values: tuple
    objectives: tuple
    margins: tuple
    status: DesignStatus
    message: str = ""
    n_points: int = 0

    @property
    def feasible(self) -> bool:
        """OK and every margin >= 0."""
        return self.status is DesignStatus.OK and all(m >= 0 for m in self.margins)


@dataclass(frozen=True)
class Task:
    """A chunk of designs for one worker: the base document, the space, and
    ``(index, values)`` pairs."""

    doc: dict
    source: str
    name: str
    space: DesignSpace
    designs: tuple


def band_rms(freq_hz, values, band) -> float:
    """RMS of a curve over ``band`` (Hz), equal weight per Hz.

    The curve (points in continuation order, possibly folding back) is interpolated
    linearly along each segment onto :data:`RMS_GRID_POINTS` uniform frequencies; where
    it holds several solutions at a frequency the largest is taken (the upper envelope:
    the response a slow sweep may meet). NaN when the curve does not cover the band.
    """
    f = np.asarray(freq_hz, dtype=float)
    v = np.asarray(values, dtype=float)
    grid = np.linspace(band[0], band[1], RMS_GRID_POINTS)
    env = np.full(grid.size, -np.inf)
    if f.size < 2:
        return math.nan
    f0, f1, v0, v1 = f[:-1], f[1:], v[:-1], v[1:]
    lo, hi = np.minimum(f0, f1), np.maximum(f0, f1)
    tol = 1e-9 * band[1]
    for k in np.flatnonzero((hi >= band[0] - tol) & (lo <= band[1] + tol)):
        m = (grid >= lo[k] - tol) & (grid <= hi[k] + tol)
        if not m.any():
            continue
        if hi[k] - lo[k] > 0:
            w = np.clip((grid[m] - f0[k]) / (f1[k] - f0[k]), 0.0, 1.0)
            y = v0[k] + w * (v1[k] - v0[k])
        else:
            y = np.full(m.sum(), max(v0[k], v1[k]))
        env[m] = np.maximum(env[m], y)
    if not np.all(np.isfinite(env)):
        return math.nan
    return float(math.sqrt(np.trapezoid(env**2, grid) / (band[1] - band[0])))


def _series(metric: Metric, fr, system) -> np.ndarray:
    if metric.quantity is Quantity.DISPLACEMENT:
        return np.asarray(fr.peak, dtype=float)[:, fr.dof_names.index(metric.dof)]
    t = np.asarray(fr.transmissibility, dtype=float)
    if metric.quantity is Quantity.FORCE:
        den = [system.excitation.scalar_amplitude(2 * np.pi * f) for f in fr.freq_hz]
        return t * np.asarray(den, dtype=float)
    return t


def metric_value(metric: Metric, fr, system) -> float:
    """The value of ``metric`` on a frequency response ``fr`` of ``system``."""
    f = np.asarray(fr.freq_hz, dtype=float)
    y = _series(metric, fr, system)
    if metric.measure is Measure.RMS:
        return band_rms(f, y, metric.band_hz)
    tol = 1e-9 * metric.band_hz[1]
    m = (f >= metric.band_hz[0] - tol) & (f <= metric.band_hz[1] + tol) & np.isfinite(y)
    return float(np.max(y[m])) if m.any() else math.nan


def _box_margin(c: BoxConstraint, doc: dict) -> float:
    from drymount.paths import expand, get_value

    worst = math.inf
    for parts in expand(doc, c.path):
        p = np.asarray(get_value(doc, parts), dtype=float)
        d = np.minimum(p - np.asarray(c.lower), np.asarray(c.upper) - p)
        worst = min(worst, float(d.min()))
    return worst


def evaluate_design(doc: dict, space: DesignSpace, index: int, values, *,
                    source: str = "<design>", name: str = "design") -> DesignResult:
    """Evaluate design ``index`` with variable ``values`` (see module docstring).

    Never raises for a bad design: an invalid configuration gives status INVALID with
    the configuration's problems, a continuation that stopped gives FAILED with the
    values of the partial curve and its message.
    """
    import drymount.hbm as hbm
    from drymount.config import ConfigError, config_from_dict
    from drymount.design.space import apply_values
    from drymount.paths import PathError

    values = tuple(float(x) for x in values)
    nan_o = (math.nan,) * len(space.objectives)
    nan_c = (math.nan,) * len(space.constraints)
    try:
        new = apply_values(doc, space.variables, values)
        cfg = config_from_dict(new, source=source, name=name)
    except (ConfigError, PathError) as exc:
        msg = "; ".join(exc.problems) if isinstance(exc, ConfigError) else str(exc)
        return DesignResult(index, values, nan_o, nan_c, DesignStatus.INVALID, msg)
    try:
        fr = hbm.frequency_response(cfg.system, *space.band_hz,
                                    harmonics=space.harmonics)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return DesignResult(index, values, nan_o, nan_c, DesignStatus.FAILED,
                            f"harmonic balance raised {type(exc).__name__}: {exc}")
    objectives = tuple(metric_value(o, fr, cfg.system) for o in space.objectives)
    margins = tuple(_box_margin(c, new) if isinstance(c, BoxConstraint)
                    else c.limit - metric_value(c, fr, cfg.system)
                    for c in space.constraints)
    status = DesignStatus.OK if fr.success else DesignStatus.FAILED
    return DesignResult(index, values, objectives, margins, status,
                        "" if fr.success else fr.message, len(fr.freq_hz))


def evaluate_chunk(task: Task) -> list[DesignResult]:
    """Evaluate every design of ``task`` in order (what a worker runs)."""
    return [evaluate_design(task.doc, task.space, i, x, source=task.source,
                            name=task.name) for i, x in task.designs]
