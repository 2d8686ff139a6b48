"""Curves in segments: clip a frequency response to its band, join restarted pieces.

:func:`hbm.frequency_response` restarts the continuation past a point where it stalls
(``HBMOptions.max_restarts``); the pieces are clipped to the band (a branch that turns
back can leave it) and joined into one :class:`hbm.result.FrequencyResponse`, one gap
row (NaN values at the restart frequency) between neighbours.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from drymount.hbm.continuation import Status
from drymount.hbm.result import FrequencyResponse

__all__ = ["Restart", "clip", "join"]

#: Relative tolerance of the band ends.
BAND_RTOL = 1e-9
#: Per-point fields of a FrequencyResponse and their value in a gap row.
_POINT_FIELDS = {"freq_hz": None, "coefficients": np.nan, "amplitude": np.nan,
                 "peak": np.nan, "transmissibility": np.nan, "stable": True,
                 "floquet_max_real": np.nan, "newton_per_point": 0,
                 "error_truncation": np.nan, "error_sampling": np.nan, "stuck": 0,
                 "samples_per_point": 0}


class Restart(NamedTuple):
    """Where a segment of a curve starts again (Hz) and why the one before stopped."""

    freq_hz: float
    reason: str


def _points(fr: FrequencyResponse, name: str) -> np.ndarray:
    value = np.asarray(getattr(fr, name))
    if name in ("floquet_max_real", "newton_per_point", "error_truncation",
                "error_sampling") and value.shape[:1] != fr.freq_hz.shape:
        # not computed: give one entry per point
        fill = 0 if name == "newton_per_point" else np.nan
        value = np.full(fr.freq_hz.shape, fill, dtype=value.dtype)
    if name == "samples_per_point" and value.shape[:1] != fr.freq_hz.shape:
        value = np.full(fr.freq_hz.shape, fr.n_samples, dtype=int)
    if name == "stuck" and value.shape[:1] != fr.freq_hz.shape:
        value = np.zeros((fr.freq_hz.size, len(fr.stuck_labels)), dtype=int)
    return value


def clip(fr: FrequencyResponse, fmin: float, fmax: float) -> FrequencyResponse:
    """The points of ``fr`` inside [fmin, fmax] Hz, turning points renumbered."""
    f = np.asarray(fr.freq_hz, dtype=float)
    keep = (f >= fmin * (1 - BAND_RTOL)) & (f <= fmax * (1 + BAND_RTOL))
    if np.all(keep):
        return fr
    new_index = np.cumsum(keep) - 1
    kept = [i for i, t in enumerate(fr.turning_points) if keep[t]]
    tps = np.array([new_index[fr.turning_points[i]] for i in kept], dtype=int)
    fold = np.asarray(fr.turning_freq_hz)
    fold = fold[kept] if fold.size == len(fr.turning_points) else fold
    return dataclasses.replace(
        fr, **{k: _points(fr, k)[keep] for k in _POINT_FIELDS},
        turning_points=tps, turning_freq_hz=fold,
        folds=_moved(fr.folds, keep, new_index),
        bifurcations=_moved(fr.bifurcations, keep, new_index),
        peaks=_moved(fr.peaks, keep, new_index))


def _moved(events, keep, new_index) -> list:
    """Located folds/peaks whose point was kept, renumbered."""
    out = []
    for e in events:
        i = min(e.index, len(keep) - 1)
        if keep[i]:
            out.append(dataclasses.replace(e, index=int(new_index[i])))
    return out


def _joined_events(parts, offsets) -> tuple[list, list]:
    """Folds of every segment (renumbered) and, per DOF, the highest peak."""
    folds, peaks = [], {}
    for fr, n in zip(parts, offsets, strict=True):
        folds += [dataclasses.replace(e, index=e.index + n) for e in fr.folds]
        for e in fr.peaks:
            j = fr.dof_names.index(e.dof)
            best = peaks.get(e.dof)
            if best is None or e.amplitude[j] > best.amplitude[j]:
                peaks[e.dof] = dataclasses.replace(e, index=e.index + n)
    return folds, list(peaks.values())


def _gap(fr: FrequencyResponse, f_gap: float) -> dict:
    """One gap row shaped like the points of ``fr``."""
    out = {}
    for k, fill in _POINT_FIELDS.items():
        like = _points(fr, k)
        out[k] = np.full((1,) + like.shape[1:], f_gap if fill is None else fill,
                         dtype=like.dtype)
    return out


def join(parts: list[FrequencyResponse], restarts: list[Restart], fmax: float
         ) -> FrequencyResponse:
    """Concatenate the segments ``parts`` (already clipped), one gap row between
    neighbours at the restart frequency. Success: the last segment reached ``fmax``."""
    if len(parts) == 1:
        return parts[0]
    cols = {k: [] for k in _POINT_FIELDS}
    tps, n, offsets = [], 0, []
    for i, fr in enumerate(parts):
        if i:
            for k, v in _gap(fr, restarts[i - 1].freq_hz).items():
                cols[k].append(v)
            n += 1
        offsets.append(n)
        for k in cols:
            cols[k].append(_points(fr, k))
        tps += [n + int(t) for t in fr.turning_points]
        n += len(fr.freq_hz)
    folds, peaks = _joined_events(parts, offsets)
    bifurcations = [dataclasses.replace(e, index=e.index + n)
                    for fr, n in zip(parts, offsets, strict=True)
                    for e in fr.bifurcations]
    last = parts[-1]
    reached = bool(len(last.freq_hz)) and \
        float(np.max(last.freq_hz)) >= fmax * (1 - BAND_RTOL)
    success = bool(last.success or reached)
    message = f"{len(parts)} segments; " + "; ".join(
        f"restarted at {r.freq_hz:.4g} Hz after: {r.reason}" for r in restarts)
    return dataclasses.replace(
        last, **{k: np.concatenate(v) for k, v in cols.items()},
        turning_points=np.array(tps, dtype=int),
        turning_freq_hz=np.concatenate([np.asarray(p.turning_freq_hz) for p in parts]),
        success=success, status=Status.DONE if success else last.status,
        message=message, n_newton=sum(p.n_newton for p in parts),
        n_steps=sum(p.n_steps for p in parts), restarts=tuple(restarts),
        folds=folds, peaks=peaks, bifurcations=bifurcations,
        turning_points_merged=sum(p.turning_points_merged for p in parts))
