"""Small C libraries compiled at first use and kept in the native cache.

:func:`shared_library` compiles one C source with the system C compiler (``$CC``,
``cc`` or ``gcc``) into the folder of :func:`fmu_build.native.cache_folder` (tested
equal; not imported from there: importing :mod:`fmu_build` costs 0.2 s, the FMU builder
and the mount law), keyed by the source, the flags and the compiler's identity, and
returns its path. Used by :mod:`hbm.aft_native` (the AFT's kernels) and
:mod:`vehicle.c_loop` (the FMU stepping loop).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

__all__ = ["compiler", "cache_folder", "shared_library"]


def compiler() -> list[str] | None:
    """``$CC`` (split), else ``cc`` or ``gcc`` on the PATH; None without one."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    return cc.split() if cc else None


def cache_folder() -> Path | None:
    """``$DRYMOUNT_NATIVE_CACHE`` (empty: no cache), else
    ``~/.cache/drymount/native`` (``$XDG_CACHE_HOME``)."""
    env = os.environ.get("DRYMOUNT_NATIVE_CACHE")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "drymount" / "native"


def shared_library(source: Path, stem: str, flags: list[str] | tuple[str, ...],
                   cc: list[str], identity: str) -> Path:
    """The shared library of ``source`` compiled by ``cc`` with ``flags`` in the
    cache's folder ``stem`` (a temporary folder without a cache); compiled when
    missing. ``identity`` names the compiler's version in the key (a compiler
    upgrade builds anew). ``$DRYMOUNT_NATIVE_CFLAGS`` (debugging only, e.g.
    ``-fsanitize=address -g``; see docs/fmu.md) is appended to ``flags``. Raises
    OSError if the compiler fails."""
    flags = [*flags, *os.environ.get("DRYMOUNT_NATIVE_CFLAGS", "").split()]
    src = source.read_bytes()
    key = hashlib.sha256(src + identity.encode() + " ".join([*cc, *flags]).encode())
    folder = cache_folder()
    folder = (folder / stem) if folder is not None else Path(
        tempfile.mkdtemp(prefix=f"drymount_{stem}_"))
    out = folder / f"{stem}-{key.hexdigest()[:16]}.so"
    if not out.exists():
        folder.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(f".{os.getpid()}.tmp")
        proc = subprocess.run([*cc, *flags, "-o", str(tmp), str(source)],
                              capture_output=True, text=True, timeout=120)
        if proc.returncode != 0:
            raise OSError(f"{cc[0]} failed: {proc.stderr.strip()[:300]}")
        os.replace(tmp, out)
    return out
