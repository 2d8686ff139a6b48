"""Every harmonic-balance solution at a frequency, and the one a time simulation is on.

Where a response curve folds (hardening spring, thesis Sec. 3.1.4, Fig. 3.5/3.7)
several periodic solutions coexist at one frequency, two of them stable. Which one a
stepped-sine simulation or a test rig settles on depends on its history, not on the
frequency alone. :func:`solutions_at` finds all of them: each crossing of the
continuation curve (:func:`hbm.frequency_response`) with the frequency is refined by
Newton at exactly that frequency (thesis eq. 3.53) and checked for stability (Hill).
:func:`solve_on_branch` keeps, per frequency, the solution whose fundamental amplitude
of a chosen DOF is nearest a given amplitude (stable solutions first): the HBM
counterpart of a co-simulated steady state.
"""

from __future__ import annotations

import numpy as np

from hbm.analysis import _options, _postprocess, build_problem
from hbm.continuation import Branch, newton
from hbm.result import FrequencyResponse
from hbm.stability import is_stable
from hbm.system import System

__all__ = ["solutions_at", "solve_on_branch"]


def _crossings(curve: FrequencyResponse, freq_hz: float) -> list[tuple[int, float]]:
    """``(i, t)`` for each segment i..i+1 of the curve that contains ``freq_hz``
    (``t`` the linear interpolation weight)."""
    f = np.asarray(curve.freq_hz, dtype=float)
    out = []
    for i in range(len(f) - 1):
        lo, hi = min(f[i], f[i + 1]), max(f[i], f[i + 1])
        if lo <= freq_hz <= hi and hi > lo:
            out.append((i, (freq_hz - f[i]) / (f[i + 1] - f[i])))
    if not out and len(f):
        k = int(np.argmin(np.abs(f - freq_hz)))
        out.append((k, 0.0) if k < len(f) - 1 else (k - 1, 1.0))
    return out


def solutions_at(system: System, curve: FrequencyResponse, freq_hz: float, prob=None,
                 options=None) -> list[tuple[np.ndarray, bool, int]]:
    """All distinct HBM solutions at ``freq_hz`` found from the crossings of ``curve``.

    Returns a list of ``(y, stable, n_newton)`` in the scaled unknowns of ``prob``
    (built from ``system`` with the curve's harmonics if not given).
    """
    H, N, opts = _options(options, curve.harmonics, curve.n_samples or None)
    if prob is None:
        f = np.asarray(curve.freq_hz)
        prob = build_problem(system, float(min(f.min(), freq_hz)),
                             float(max(f.max(), freq_hz)), H, N, curve.closed_form)
    settings = opts.continuation_settings()
    hb = prob.hb
    n = hb.size
    omega = 2 * np.pi * freq_hz
    found: list[tuple[np.ndarray, bool, int]] = []
    for i, t in _crossings(curve, freq_hz):
        c = (1 - t) * curve.coefficients[i] + t * curve.coefficients[i + 1]
        y0 = prob.y_of(np.asarray(c).T.ravel(), omega)
        y, ok, its, _ = newton(prob, y0, settings, fixed=n)
        if not ok:
            continue
        if any(np.linalg.norm(y[:-1] - g[:-1]) <= 1e-6 * max(1.0, np.linalg.norm(g))
               for g, _, _ in found):
            continue
        X, w = prob.x_of(y)
        J = hb.residual(X, w)[1]
        try:
            stable, _ = is_stable(hb, J, w)
        except (np.linalg.LinAlgError, ValueError):
            stable = True
        found.append((y, bool(stable), its))
    return found


def solve_on_branch(system: System, freqs_hz, curve: FrequencyResponse,
                    near_amplitude, dof: int = 0, *, options=None) -> FrequencyResponse:
    """Per frequency, the HBM solution nearest ``near_amplitude`` (fundamental
    amplitude of DOF ``dof``), preferring stable solutions.

    Parameters
    ----------
    system : System
    freqs_hz : array_like, shape (n_freq,)
        Frequencies, Hz, inside the range of ``curve``.
    curve : FrequencyResponse
        A continuation curve of the same system (:func:`hbm.frequency_response`);
        its harmonics, samples and closed-form choice are reused.
    near_amplitude : array_like, shape (n_freq,)
        Amplitudes to match, e.g. co-simulated steady states (m or rad).
    dof : int
        DOF whose fundamental amplitude is matched.

    Returns
    -------
    FrequencyResponse
        One point per frequency (``success=False`` and the points so far if some
        frequency has no solution).
    """
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    target = np.atleast_1d(np.asarray(near_amplitude, dtype=float))
    if f.shape != target.shape:
        raise ValueError(f"`near_amplitude` must have the shape of `freqs_hz` "
                         f"{f.shape}, got {target.shape}")
    H, N, opts = _options(options, curve.harmonics, curve.n_samples or None)
    fc = np.asarray(curve.freq_hz)
    prob = build_problem(system, float(min(fc.min(), f.min())),
                         float(max(fc.max(), f.max())), H, N, curve.closed_form)
    hb = prob.hb
    br = Branch()
    ys = []
    for fk, ak in zip(f, target, strict=True):
        sols = solutions_at(system, curve, float(fk), prob=prob, options=opts)
        br.n_steps += 1
        if not sols:
            br.status, br.message = 1, f"no HBM solution found at {fk:.6g} Hz"
            break

        def amp(y):
            X, _ = prob.x_of(y)
            Xr = X.reshape(hb.m, hb.n)
            return float(np.hypot(Xr[1, dof], Xr[2, dof]))

        pool = [s for s in sols if s[1]] or sols
        y, _, its = min(pool, key=lambda s: abs(amp(s[0]) - ak))
        br.n_newton += sum(s[2] for s in sols)
        br.n_iter.append(its)
        ys.append(y)
    else:
        br.success, br.status, br.message = True, 0, "solved at every frequency"
    return _postprocess(prob, ys, opts, br, [])
