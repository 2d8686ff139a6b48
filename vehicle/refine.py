"""Where a stepped sweep needs extra frequencies: at the peak, where the response
changes fastest, or at the peak and folds of a harmonic-balance curve.

A sweep on a fixed grid reads a resonance peak low by up to the curvature of the peak
times the square of half the grid step (quarter_car_halved, 30 points over 0.5-30 Hz:
12 % low). :func:`refine_targets` picks frequencies to add from what the sweep has
computed so far; :func:`vehicle.sweep.sweep` (``refine=n``) runs them and repeats
until ``n`` points were added:

- **peak**: the vertex of the parabola through the largest transmissibility and its
  two neighbours, and the midpoint of the wider of the two intervals next to it (the
  bracket around the maximum shrinks every round, the vertex converges fast on a
  smooth peak);
- **fastest change**: the midpoint of the interval with the largest change of
  log(transmissibility) between its ends, not yet bisected down to ``min_step``;
- **HBM curve** (``hbm_targets``): the frequency of the HBM's largest
  transmissibility and of its folds (turning points of the continuation, where the
  frequency reverses), inside the band; these come first.

Frequencies closer than ``min_step`` to one already computed are not added.
"""

from __future__ import annotations

import numpy as np

__all__ = ["refine_targets", "hbm_targets", "MIN_STEP_FRACTION", "PER_ROUND"]

#: Smallest spacing refinement creates, as a fraction of the band.
MIN_STEP_FRACTION = 1e-4
#: Frequencies added per refinement round at most (two at the peak, one elsewhere).
PER_ROUND = 3


def hbm_targets(freq_hz, transmissibility, fmin: float, fmax: float) -> list[float]:
    """Frequencies (Hz) of an HBM curve's largest transmissibility and of its folds
    (where the continuation's frequency turns back), inside ``[fmin, fmax]``.

    ``freq_hz``, ``transmissibility``: the curve in continuation order."""
    f = np.asarray(freq_hz, dtype=float).reshape(-1)
    tr = np.asarray(transmissibility, dtype=float).reshape(-1)
    if f.shape != tr.shape or f.size == 0:
        raise ValueError(f"the HBM curve needs as many transmissibilities as "
                         f"frequencies (>= 1), got {tr.size} and {f.size}")
    ok = np.isfinite(f) & np.isfinite(tr)
    out = []
    if ok.any():
        out.append(float(f[ok][np.argmax(tr[ok])]))
    df = np.diff(f)
    turns = np.nonzero(df[:-1] * df[1:] < 0)[0] + 1
    out += [float(f[i]) for i in turns if ok[i]]
    return [x for x in out if fmin <= x <= fmax]


def refine_targets(freq_hz, transmissibility, count: int, *, min_step: float,
                   first=()) -> list[float]:
    """Up to ``count`` new frequencies (Hz) for a sweep that has computed the
    transmissibility ``transmissibility`` at ``freq_hz`` (any order).

    ``first``: frequencies to add before the automatic ones (HBM peak and folds).
    None is closer than ``min_step`` to a computed frequency or to another new one.
    """
    f = np.asarray(freq_hz, dtype=float).reshape(-1)
    tr = np.asarray(transmissibility, dtype=float).reshape(-1)
    order = np.argsort(f)
    f, tr = f[order], tr[order]
    out: list[float] = []

    def add(x: float) -> None:
        if len(out) < count and all(abs(x - y) >= min_step
                                    for y in (*f.tolist(), *out)):
            out.append(float(x))

    for x in first:
        add(x)
    ok = np.isfinite(tr) & (tr > 0)
    if ok.sum() < 2:
        return out
    f, tr = f[ok], tr[ok]
    i = int(np.argmax(tr))
    if 0 < i < f.size - 1:
        add(_vertex(f[i - 1:i + 2], tr[i - 1:i + 2]))
        j = i - 1 if f[i] - f[i - 1] >= f[i + 1] - f[i] else i
        add(0.5 * (f[j] + f[j + 1]))  # bisect the wider side of the bracket
    else:
        j = min(i, f.size - 2)
        add(0.5 * (f[j] + f[j + 1]))
    change = np.abs(np.diff(np.log(tr)))
    change[np.diff(f) < 2 * min_step] = -1.0
    for j in np.argsort(change)[::-1]:
        if len(out) >= count or change[j] < 0:
            break
        add(0.5 * (f[j] + f[j + 1]))
    return out


def _vertex(f: np.ndarray, y: np.ndarray) -> float:
    """Abscissa of the vertex of the parabola through three points with the middle
    one the largest, clipped into (f[0], f[2]); the midpoint if degenerate."""
    d1, d2 = f[1] - f[0], f[2] - f[1]
    s1, s2 = (y[1] - y[0]) / d1, (y[2] - y[1]) / d2
    curv = (s2 - s1) / (f[2] - f[0])  # half the second derivative
    if not (np.isfinite(curv) and curv < 0):
        return float(0.5 * (f[0] + f[2]))
    x = 0.5 * (f[0] + f[1]) - s1 / (2.0 * curv)
    return float(min(max(x, f[0]), f[2]))
