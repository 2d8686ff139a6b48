"""The FMU backend's stepping loop in C (``vehicle/c_loop.c``), the Python loop of
:meth:`vehicle.backends.FMUBackend.run` its reference and fallback.

Per step the C loop makes exactly the Python loop's calls: per mount one set of its
inputs, one get of its outputs, one doStep (the FMU's own functions, pointers taken
from the loaded library), then the linear update through the very BLAS ``dgemv``
NumPy's ``W.dot`` calls, so the rows equal the Python loop's bit for bit. The product
is checked against ``W.dot`` on the bound matrix at every :func:`for_backend`; a
mismatch (another BLAS, another kernel) falls back to the Python loop.

The library is compiled at first use with the system C compiler (``$CC``, ``cc`` or
``gcc``) into the native cache (:func:`fmu_build.native.cache_folder`, keyed by the
source and the compiler's version). Steps run in chunks of :data:`CHUNK` so a
KeyboardInterrupt (SIGINT) is seen between chunks, the rows done so far kept.

Used for the native C FMUs (``fmu_build.native``: FMI 2.0 and 3.0); not for the
PythonFMU build (its law runs in Python inside the FMU call, so the loop's own cost
is small beside it and a SIGINT should reach Python at a step boundary), not with
semi-active control (the controllers are Python), nor when ``$DRYMOUNT_C_LOOP`` is
``0``. Each fallback says why in a debug log (``drymount.vehicle.c_loop``).
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import logging
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["CLoop", "for_backend", "library", "CHUNK"]

_log = logging.getLogger(__name__)

#: Steps per call into C (between two, Python sees signals).
CHUNK = 1000
SOURCE = Path(__file__).with_name("c_loop.c")
#: ILP64 cblas_dgemv names of the OpenBLAS builds NumPy ships (scipy-openblas).
_GEMV_NAMES = ("scipy_cblas_dgemv64_", "cblas_dgemv64_")

_i64, _dbl, _vp = ctypes.c_int64, ctypes.c_double, ctypes.c_void_p


class _Mount(ctypes.Structure):
    _fields_ = [("component", _vp), ("set", _vp), ("get", _vp), ("step", _vp),
                ("vin", _vp), ("vout", _vp), ("nin", _i64), ("nout", _i64),
                ("uv_off", _i64), ("out_off", _i64)]


class _Fail(ctypes.Structure):
    _fields_ = [("k", _i64), ("e", _i64), ("which", _i64), ("status", _i64)]


def _compiler() -> list[str] | None:
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    return cc.split() if cc else None


def _compile(cc: list[str]) -> Path:
    """The shared library in the native cache (compiled when missing)."""
    from drymount.fmu_build.native import cache_folder, debug_cflags

    src = SOURCE.read_bytes()
    ver = subprocess.run([cc[0], "--version"], capture_output=True, text=True,
                         check=False).stdout
    flags = ["-std=c11", "-O2", "-shared", "-fPIC", *debug_cflags()]
    key = hashlib.sha256(src + ver.encode() + " ".join(cc + flags).encode())
    folder = cache_folder()
    folder = (folder / "c_loop") if folder is not None else Path(
        tempfile.mkdtemp(prefix="drymount_c_loop_"))
    out = folder / f"c_loop-{key.hexdigest()[:16]}.so"
    if not out.exists():
        folder.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(f".{os.getpid()}.tmp")
        proc = subprocess.run([*cc, *flags, "-o", str(tmp), str(SOURCE)],
                              capture_output=True, text=True, timeout=120)
        if proc.returncode != 0:
            raise OSError(f"{cc[0]} failed: {proc.stderr.strip()[:300]}")
        os.replace(tmp, out)
    return out


@functools.cache
def library():
    """``(ctypes library, "")`` or ``(None, why not)``."""
    cc = _compiler()
    if cc is None:
        return None, "no C compiler ($CC, cc or gcc)"
    try:
        lib = ctypes.CDLL(str(_compile(cc)))
    except (OSError, subprocess.SubprocessError) as exc:
        return None, f"the C loop did not build: {exc}"
    fn = lib.dm_run
    fn.restype = _i64
    fn.argtypes = [ctypes.c_int, ctypes.POINTER(_Mount), _i64, _vp, _i64, _i64, _i64,
                   _i64, _vp, _vp, _vp, _dbl, _i64, _i64, ctypes.POINTER(_Fail)]
    return lib, ""


@functools.cache
def _gemv() -> int | None:
    """Address of the cblas_dgemv of the OpenBLAS loaded by NumPy, or None."""
    try:
        with open("/proc/self/maps") as f:
            paths = {line.split()[-1] for line in f
                     if "openblas" in line.rsplit("/", 1)[-1].lower()}
    except OSError:
        return None
    for path in sorted(paths):
        try:
            dll = ctypes.CDLL(path)
        except OSError:
            continue
        for name in _GEMV_NAMES:
            try:
                return ctypes.cast(dll[name], _vp).value
            except AttributeError:
                continue
    return None


def _product_matches(lib, gemv: int, W: np.ndarray, width: int, o_x: int) -> bool:
    """Whether the C loop's product equals ``W.dot`` bit for bit on random rows."""
    rng = np.random.default_rng(7)
    rec = rng.standard_normal((4, width))
    ref = rec.copy()
    for k in range(3):
        W.dot(ref[k, o_x:], ref[k + 1, :W.shape[0]])
    times = np.zeros(3)
    lib.dm_run(2, None, 0, rec.ctypes.data, width, o_x, W.shape[0], W.shape[1],
               W.ctypes.data, gemv, times.ctypes.data, 0.0, 0, 3,
               ctypes.byref(_Fail()))
    return bool(np.array_equal(rec, ref))


