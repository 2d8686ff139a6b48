"""Vectorised periodic march of Jenkins (macro-slip) elements for the AFT.

:func:`hbm.elements.jenkins_periodic` marches the scalar return map
:func:`fmu_src.mount_law.jenkins_update` sample by sample in Python. This module gives
the same numbers (bit for bit; tested against it to 1e-12) with array operations over
the samples, the elements and any batch of motions (e.g. several frequency points):

- One step of the return map is a clamp of the slider position,
  ``w_n = min(max(w_{n-1}, u_n - eps), u_n + eps)`` with ``eps = Fs / kf``. A
  composition of clamps is again a clamp, ``clamp(clamp(x, a1, b1), a2, b2) =
  clamp(x, a', b')`` with ``a' = clamp(a1, a2, b2)``, ``b' = clamp(b1, a2, b2)``, so
  the slider positions of all samples follow from one associative prefix scan
  (Hillis-Steele, ``ceil(log2 N)`` array passes) and ``w_n = clamp(w_0, A_n, B_n)``.
  The scan only selects values (min/max), so every ``w_n`` is bitwise one of
  ``u_k -+ eps`` or ``w_0``.
- The scalar march decides slip by ``kf (u_n - w_{n-1}) > Fs`` rather than by
  ``w_{n-1} < u_n - eps``; both agree except within round-off of the slip threshold.
  Forces, flags and slip indices are therefore computed from the scanned ``w_{n-1}``
  with the scalar's own formulas, and a column where the resulting ``w_n`` differs from
  the scan (a tie within round-off; rare) is marched again by the scalar reference.
  Hence the result is that of the scalar march, sample for sample.
- The period convention is the scalar one (PHYSICS.md section 1): a column whose range
  exceeds ``2 eps`` slips at both extrema and is marched once, starting at its global
  maximum with ``w = u_max - eps`` (in the original sample order: the clamp at the
  maximum becomes the constant ``u_max - eps``, and the samples before it continue
  from the last one); any other column is marched twice from ``w_start`` and the
  second pass kept.

:func:`jenkins_jacobian` gives the analytic AFT Jacobian of the friction forces from the
stick flags and slip indices (a stuck sample depends on its last slip sample too).

Backends, all equal to the scalar march bit for bit:

- ``"scan"``: the array scan above (pure NumPy);
- ``"scalar"``: the scalar march per column (:func:`hbm.elements.jenkins_periodic`);
- ``"numpy"``: ``"scalar"`` below :data:`SCAN_FROM` samples x columns, where its few
  microseconds of fixed cost beat the scan's ~100 us (about 60 NumPy calls), else
  ``"scan"`` (measured crossover ~170-190 on the 2-core development machine,
  ``bench/bench_aft.py``);
- ``"numba"``: the scalar algorithm compiled (:mod:`hbm.friction_march_numba`; the
  optional ``fast`` extra), the fastest per call once loaded.

The default ``"auto"`` is ``"numpy"`` without numba; with numba it starts with
``"numpy"`` and switches to ``"numba"`` once the NumPy marches of the process have cost
what numba's start does (:mod:`hbm.march_choice`: a small curve never loads numba; a
cold cache is compiled in the background). The environment variable
``DRYMOUNT_MARCH`` overrides it (read at import).
"""

from __future__ import annotations

import importlib.util
import os
from dataclasses import dataclass

import numpy as np

from drymount.hbm.elements import jenkins_periodic
from drymount.hbm.march_choice import AutoMarch

__all__ = ["BACKENDS", "JenkinsMarch", "jenkins_march", "jenkins_jacobian",
           "jenkins_aft", "resolve_backend"]

#: Names of the march implementations ("c": the C kernels of :mod:`hbm.aft_native`).
BACKENDS = ("numpy", "numba", "scan", "scalar", "c")
#: Samples x columns from which the ``"numpy"`` backend scans instead of looping.
SCAN_FROM = 192
_HAVE_NUMBA = importlib.util.find_spec("numba") is not None


