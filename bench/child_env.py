"""The environment of the processes a benchmark times: what a user's machine has.

- BLAS and OpenMP on one thread (what the command line sets, :mod:`drymount.threads`).
- Python's bytecode caches written and read: ``PYTHONDONTWRITEBYTECODE`` is removed.
  A user's installation has the ``.pyc`` of every module (pip compiles them at install;
  an editable install or a source tree writes them on the first import). A machine
  whose environment sets ``PYTHONDONTWRITEBYTECODE=1`` (the development sandbox of
  2026-12 does) makes every timed process compile drymount's modules from source:
  about 0.2 s CPU of the default 6-DOF curve, for this tree and the original alike
  (docs/performance.md, "Tenth pass"). The first run of a tree writes its caches;
  the benchmarks warm each tree (or take a median of repeats) before they time it.
"""

from __future__ import annotations

import os
import subprocess

__all__ = ["child_env", "compile_bytecode", "entry_python"]

_ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def child_env(**extra: str) -> dict[str, str]:
    """``os.environ`` with one BLAS/OpenMP thread, bytecode caches on, and ``extra``."""
    env = dict(os.environ, **_ONE_THREAD, **extra)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


_COMPILE = """
import compileall, importlib.util, sys
layers = ("hbm", "vehicle", "fmu_src", "fmu_build")
names = ["drymount"] + [f"drymount.{n}" for n in layers]
for name in names:
    spec = importlib.util.find_spec(name)
    for folder in (spec.submodule_search_locations or []) if spec else []:
        if not compileall.compile_dir(folder, quiet=1):
            sys.exit(f"compileall failed in {folder}")
"""


def entry_python(entry_point: str | None) -> str:
    """The interpreter of a console script (its ``#!`` line), e.g. another venv's."""
    if entry_point is None:
        raise SystemExit("no `drymount` on PATH: activate its venv or pass --drymount")
    with open(entry_point, "rb") as f:
        first = f.readline().decode(errors="replace").strip()
    if not first.startswith("#!"):
        raise ValueError(f"{entry_point} has no #! line naming its interpreter")
    return first[2:].split()[0]


def compile_bytecode(python: str) -> None:
    """Write the bytecode caches of the drymount that ``python`` imports (its package
    and its layers), as pip does at install: the timed processes then read them."""
    subprocess.run([python, "-c", _COMPILE], check=True, env=child_env())
