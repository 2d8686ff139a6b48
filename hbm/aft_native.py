"""The compiled harmonic-form AFT's kernels in C (``hbm/aft_native.c``), through ctypes.

:func:`aft_samples` and :func:`slip_memory` are those of
:mod:`hbm.friction_march_numba` (the same operations in the same order, so the same
numbers bit for bit: tests/test_hbm_aft_native.py), without numba's start: loading
the library costs about a millisecond, where numba's import and the load of its cached
kernels cost about 1 s CPU per process (issue 27). :func:`hbm.aft._aft_harmonic`
uses them under the ``auto`` march whenever the library is there.

The library is compiled at first use with the system C compiler (about 0.3 s, once)
into the native cache (:func:`hbm.c_build.shared_library`), keyed by the source, the
flags and the compiler (its path and modification time: no ``--version`` subprocess
per process).
Without a compiler, or with ``$DRYMOUNT_NATIVE_AFT`` set to ``0``, :func:`library`
is None and the AFT takes the numba or the NumPy path as before.
"""

from __future__ import annotations

import ctypes
import functools
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from drymount.hbm.c_build import compiler, shared_library

__all__ = ["library", "aft_samples", "slip_memory", "bound", "Bound", "march",
           "jacobian_samples", "march_and_samples", "SOURCE"]

SOURCE = Path(__file__).with_name("aft_native.c")
FLAGS = ("-std=c11", "-O3", "-ffp-contract=off", "-fno-fast-math", "-shared", "-fPIC")
_i64, _vp = ctypes.c_int64, ctypes.c_void_p


def _identity(cc: list[str]) -> str:
    """The compiler's path and modification time (a ``--version`` subprocess would
    cost more than the library's load, in every process)."""
    exe = shutil.which(cc[0]) or cc[0]
    try:
        return f"{os.path.realpath(exe)} {os.stat(exe).st_mtime_ns}"
    except OSError:
        return exe


@functools.cache
def library():
    """The loaded library (argument types set), or None (no compiler, the build
    failed, or ``$DRYMOUNT_NATIVE_AFT=0``)."""
    if os.environ.get("DRYMOUNT_NATIVE_AFT", "1") == "0":
        return None
    cc = compiler()
    if cc is None:
        return None
    try:
        lib = ctypes.CDLL(str(shared_library(SOURCE, "aft", FLAGS, cc, _identity(cc))))
    except (OSError, subprocess.SubprocessError):
        return None
    lib.dm_aft_samples.restype = None
    lib.dm_aft_samples.argtypes = [_i64, _i64, _i64, _vp, _vp, _vp, _vp, _vp, _i64,
                                   _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp,
                                   _vp, _vp]
    lib.dm_march.restype = None
    lib.dm_march.argtypes = [_i64, _i64, _i64] + [_vp] * 11
    lib.dm_samples.restype = None
    lib.dm_samples.argtypes = [_i64, _i64, _i64, _i64] + [_vp] * 5
    lib.dm_slip_memory.restype = None
    lib.dm_slip_memory.argtypes = [_i64, _i64, _i64, _i64, _i64, _vp, _vp, _vp, _vp,
                                   _vp, _vp, _vp]
    return lib