def resolve_backend(backend: str | None = None) -> str:
    """The backend to use: ``backend`` if given, else ``$DRYMOUNT_MARCH``, else auto.

    ``"auto"`` is ``"numpy"`` without numba; with numba it stays ``"auto"``, chosen per
    call by :data:`AUTO` (``"numpy"`` until ``"numba"`` pays).
    """
    name = backend if backend is not None else os.environ.get("DRYMOUNT_MARCH", "auto")
    if name == "auto":
        return "auto" if _HAVE_NUMBA else "numpy"
    if name not in BACKENDS:
        raise ValueError(f"march `backend` (or $DRYMOUNT_MARCH) must be one of "
                         f"auto, {', '.join(BACKENDS)}, got {name!r}")
    if name == "numba" and not _HAVE_NUMBA:
        raise ValueError("march backend 'numba' needs numba: pip install "
                         "'drymount[fast]' (or use 'numpy')")
    if name == "c" and not _c_loads():
        raise ValueError("march backend 'c' needs a C compiler ($CC, cc or gcc) to "
                         "build hbm/aft_native.c (or use 'numpy')")
    return name


def _c_loads() -> bool:
    """Whether the C kernels of :mod:`hbm.aft_native` load (built at first use)."""
    from drymount.hbm import aft_native

    return aft_native.library() is not None


_DEFAULT = resolve_backend()
#: The process's choice between the NumPy and the compiled march under "auto".
AUTO = AutoMarch(_HAVE_NUMBA)


#: The march left to ``auto`` (``$DRYMOUNT_MARCH`` unset or ``auto``) takes the C
#: kernels whenever they load: they give the compiled march's numbers without numba's
#: start (about 1 s CPU per process), so no size or time rule is needed (issue 27).
C_IN_AUTO = os.environ.get("DRYMOUNT_MARCH", "auto") == "auto"


def c_in_auto() -> bool:
    """Whether a march left to the default takes the C kernels (:data:`C_IN_AUTO`
    and they load)."""
    return C_IN_AUTO and _c_loads()


def _chosen(backend: str | None, size: int = 0) -> str:
    """The backend of a march of ``size`` samples x columns (x batch)."""
    if backend is None and c_in_auto():
        return "c"
    backend = _DEFAULT if backend is None else resolve_backend(backend)
    return AUTO.choose(size) if backend == "auto" else backend


def _compiled(backend: str):
    """The kernels' module of a compiled backend ("numba" or "c"), else None."""
    if backend == "c":
        from drymount.hbm import aft_native
        return aft_native
    if backend == "numba":
        import drymount.hbm.friction_march_numba as friction_march_numba
        return friction_march_numba
    return None


@dataclass(frozen=True)
class JenkinsMarch:
    """Periodic response of Jenkins elements to sampled periodic motions.

    Attributes
    ----------
    force : ndarray, shape (..., N, C)
        Friction force, N.
    stuck : ndarray of bool, shape (..., N, C)
        Whether the element sticks at each sample.
    last_slip : ndarray of int, shape (..., N, C)
        Index (within the period) of the last slip sample before or at each sample, -1
        if the element never slipped since the start (see
        :func:`hbm.elements.jenkins_periodic`).
    n_fallback : int
        Columns marched by the scalar reference because the scan met a slip decision
        within round-off of the threshold.
    """

    force: np.ndarray
    stuck: np.ndarray
    last_slip: np.ndarray
    n_fallback: int = 0
    backend: str = "numpy"


def _scan_clamps(S: np.ndarray) -> np.ndarray:
    """Prefix compositions of clamps along axis 2, in place of a copy.

    ``S[0, :, n]``, ``S[1, :, n]`` are the bounds ``lo_n <= hi_n`` of the clamp
    ``x -> min(max(x, lo_n), hi_n)``; returns ``T`` with
    ``F_n o ... o F_0 (x) = min(max(x, T[0, :, n]), T[1, :, n])``.
    """
    S2 = np.empty_like(S)
    n = S.shape[2]
    d = 1
    while d < n:
        # (later after earlier): both bounds of the earlier clamp go through the later
        new = S2[:, :, d:]
        np.maximum(S[:, :, :-d], S[:1, :, d:], out=new)
        np.minimum(new, S[1:, :, d:], out=new)
        S2[:, :, :d] = S[:, :, :d]
        S, S2 = S2, S
        d *= 2
    return S