class CLoop:
    """The C stepping loop bound to an :class:`vehicle.backends.FMUBackend`'s row
    buffer, matrix and raw FMI calls (after its ``bind``)."""

    def __init__(self, backend, lib, gemv: int, fmi: int):
        L = backend.layout
        self.backend, self.lib, self.gemv, self.fmi = backend, lib, gemv, fmi
        raws = backend._raw
        self._mounts = (_Mount * len(raws))()

        def addr(fn):
            return ctypes.cast(fn, _vp).value

        for e, r in enumerate(raws):
            self._mounts[e] = _Mount(
                r.component.value, addr(r.set_real), addr(r.get_real),
                addr(r.do_step), ctypes.addressof(backend._vin[e]),
                ctypes.addressof(backend._vout[e]), backend._nin[e],
                backend._nout[e], L.uv_off(e), L.out_off(e))
        self._fail = _Fail()

    def run(self, k0: int, k1: int, times) -> None:
        """Rows k0..k1-1 as ``FMUBackend.run`` (same errors, same ``steps``)."""
        be, L = self.backend, self.backend.layout
        rec, W = be._rec, be._W
        t = np.ascontiguousarray(times, dtype=float)
        k = k0
        try:
            while k < k1:
                b = min(CHUNK, k1 - k)
                done = self.lib.dm_run(
                    self.fmi, self._mounts, len(self._mounts), rec.ctypes.data,
                    L.width, L.o_x, W.shape[0], W.shape[1], W.ctypes.data,
                    self.gemv, t.ctypes.data + 8 * (k - k0), be._h, k, k + b,
                    ctypes.byref(self._fail))
                k += done
                if done < b:
                    self._raise(k0, t)
        finally:
            be.steps += k - k0
        if k1 > k0:
            be.time = float(t[k1 - k0 - 1])

    def _raise(self, k0: int, t: np.ndarray):
        f, be = self._fail, self.backend
        which = {1: "set", 2: "get", 3: "step"}[f.which]
        exc = be._raw[f.e].failed(which, int(f.status))
        raise be._error(int(f.e), float(t[f.k - k0]), exc) from exc


def _fmi_version(backend) -> int | None:
    """2 or 3 for the raw calls of a native C FMU (``fmu_build.native``), else None."""
    from fmpy import read_model_description

    md = read_model_description(backend.fmu_path)
    if not (md.generationTool or "").startswith("drymount fmu_build.native"):
        return None
    names = {r.names["set"] for r in backend._raw}
    return {"fmi2SetReal": 2, "fmi3SetFloat64": 3}.get(names.pop()) \
        if len(names) == 1 else None


def for_backend(backend) -> CLoop | None:
    """The C loop for a bound FMU backend, or None (the reason in a debug log)."""
    if os.environ.get("DRYMOUNT_C_LOOP", "1") == "0":
        return _no("$DRYMOUNT_C_LOOP=0")
    fmi = _fmi_version(backend)
    if fmi is None:
        return _no(f"{backend.fmu_path} is not a native C FMU (fmu_build.native)")
    lib, why = library()
    if lib is None:
        return _no(why)
    gemv = _gemv()
    if gemv is None:
        return _no("NumPy's BLAS has no ILP64 cblas_dgemv the C loop can call")
    L = backend.layout
    if not _product_matches(lib, gemv, backend._W, L.width, L.o_x):
        return _no("the BLAS product from C differs from W.dot")
    return CLoop(backend, lib, gemv, fmi)


def _no(why: str) -> None:
    _log.debug("co-simulation loop in Python: %s", why)
    return None
