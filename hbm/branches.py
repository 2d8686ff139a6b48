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

from drymount.hbm.postprocess import postprocess
from drymount.hbm.problem import build_problem, resolve_options
from drymount.hbm.continuation import Branch, Status, newton
from drymount.hbm.result import FrequencyResponse
from drymount.hbm.stability import is_stable
from drymount.hbm.system import System

__all__ = ["solutions_at", "solve_on_branch", "solve_from_phasors"]


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
    H, N, opts = resolve_options(options, curve.harmonics, curve.n_samples or None)
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
    H, N, opts = resolve_options(options, curve.harmonics, curve.n_samples or None)
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
            br.status = Status.NO_CONVERGENCE
            br.message = f"no HBM solution found at {fk:.6g} Hz"
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
        br.success, br.status = True, Status.DONE
        br.message = "solved at every frequency"
    return postprocess(prob, ys, opts, br, [])


def _shaped(value, name: str, shape: tuple, dtype=float):
    """``value`` as an array of ``shape`` (None stays None); a clear error if not."""
    if value is None:
        return None
    out = np.asarray(value, dtype=dtype)
    if out.shape != shape:
        raise ValueError(f"`{name}` must have shape {shape}, got {out.shape}")
    return out


def _start_coefficients(hb, phasor, static, coefficients) -> np.ndarray:
    """Newton's start (m, n): the fundamental from ``phasor`` (sine convention), the
    static term from ``static``, or all of ``coefficients`` (n_dof, 2K+1) truncated
    or zero-padded to H."""
    X = np.zeros((hb.m, hb.n))
    X[1] = phasor.imag  # cos1
    X[2] = phasor.real  # sin1
    if static is not None:
        X[0] = static
    if coefficients is not None:
        c = np.asarray(coefficients, dtype=float).T  # (2K+1, n_dof)
        r = min(c.shape[0], hb.m)
        X[:] = 0.0
        X[:r] = c[:r]
    return X


def solve_from_phasors(system: System, freqs_hz, phasors, *, harmonics: int = 7,
                       n_samples: int | None = None, closed_form: bool | None = None,
                       static=None, coefficients=None, sliders=None, options=None
                       ) -> FrequencyResponse:
    """Newton at each frequency started from a given fundamental (e.g. a co-simulated
    steady state), higher harmonics and static term starting at zero.

    Newton converges to an exact HBM solution near the start, so a steady state from a
    time simulation selects the branch it is on; the HBM solution is still computed
    from the harmonic-balance equations alone. Frequencies where Newton fails are
    left out (``success=False``, the message lists them); the others are returned in
    the given order.

    Parameters
    ----------
    freqs_hz : array_like, shape (n_freq,)
    phasors : array_like, complex, shape (n_freq, n_dof)
        ``q(t) ~ Im(phasor exp(i omega t))`` per DOF, m or rad.
    static : array_like, shape (n_freq, n_dof), optional
        Static term (mean over the period) to start from, m or rad. Needed to reach
        an asymmetric solution: Newton started in the symmetric subspace (static
        term and even harmonics zero) of a symmetric system stays there, even where
        the symmetric solution is unstable and the motion has broken the symmetry.
    coefficients : array_like, shape (n_freq, n_dof, 2K+1), optional
        Full start (layout ``[static, cos1, sin1, ...]``, e.g.
        ``vehicle.SweepResult.fourier``), truncated or zero-padded to H; overrides
        ``phasors`` and ``static``. The surest way onto the branch a time simulation
        is on when its motion is not symmetric (even harmonics).
    sliders : array_like, shape (n_freq, n_mounts, 3), optional
        Slider positions the AFT march starts from at each frequency, m, e.g. where
        the time simulation left them. A Jenkins element that never slips keeps any
        offset (PHYSICS.md section 1); with a nonlinear elastic law the offset moves
        the operating point and so the amplitude. Default: zero (HBM convention).
    """
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    P = _shaped(phasors, "phasors", (f.size, system.n_dof), complex)
    static = _shaped(static, "static", (f.size, system.n_dof))
    sliders = _shaped(sliders, "sliders", (f.size, len(system.elements), 3))
    H, N, opts = resolve_options(options, harmonics, n_samples)
    fmin, fmax = float(f.min()), float(max(f.max(), 1.001 * f.min()))
    settings = opts.continuation_settings()
    br = Branch()
    points, failed = [], []
    prob = build_problem(system, fmin, fmax, H, N, closed_form)
    for k, (fk, pk) in enumerate(zip(f, P, strict=True)):
        if sliders is not None:  # each point marches from its own slider state
            prob = build_problem(system, fmin, fmax, H, N, closed_form, sliders[k])
        hb = prob.hb
        X = _start_coefficients(hb, pk, None if static is None else static[k],
                                None if coefficients is None else coefficients[k])
        y, ok, its, _ = newton(prob, prob.y_of(X.ravel(), 2 * np.pi * fk), settings,
                               fixed=hb.size)
        br.n_newton += its
        br.n_steps += 1
        if ok:
            one = Branch(n_iter=[its], success=True)
            points.append(postprocess(prob, [y], opts, one, []))
        else:
            failed.append(fk)
    br.success = not failed
    br.status = Status.NO_CONVERGENCE if failed else Status.DONE
    br.message = ("Newton did not converge at " + ", ".join(f"{v:.6g}" for v in failed)
                  + " Hz") if failed else "solved at every frequency"
    if not points:
        return postprocess(prob, [], opts, br, [])
    first = points[0]

    def cat(name):
        return np.concatenate([getattr(p, name) for p in points])

    return FrequencyResponse(
        freq_hz=cat("freq_hz"), coefficients=cat("coefficients"),
        amplitude=cat("amplitude"), peak=cat("peak"),
        transmissibility=cat("transmissibility"), stable=cat("stable"),
        turning_points=np.zeros(0, dtype=int), success=br.success, status=br.status,
        message=br.message, n_newton=br.n_newton, n_steps=br.n_steps,
        dof_names=first.dof_names, harmonics=first.harmonics,
        n_samples=first.n_samples, closed_form=first.closed_form,
        floquet_max_real=cat("floquet_max_real"),
        newton_per_point=cat("newton_per_point"), system_name=first.system_name)