def _decide(u, w, w_prev, kf, fs, eps):
    """The scalar return map's own decisions, given the scanned positions.

    ``w_prev[:, n]`` is the position before sample n, ``w[:, n]`` the scanned one
    after it. Returns ``(force, slip, consistent)``: the scalar's force and slip flag
    of each sample from ``w_prev`` and, per column, whether its map reproduces ``w``.
    """
    trial = kf * (u - w_prev)
    up = trial > fs
    down = trial < -fs
    w_map = np.where(up, u - eps, np.where(down, u + eps, w_prev))
    force = np.where(up, fs, np.where(down, -fs, trial))
    return force, up | down, (w_map == w).all(axis=1)


def _shift_in(w: np.ndarray, first: np.ndarray) -> np.ndarray:
    """``w`` delayed by one sample along axis 1, ``first`` before the first sample."""
    out = np.empty_like(w)
    out[:, 1:] = w[:, :-1]
    out[:, 0] = first
    return out


def _last_slip(slip: np.ndarray, before) -> np.ndarray:
    """Index of the last slip at or before each sample, ``before`` if none yet."""
    pos = np.where(slip, np.arange(slip.shape[1])[:, None], -1)
    np.maximum.accumulate(pos, axis=1, out=pos)
    return np.where(pos >= 0, pos, before)


def _march(u: np.ndarray, kf: np.ndarray, fs: np.ndarray, w_start: np.ndarray):
    """The periodic march of ``u`` (nb, N, C); see the module docstring.

    A column that slips at both extrema is marched once from its global maximum
    ``i_max`` with ``w = u_max - eps``: in the original sample order that is the clamp
    at ``i_max`` replaced by the constant ``u_max - eps`` (which makes every prefix
    from ``i_max`` on constant), and the samples before ``i_max`` continue from the
    last one. Any other column is marched twice from ``w_start``.
    """
    # C order: the flat writes below (``reshape(-1)[at_max]``) must land in the
    # arrays themselves, and ``u + ...`` and ``empty_like`` keep u's layout (the AFT's
    # ``u[..., fr]`` is not C-ordered; the writes went into copies and the march
    # differed from the scalar one where a column starts stuck at its maximum)
    u = np.ascontiguousarray(u)
    nb, N, C = u.shape
    eps = fs / kf
    # flat index of each column's first maximum (the scalar's max())
    at_max = (u.argmax(axis=1) * C
              + (np.arange(nb)[:, None] * (N * C) + np.arange(C))).ravel()
    u_max = u.max(axis=1)
    top = (u_max - eps).ravel()  # slider after slipping at the maximum
    slips = (u_max - u.min(axis=1) > 2.0 * eps).ravel()  # (nb C,)
    all_slip = slips.all()
    if not all_slip:
        at_max, top_s = at_max[slips], top[slips]
    else:
        top_s = top
    S = u + np.stack([-eps, eps])[:, None, None, :]  # clamp bounds (2, nb, N, C)
    S.reshape(2, -1)[:, at_max] = top_s
    S = _scan_clamps(S)
    A, B = S[0], S[1]
    ok = np.ones(nb * C, dtype=bool)
    w0 = A[:, -1, :]  # slipping columns: the last sample leads into the first
    if not all_slip:
        # first pass of the other columns from w_start
        w1 = np.minimum(np.maximum(w_start, A), B)
        _, slip1, ok1 = _decide(u, w1, _shift_in(w1, w_start), kf, fs, eps)
        ok &= ok1.ravel() | slips
        w0 = np.where(slips.reshape(nb, C), w0, w1[:, -1, :])
    w = np.minimum(np.maximum(w0[:, None, :], A), B)
    w_prev = _shift_in(w, w0)
    # the scalar starts at i_max from u_max - eps (not from the sample before)
    w_prev.reshape(-1)[at_max] = top_s
    force, slip, ok2 = _decide(u, w, w_prev, kf, fs, eps)
    ok &= ok2.ravel()
    mark = slip.copy()
    mark.reshape(-1)[at_max] = True  # the scalar's "last slip" starts at i_max
    if all_slip:
        last = _last_slip(mark, -1)
        last = np.where(last >= 0, last, last[:, -1:, :])
    else:
        last1 = _last_slip(slip1, -1)[:, -1:, :]
        last = _last_slip(mark, last1)
        wrap = (last < 0) & slips.reshape(nb, 1, C)
        last = np.where(wrap, last[:, -1:, :], last)
    stuck = ~slip
    bad = np.flatnonzero(~ok)
    for i in bad:
        b, k = divmod(int(i), C)
        force[b, :, k], stuck[b, :, k], last[b, :, k] = jenkins_periodic(
            u[b, :, k], float(kf[k]), float(fs[k]), float(w_start[k]))
    return force, stuck, last, len(bad)