def _ptr(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


def _checked(a: np.ndarray, dtype) -> np.ndarray:
    """``a`` as a C-ordered array of ``dtype`` (no copy when it is one already)."""
    return np.ascontiguousarray(a, dtype=dtype)


class Bound:
    """The kernels bound to one plan of :func:`hbm.aft._plan` and one
    :class:`hbm.aft.FourierBasis`, for batches of ``nb`` motions: the addresses of
    the parameters and of kept input and output buffers taken once (the AFT's
    per-call Python: an address costs 1-4 us, the checks and allocations of
    :func:`aft_samples` more than the kernels at H = 7, N = 1024). The arrays a call
    returns are overwritten by the next call (but ``force``)."""

    def __init__(self, plan, basis, nb: int, n_ax: int):
        self.lib = library()
        N, m = basis.E.shape
        C = plan.friction_i8.size
        self.keep = (plan, basis)   # the addresses below stay valid
        self.shape = (nb, N, n_ax)
        self.u = np.empty(self.shape)
        self._dense = None
        self._E = _ptr(basis.E)
        self.f, self.kt = np.empty(self.shape), np.empty(self.shape)
        self.stuck = np.empty((nb, N, C), dtype=np.bool_)
        self.last = np.empty((nb, N, C), dtype=np.int64)
        self.scratch = (np.empty(N), np.empty(N, dtype=np.bool_),
                        np.empty(N, dtype=np.int64), np.empty(N))
        # without compiled laws (plan.codes None) only march_samples is usable
        codes = plan.codes or (np.zeros(n_ax, np.int64),) + (np.zeros(n_ax),) * 3
        params = (*codes, plan.friction_i8, plan.kf, plan.fs, plan.w_start)
        for p in params:
            assert p.flags.c_contiguous and p.dtype in (np.float64, np.int64)
        assert codes[0].size == n_ax and plan.kf.size == C
        self._params = params
        code, p1, p2, p3, fr, kf, fs, w0 = (_ptr(p) for p in params)
        out = (_ptr(self.f), _ptr(self.kt), _ptr(self.stuck), _ptr(self.last),
               *(_ptr(a) for a in self.scratch))
        self._samples = (nb, N, n_ax, _ptr(self.u), code, p1, p2, p3, C, fr, kf, fs,
                         w0, *out)
        cum = basis.cumulative_projection()
        self._slip = (nb, N, C, n_ax, m, _ptr(self.stuck), _ptr(self.last), fr, kf,
                      _ptr(cum), _ptr(basis.E))

    def samples(self, U: np.ndarray, E: np.ndarray):
        """``(f, kt, stuck, last)`` of the motion ``u = E U`` (U: (..., m, n_ax),
        nb motions; ``u`` computed into the kept buffer by the same product)."""
        np.matmul(E, U, out=self.u.reshape(*U.shape[:-2], *self.shape[1:]))
        self.lib.dm_aft_samples(*self._samples)
        return self.f, self.kt, self.stuck, self.last

    def march_samples(self, u_fr: np.ndarray):
        """``(force, Z)`` of :func:`march_and_samples` for the friction columns'
        motion ``u_fr`` (nb, N, C) (copied into a kept buffer; ``force`` a copy)."""
        if self._dense is None:
            nb, N, _ = self.shape
            C, m = self._slip[2], self._slip[4]
            buf = (np.empty((nb, N, C)), np.empty((nb, N, C)),
                   np.empty((nb, N, C), dtype=np.bool_),
                   np.empty((nb, N, C), dtype=np.int64), np.empty((nb, C, N, m)),
                   np.empty(N), np.empty(N), np.empty(N, dtype=np.bool_),
                   np.empty(N, dtype=np.int64))
            u, force, stuck, last, Z = buf[:5]
            kf, fs, w0 = self._samples[10:13]
            self._dense = (buf, (nb, N, C, _ptr(u), kf, fs, w0, _ptr(force),
                                 _ptr(stuck), _ptr(last), *(_ptr(a) for a in buf[5:])),
                           (nb, N, C, m, self._E, kf, _ptr(stuck), _ptr(last), _ptr(Z)))
        buf, a_march, a_samples = self._dense
        np.copyto(buf[0], u_fr)
        self.lib.dm_march(*a_march)
        self.lib.dm_samples(*a_samples)
        return buf[1].copy(), buf[4]

    def slip_memory(self, dF: np.ndarray) -> None:
        """Subtract the slip memory of the last :meth:`samples` from ``dF`` (nb,
        n_ax, m, m), in place."""
        nb, N, C, n_ax, m = self._slip[:5]
        if dF.shape != (nb, n_ax, m, m) or not dF.flags.c_contiguous:
            raise ValueError(f"dF of shape {dF.shape} (C-ordered {(nb, n_ax, m, m)} "
                             f"expected)")
        a = self._slip
        self.lib.dm_slip_memory(*a[:5], _ptr(dF), *a[5:])


def bound(plan, basis, nb: int, n_ax: int) -> Bound:
    """The :class:`Bound` kernels of ``plan`` and ``basis`` for ``nb`` motions of
    ``n_ax`` axes (kept on ``basis``)."""
    cache = basis.__dict__.setdefault("_native", {})
    key = (id(plan), nb, n_ax)
    got = cache.get(key)
    if got is None:
        got = cache[key] = Bound(plan, basis, nb, n_ax)
    return got


def aft_samples(u: np.ndarray, code: np.ndarray, p1: np.ndarray, p2: np.ndarray,
                p3: np.ndarray, fr: np.ndarray, kf: np.ndarray, fs: np.ndarray,
                w_start: np.ndarray):
    """:func:`hbm.friction_march_numba.aft_samples` in C: ``(f, kt, stuck, last)``
    of the samples ``u`` (nb, N, n_ax)."""
    lib = library()
    u = _checked(u, np.float64)
    nb, N, n_ax = u.shape
    code, fr = _checked(code, np.int64), _checked(fr, np.int64)
    p1, p2, p3 = (_checked(p, np.float64) for p in (p1, p2, p3))
    kf, fs, w_start = (_checked(p, np.float64) for p in (kf, fs, w_start))
    if not (code.size == p1.size == p2.size == p3.size == n_ax
            and fr.size == kf.size == fs.size == w_start.size) or (
            fr.size and not (0 <= fr.min() and fr.max() < n_ax)):
        raise ValueError(f"aft_samples: parameters do not fit {n_ax} axes and "
                         f"{fr.size} friction axes")
    C = fr.size
    f = np.empty_like(u)
    kt = np.empty_like(u)
    stuck = np.empty((nb, N, C), dtype=np.bool_)
    last = np.empty((nb, N, C), dtype=np.int64)
    force, col = np.empty(N), np.empty(N)
    cstuck, clast = np.empty(N, dtype=np.bool_), np.empty(N, dtype=np.int64)
    lib.dm_aft_samples(nb, N, n_ax, _ptr(u), _ptr(code), _ptr(p1), _ptr(p2),
                       _ptr(p3), C, _ptr(fr), _ptr(kf), _ptr(fs), _ptr(w_start),
                       _ptr(f), _ptr(kt), _ptr(stuck), _ptr(last), _ptr(force),
                       _ptr(cstuck), _ptr(clast), _ptr(col))
    return f, kt, stuck, last


def slip_memory(dF: np.ndarray, stuck: np.ndarray, last: np.ndarray, fr: np.ndarray,
                kf: np.ndarray, cum: np.ndarray, E: np.ndarray) -> None:
    """:func:`hbm.friction_march_numba.slip_memory` in C: subtract in place the
    Jenkins slip memory from ``dF`` (nb, n_ax, m, m), C-ordered."""
    lib = library()
    nb, N, C = stuck.shape
    m = E.shape[1]
    if not (dF.flags.c_contiguous and dF.dtype == np.float64 and dF.ndim == 4
            and dF.shape[0] == nb and dF.shape[2:] == (m, m)
            and cum.shape == (N + 1, m) and E.shape[0] == N
            and last.shape == stuck.shape and len(fr) == C == len(kf)):
        raise ValueError("slip_memory: arrays of inconsistent shapes or a dF that is "
                         "not C-ordered float64")
    stuck, last = _checked(stuck, np.bool_), _checked(last, np.int64)
    fr, kf = _checked(fr, np.int64), _checked(kf, np.float64)
    cum, E = _checked(cum, np.float64), _checked(E, np.float64)
    lib.dm_slip_memory(nb, N, C, dF.shape[1], m, _ptr(dF), _ptr(stuck), _ptr(last),
                       _ptr(fr), _ptr(kf), _ptr(cum), _ptr(E))


def march(u: np.ndarray, kf: np.ndarray, fs: np.ndarray, w_start: np.ndarray):
    """:func:`hbm.friction_march_numba.march` in C: ``(force, stuck, last_slip)`` of
    the periodic march of ``u`` (nb, N, C)."""
    lib = library()
    u = _checked(u, np.float64)
    nb, N, C = u.shape
    kf, fs, w_start = (_checked(p, np.float64) for p in (kf, fs, w_start))
    if not kf.size == fs.size == w_start.size == C:
        raise ValueError(f"march: parameters do not fit {C} columns")
    force = np.empty_like(u)
    stuck = np.empty(u.shape, dtype=np.bool_)
    last = np.empty(u.shape, dtype=np.int64)
    scratch = (np.empty(N), np.empty(N), np.empty(N, dtype=np.bool_),
               np.empty(N, dtype=np.int64))
    lib.dm_march(nb, N, C, _ptr(u), _ptr(kf), _ptr(fs), _ptr(w_start), _ptr(force),
                 _ptr(stuck), _ptr(last), *(_ptr(a) for a in scratch))
    return force, stuck, last


def jacobian_samples(E: np.ndarray, kf: np.ndarray, stuck: np.ndarray,
                     last: np.ndarray) -> np.ndarray:
    """:func:`hbm.friction_march_numba.jacobian_samples` in C: ``Z`` (nb, C, N, m)
    with ``dF = P Z``."""
    lib = library()
    nb, N, C = stuck.shape
    E, kf = _checked(E, np.float64), _checked(kf, np.float64)
    stuck, last = _checked(stuck, np.bool_), _checked(last, np.int64)
    if E.shape[0] != N or kf.size != C or last.shape != stuck.shape:
        raise ValueError("jacobian_samples: arrays of inconsistent shapes")
    Z = np.empty((nb, C, N, E.shape[1]))
    lib.dm_samples(nb, N, C, E.shape[1], _ptr(E), _ptr(kf), _ptr(stuck), _ptr(last),
                   _ptr(Z))
    return Z


def march_and_samples(u: np.ndarray, kf: np.ndarray, fs: np.ndarray,
                      w_start: np.ndarray, E: np.ndarray):
    """``(force, Z)``: :func:`march` and :func:`jacobian_samples` (as
    :func:`hbm.friction_march_numba.march_and_samples`)."""
    force, stuck, last = march(u, kf, fs, w_start)
    return force, jacobian_samples(E, kf, stuck, last)
