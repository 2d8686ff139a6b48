"""Thread limits of the BLAS/OpenMP libraries for drymount's own work.

drymount's linear algebra is small (HBM Jacobians of at most a few hundred rows, 6-DOF
time steps): many BLAS threads only add synchronisation, a lot of it on a busy
machine (``drymount hbm six_dof_halved`` took 7x longer with OpenBLAS's default threads
than with one thread on a shared 2-core machine; ``docs/performance.md``). The command
line therefore runs the BLAS and OpenMP libraries with **one thread** by default.

Override with the environment variable ``DRYMOUNT_THREADS``: a positive integer is the
thread count, ``default`` leaves the libraries' own settings (and any
``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``, ... of yours) alone.

The limit is set twice: in the environment (``OPENBLAS_NUM_THREADS`` and friends), which
libraries read when they load, so worker processes (``drymount sweep --workers``, which
start fresh interpreters) inherit it; and through ``threadpoolctl`` for libraries that
are already loaded in this process.
"""

from __future__ import annotations

import os
import sys

__all__ = ["ENV", "LIBRARY_VARIABLES", "thread_limit", "limit_threads"]

#: The override: a positive integer, or ``default``.
ENV = "DRYMOUNT_THREADS"
#: Variables the BLAS/OpenMP libraries read when they load.
LIBRARY_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                     "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")
DEFAULT_THREADS = 1
#: Modules whose loading starts a BLAS/OpenMP library: once one is loaded, the
#: environment comes too late and threadpoolctl sets the limit (a start-up without
#: them skips threadpoolctl's 0.1 s import, issue 27).
_LOADED = frozenset(("numpy", "scipy", "numba", "sklearn", "torch"))


def thread_limit(environ=None) -> int | None:
    """The thread count asked for by ``$DRYMOUNT_THREADS`` (None: ``default``).

    Raises
    ------
    ValueError
        The variable is neither a positive integer nor ``default``.
    """
    text = (os.environ if environ is None else environ).get(ENV, "").strip()
    if not text:
        return DEFAULT_THREADS
    if text.lower() == "default":
        return None
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"`{ENV}` must be a positive integer or 'default', "
                         f"got {text!r}")
    return n


def limit_threads(environ=None) -> int | None:
    """Apply :func:`thread_limit` to this process and to the processes it starts.

    Returns the limit applied (None: the libraries' defaults were left alone).
    """
    env = os.environ if environ is None else environ
    n = thread_limit(env)
    if n is None:
        return None
    for var in LIBRARY_VARIABLES:
        env[var] = str(n)
    if environ is None and not _LOADED.intersection(sys.modules):
        return n  # nothing loaded yet: the libraries will read the environment
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # the environment still covers libraries not loaded yet
        return n
    threadpool_limits(limits=n)
    return n