def _march_scalar(u, kf, fs, w_start):
    """The scalar march of every column of ``u`` (nb, N, C)."""
    force = np.empty_like(u)
    stuck = np.empty(u.shape, dtype=bool)
    last = np.empty(u.shape, dtype=int)
    for b in range(u.shape[0]):
        for k in range(u.shape[2]):
            force[b, :, k], stuck[b, :, k], last[b, :, k] = jenkins_periodic(
                u[b, :, k], float(kf[k]), float(fs[k]), float(w_start[k]))
    return force, stuck, last, 0


def _march_numpy(u3, kf, fs, w_start, backend):
    """The march of a NumPy backend (``numpy``, ``scan`` or ``scalar``)."""
    if backend == "scalar" or (backend == "numpy" and u3.size < SCAN_FROM):
        return _march_scalar(u3, kf, fs, w_start)
    return _march(u3, kf, fs, w_start)


def jenkins_march(u, kf, fs, w_start=None, backend: str | None = None
                  ) -> JenkinsMarch:
    """Periodic response of Jenkins elements, equal to the scalar march.

    Parameters
    ----------
    u : array_like, shape (..., N, C)
        Deflection at N equidistant samples of one period for C elements (leading
        axes: any batch, e.g. frequency points), m.
    kf, fs : array_like, shape (C,)
        Contact stiffness (N/m, > 0) and slip force (N, >= 0) of each element.
    w_start : array_like, shape (C,), optional
        Slider position the first pass starts from, m (default 0); it only matters for
        an element that does not slip at both extrema.
    backend : str, optional
        One of :data:`BACKENDS` or ``"auto"``; default: ``$DRYMOUNT_MARCH`` or auto,
        resolved at import (:func:`resolve_backend`).

    Returns
    -------
    JenkinsMarch
    """
    u = np.asarray(u, dtype=float)
    backend = _chosen(backend, u.size)
    if u.ndim < 2:
        raise ValueError(f"`u` must have shape (..., N, C), got {u.shape}")
    shape = u.shape
    C = shape[-1]
    kf = np.asarray(kf, dtype=float).reshape(-1)
    fs = np.asarray(fs, dtype=float).reshape(-1)
    w_start = (np.zeros(C) if w_start is None
               else np.asarray(w_start, dtype=float).reshape(-1))
    if not (kf.shape == fs.shape == w_start.shape == (C,)):
        raise ValueError(f"`kf`, `fs` and `w_start` must have shape ({C},), got "
                         f"{kf.shape}, {fs.shape}, {w_start.shape}")
    if not ((kf > 0.0).all() and (fs >= 0.0).all()):
        raise ValueError(f"`kf` must be > 0 and `fs` >= 0, got kf={kf.tolist()}, "
                         f"fs={fs.tolist()}")
    u3 = u.reshape(-1, shape[-2], C)
    kernels = _compiled(backend)
    if kernels is not None:
        force, stuck, last = kernels.march(u3, kf, fs, w_start)
        n_bad = 0
    else:
        t0 = AUTO.clock()
        force, stuck, last, n_bad = _march_numpy(u3, kf, fs, w_start, backend)
        AUTO.spent(AUTO.clock() - t0)
    return JenkinsMarch(force.reshape(shape), stuck.reshape(shape),
                        last.reshape(shape), n_bad, backend)


def jenkins_jacobian(march: JenkinsMarch, kf, E: np.ndarray, P: np.ndarray
                     ) -> np.ndarray:
    """Analytic AFT Jacobian of the friction force coefficients.

    ``F = P f`` with ``f`` the march of ``u = E U``; at a stuck sample
    ``df_n = kf (du_n - du_{last_slip[n]})`` (``kf du_n`` if ``last_slip[n] == -1``),
    at a slipping one ``df_n = 0``.

    Parameters
    ----------
    march : JenkinsMarch
        Of ``u`` with shape (..., N, C).
    kf : array_like, shape (C,)
    E : ndarray, shape (N, m)
    P : ndarray, shape (m, N)

    Returns
    -------
    ndarray, shape (..., C, m, m)
        ``dF[..., c, h, g] = dF[h, c] / dU[g, c]``.
    """
    kf = np.asarray(kf, dtype=float)
    kernels = _compiled(march.backend)
    if kernels is not None:
        shape = march.stuck.shape
        s3 = march.stuck.reshape(-1, *shape[-2:])
        Z = kernels.jacobian_samples(
            E, kf, s3, march.last_slip.reshape(s3.shape))
        return (P @ Z).reshape(*shape[:-2], shape[-1], *P.shape[:1], E.shape[1])
    t0 = AUTO.clock()
    stuck = np.swapaxes(march.stuck, -1, -2)  # (..., C, N)
    last = np.swapaxes(march.last_slip, -1, -2)
    kt = stuck * kf[:, None]
    back = kt * (last >= 0)  # weight of the last slip sample's motion
    Z = kt[..., None] * E - back[..., None] * E[np.maximum(last, 0)]
    AUTO.spent(AUTO.clock() - t0)  # what the compiled samples would save
    return P @ Z


def jenkins_aft(u: np.ndarray, kf: np.ndarray, fs: np.ndarray, w_start: np.ndarray,
                E: np.ndarray, P: np.ndarray, jacobian: bool = True,
                backend: str | None = None):
    """Friction forces at the samples and their coefficient Jacobian, for the AFT.

    The lean path of :func:`hbm.aft.aft_forces`: the arguments are taken as checked
    (``kf``, ``fs``, ``w_start`` float arrays of shape (C,) with ``kf > 0``,
    ``fs >= 0``); with numba the march and the Jacobian samples are one compiled call.

    Parameters
    ----------
    u : ndarray, shape (..., N, C)
    kf, fs, w_start : ndarray, shape (C,)
    E : ndarray, shape (N, m)
    P : ndarray, shape (m, N)
    jacobian : bool
    backend : str, optional

    Returns
    -------
    force : ndarray, shape (..., N, C)
    dF : ndarray, shape (..., C, m, m) or None
        As :func:`jenkins_jacobian`.
    """
    backend = _chosen(backend, u.size)
    shape = u.shape
    u3 = u.reshape(-1, *shape[-2:])
    kernels = _compiled(backend)
    if kernels is not None:
        if not jacobian:
            return kernels.march(u3, kf, fs, w_start)[0].reshape(shape), None
        force, Z = kernels.march_and_samples(u3, kf, fs, w_start, E)
        dF = P @ Z
        return force.reshape(shape), dF.reshape(*shape[:-2], *dF.shape[-3:])
    t0 = AUTO.clock()
    force, stuck, last, n_bad = _march_numpy(u3, kf, fs, w_start, backend)
    AUTO.spent(AUTO.clock() - t0)
    march = JenkinsMarch(force.reshape(shape), stuck.reshape(shape),
                         last.reshape(shape), n_bad, backend)
    return march.force, (jenkins_jacobian(march, kf, E, P) if jacobian else None)
